"""clearjoint.identify.loopcheck: the fitted model's residual on the measured loop.

An exact elastic-plastic loop with a gap (tests/test_identify.friction_loop, built by
stepping the law, not by the model's formula) leaves a residual near zero; a smooth
Bouc-Wen hysteresis with no gap at all (another law, integrated here) leaves one far above
the noise floor and is flagged, on every quantity the damper fit gives. The same loop
forced into the joint's sample-by-sample fit or the line's is flagged there too, while
records of a joint from the independent simulator (tests/independent_joint.py: solve_ivp,
a tanh friction law) fitted sample by sample keep ``ok``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import clearjoint.identify.core as core
from clearjoint.identify import identify
from clearjoint.identify.core import _branches_of
from clearjoint.identify.cycles import cycle_bounds, excitation_frequency, stack, steady
from clearjoint.identify.damper import _damper_fit
from clearjoint.identify.loopcheck import Noise, Reading, damper_residual
from clearjoint.records import Record, read_record
from independent_joint import TrueJoint, write_record
from test_identify import friction_loop


def bouc_wen(noise: float, seed: int) -> Record:
    """A smooth hysteresis loop (Bouc-Wen, z' = x' - 400 |x'| z - 400 x' |z|) at 1 Hz,
    12.7 mm, 1024 Hz: friction-like, with no gap anywhere."""
    t = np.arange(8 * 1024) / 1024.0
    x = 12.7e-3 * np.sin(2 * np.pi * t)
    z = np.zeros_like(x)
    for n in range(1, x.size):
        dx = x[n] - x[n - 1]
        z[n] = z[n - 1] + dx - 400 * abs(dx) * z[n - 1] - 400 * dx * abs(z[n - 1])
    f = 4e6 * z
    rng = np.random.default_rng(seed)
    return Record(
        time=t,
        force=f + rng.normal(0.0, noise * f.std(), f.size),
        displacement=x + rng.normal(0.0, noise * x.std(), x.size),
        control="displacement",
        frequency_hz=1.0,
        source="bouc-wen",
    )


def _average(record: Record) -> tuple[np.ndarray, np.ndarray]:
    frequency = excitation_frequency(record)
    bounds = cycle_bounds(record, frequency)
    kept = steady(record.displacement, bounds, 0.03)
    st = stack(record, frequency, bounds, kept, {"x": record.displacement})
    shift = int(np.argmin(st.channels["x"].mean(axis=0)))
    st = stack(
        record, frequency, bounds, kept, {"x": record.displacement, "f": record.force}, shift
    )
    return st.channels["x"].mean(axis=0), st.channels["f"].mean(axis=0)


def test_an_exact_loop_leaves_almost_no_residual() -> None:
    friction = 1e4
    x, f = _average(friction_loop(4e-3, friction, 5e6, 20e-3))
    parts = _branches_of(x.size, x)
    assert parts is not None
    fit = _damper_fit(x, f, parts)
    assert fit is not None
    quiet = Noise(1.0, 0.0)
    assert damper_residual(x, f, parts, fit, quiet).residual < 0.01 * friction
    # the same loop with its force shifted by a quarter cycle is not the model's
    assert damper_residual(x, np.roll(f, x.size // 4), parts, fit, quiet).residual > 0.3 * friction
    result = identify(friction_loop(4e-3, friction, 5e6, 20e-3))
    assert all("residual" not in reason for _, reason in result.flags.values())


@pytest.mark.parametrize(("noise", "seed"), [(0.0, 0), (0.01, 1)])
def test_a_smooth_loop_with_no_gap_is_not_called_ok(noise: float, seed: int) -> None:
    result = identify(bouc_wen(noise, seed))
    assert result.model == "damper"
    assert result.flags["clearance_m"][0] in ("doubtful", "rejected")
    flag, reason = result.flags["friction_force_n"]
    assert flag == "doubtful"
    assert "fit residual" in reason
    assert "fit residual" in result.flag_reason


def _spy_residual(monkeypatch: pytest.MonkeyPatch) -> list[Reading]:
    """Record every residual of a per-sample fit (a joint's or a line's) identify takes."""
    seen: list[Reading] = []
    original = core.sample_fit_residual

    def spy(*args: object) -> Reading:
        value = original(*args)  # type: ignore[arg-type]
        seen.append(value)
        return value

    monkeypatch.setattr(core, "sample_fit_residual", spy)
    return seen


def _no_damper(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(core, "_damper_fit", lambda *args: None)


@pytest.mark.parametrize(("noise", "seed"), [(0.0, 0), (0.01, 1)])
def test_a_smooth_loop_forced_into_the_line_path_is_flagged(
    monkeypatch: pytest.MonkeyPatch, noise: float, seed: int
) -> None:
    _no_damper(monkeypatch)
    seen = _spy_residual(monkeypatch)
    result = identify(bouc_wen(noise, seed))
    assert result.model == "line"
    assert len(seen) == 1
    assert seen[0].residual > 0.1 * float(np.std(bouc_wen(0.0, 0).force))
    for q in ("compression_stiffness_n_per_m", "friction_force_n", "dynamic_stiffness_n_per_m"):
        flag, reason = result.flags[q]
        assert flag == "doubtful", q
        if noise == 0.0:
            assert "fit residual" in reason
            assert "times the noise floor" in reason
        else:
            # at 1 % noise the spectral velocity's sign is noise on 68 % of the samples
            # (the floor counts those flips, which then cover the residual): said instead
            assert "velocity's sign is flipped by its noise" in reason


@pytest.mark.parametrize(("noise", "seed"), [(0.0, 0), (0.01, 1)])
def test_a_smooth_loop_forced_into_the_joint_path_is_flagged(
    monkeypatch: pytest.MonkeyPatch, noise: float, seed: int
) -> None:
    """The Bouc-Wen loop read as tension, free play and compression (stage windows at
    70-100 % of the stroke each way and the middle half) by the joint's per-sample fit (the
    weak form, which would take this record, held off as for a contact too short for it)."""
    _no_damper(monkeypatch)
    fit = core._joint_fit

    def windows(x: np.ndarray, y: np.ndarray, n: int) -> list[tuple[bool, float, float]]:
        a, m = 0.5 * float(np.ptp(x)), 0.5 * float(x.max() + x.min())
        return [
            (True, m - a, m - 0.7 * a),
            (False, m - 0.5 * a, m + 0.5 * a),
            (True, m + 0.7 * a, m + a),
        ]

    monkeypatch.setattr(core, "_windows", windows)
    monkeypatch.setattr(
        core, "_joint_fit", lambda x, r, v, parts, w, compete=True: fit(x, r, v, parts, w, False)
    )
    seen = _spy_residual(monkeypatch)
    monkeypatch.setattr(core, "MIN_EQUATIONS", 10**9)
    result = identify(bouc_wen(noise, seed))
    assert result.model == "joint"
    assert len(seen) == 1  # the sample-by-sample fit, not the weak form
    for q in ("compression_stiffness_n_per_m", "friction_force_n", "clearance_m"):
        flag, reason = result.flags[q]
        assert flag in ("doubtful", "rejected"), q
        if flag == "doubtful":
            assert "fit residual" in reason, q
    assert "fit residual" in result.flag_reason


@pytest.mark.parametrize(("frequency", "noise"), [(40.0, 0.0), (100.0, 0.0), (100.0, 0.002)])
def test_an_independent_joint_fitted_sample_by_sample_keeps_ok(
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
    frequency: float,
    noise: float,
) -> None:
    """The independent simulator's joint (another friction law, no rig), with acceleration:
    the sample-by-sample fit's residual stays under the flag and every value is ``ok``
    (at 1 % noise the displacement's noise, times the contact stiffness, enters the
    residual but not the force's noise floor: docs/identify.md, Flags)."""
    seen = _spy_residual(monkeypatch)
    path = write_record(
        TrueJoint(frequency_hz=frequency), tmp_path / "r.csv", noise=noise, cycles=12
    )
    result = identify(read_record(path))
    assert result.model == "joint"
    assert len(seen) == 1  # the sample-by-sample path
    assert {flag for flag, _ in result.flags.values()} == {"ok"}
