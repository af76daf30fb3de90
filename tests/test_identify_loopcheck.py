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

import math
from pathlib import Path

import numpy as np
import pytest

import clearjoint.identify.core as core
from clearjoint.errors import ParameterError
from clearjoint.identify import identify
from clearjoint.identify.core import _branches_of
from clearjoint.identify.cycles import cycle_bounds, excitation_frequency, stack, steady
from clearjoint.identify.damper import _damper_fit
from clearjoint.identify.loopcheck import (
    Noise,
    Reading,
    channel_noise,
    damper_residual,
    reading,
    scatter,
    sign_noise,
    weak_residual,
)
from clearjoint.identify.weak import stage_runs, weak_fit, weak_system
from clearjoint.records import Record, read_record
from independent_joint import TrueJoint, steady_truth, write_record
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


def _spy_residual(
    monkeypatch: pytest.MonkeyPatch, name: str = "sample_fit_residual"
) -> list[Reading]:
    """Record every residual identify takes by ``core.<name>``: a per-sample fit's (a
    joint's or a line's) by default, the weak form's with "weak_residual"."""
    seen: list[Reading] = []
    original = getattr(core, name)

    def spy(*args: object, **kwargs: object) -> Reading:
        value = original(*args, **kwargs)
        seen.append(value)
        return value

    monkeypatch.setattr(core, name, spy)
    return seen


def _no_damper(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(core, "_damper_fit", lambda *args: None)


def _joint_stages(monkeypatch: pytest.MonkeyPatch) -> None:
    """Read any loop as a joint's tension, free play and compression (stage windows at
    70-100 % of the stroke each way and the middle half), no damper and no competing model."""
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
    _joint_stages(monkeypatch)
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


# ---- the noise floor: errors-in-variables, per sample -----------------------------------


def _line_record(
    k: float, sigma_x: float, sigma_f: float, seed: int, cycles: int = 16
) -> tuple[Record, float, float]:
    """F = k x at 10 Hz, 1 mm, 2 kHz (200 samples a cycle), displacement control, with
    Gaussian noise sigma_x (m) and sigma_f (N) per sample; returns the record, the noise
    expected on one sample, sqrt(sigma_F^2 + k^2 sigma_x^2), and the force's std."""
    t = np.arange(cycles * 200) / 2000.0
    x = 1e-3 * np.sin(2 * np.pi * 10.0 * t)
    rng = np.random.default_rng(seed)
    record = Record(
        time=t,
        force=k * x + rng.normal(0.0, sigma_f, t.size) if sigma_f else k * x,
        displacement=x + rng.normal(0.0, sigma_x, t.size) if sigma_x else x,
        control="displacement",
        frequency_hz=10.0,
        source="line",
    )
    return record, float(np.hypot(sigma_f, k * sigma_x)), float(np.std(k * x))


@pytest.mark.parametrize(
    ("sigma_x", "sigma_f"),
    [(1e-5, 0.0), (0.0, 1e3), (1e-5, 1e3)],
    ids=["displacement-noise-only", "force-noise-only", "both"],
)
def test_the_floor_of_a_straight_line_is_sqrt_of_force_and_slope_times_displacement_noise(
    monkeypatch: pytest.MonkeyPatch, sigma_x: float, sigma_f: float
) -> None:
    """A straight line F = k x read by the line fit: the errors are the force's noise
    minus k times the displacement's, so the floor must be sqrt(sigma_F^2 + k^2 sigma_x^2)
    over sqrt(n) on the average of n cycles (closed form from the noise put in, not from
    the code, well above the 0.1 % resolution, 71 N), the residual must sit on it and
    nothing is flagged (the force-only floor flagged the displacement-noise record at
    about k sigma_x / 71 N, 3.6 times)."""
    k = 1e8  # 10 um of displacement noise is 1 kN of force: the two channels weigh alike
    seen = _spy_residual(monkeypatch)
    for seed in (1, 2):
        record, per_sample, _ = _line_record(k, sigma_x, sigma_f, seed)
        result = identify(record)
        assert result.model == "line"
        (reading,) = seen
        seen.clear()
        expected = per_sample / math.sqrt(len(result.cycles))
        assert reading.floor == pytest.approx(expected, rel=0.08), seed
        assert reading.ratio == pytest.approx(1.0, abs=0.15), seed
        assert reading.note == ""
        assert not any("fit residual" in reason for _, reason in result.flags.values())


def test_a_real_misfit_above_the_displacement_noise_is_still_flagged(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The same line with displacement noise only plus a cubic term (k3 x^3 = 10 % of
    k x at the stroke's end), which two straight pieces cannot follow: still flagged on
    the line path (9 times its floor), the floor does not swallow a real misfit."""
    record, _, _ = _line_record(1e8, 1e-5, 0.0, 3)
    x = record.displacement
    cubic = Record(
        time=record.time,
        force=record.force + 0.1e8 * x**3 / 1e-6,
        displacement=x,
        control="displacement",
        frequency_hz=10.0,
        source="cubic",
    )
    monkeypatch.setattr(core, "_is_joint", lambda windows: False)  # no stages: a line
    seen = _spy_residual(monkeypatch)
    result = identify(cubic)
    assert result.model == "line"
    assert seen[0].ratio > 2 * core.RESIDUAL_FACTOR
    assert "fit residual" in result.flags["compression_stiffness_n_per_m"][1]


def test_one_cycle_gives_the_force_only_floor_with_a_note() -> None:
    """No scatter over one cycle: the displacement's noise is NaN (never a quiet zero),
    the floor counts the force alone and says so."""
    rng = np.random.default_rng(4)
    x = rng.normal(0.0, 1e-6, (1, 200))
    f = 1e3 * np.sin(np.linspace(0.0, 2 * np.pi, 200))[None, :]
    noise = channel_noise(f, scatter(x), 1e-3)
    assert np.isnan(noise.displacement)
    assert "force channel alone" in noise.note
    assert noise.force == pytest.approx(1e-3 * float(np.std(f)))
    read = reading(np.full(10, 3.0), noise, 1.0, 1e8)
    assert read.floor == pytest.approx(noise.force)
    assert read.note == noise.note
    with pytest.raises(ParameterError, match="force noise"):
        Noise(math.nan, 0.0)


def test_the_velocity_signs_noise_is_the_chance_of_a_flip() -> None:
    """sgn(v + e) has the standard deviation 2 sqrt(p (1 - p)), p = Phi(-|v| / sigma):
    checked against draws."""
    rng = np.random.default_rng(5)
    v = np.array([0.0, 0.5, 1.0, 2.0, 4.0])
    draws = np.sign(v[:, None] + rng.normal(0.0, 1.0, (5, 200_000)))
    assert sign_noise(v, 1.0) == pytest.approx(draws.std(axis=1), abs=0.01)
    assert not sign_noise(v, math.nan).any()


def test_the_weak_forms_floor_is_the_equations_noise() -> None:
    """A noise-only check of the weak form's per-equation sigma (its weights on the force
    and on the displacement): a piecewise-linear joint law (no friction) with noise on x
    and F, fitted by the weak form; over 12 noise draws the rms of error / sigma is 1."""
    m = 600
    t = np.arange(m) / m
    x = 1e-3 * np.sin(2 * np.pi * t)
    edges = (-0.2e-3, 0.3e-3)
    f = np.where(
        x > edges[1], 5e7 * (x - edges[1]), np.where(x < edges[0], 3e7 * (x - edges[0]), 0.0)
    )
    f = f + 1e5 * x
    step = 1.0 / m
    v = np.gradient(x, step)
    system = weak_system(x, v, step, stage_runs(x, edges, 0.05 * (edges[1] - edges[0])))
    assert system is not None
    rng = np.random.default_rng(6)
    cycles, sx, sf = 16, 4e-7, 20.0
    ratios = []
    for _ in range(12):
        xs = x + rng.normal(0.0, sx, (cycles, m))
        fs = f + rng.normal(0.0, sf, (cycles, m))
        fit = weak_fit(system, xs.mean(axis=0)[None, :], fs.mean(axis=0)[None, :], mass=0.0)
        noise = Noise(sf / np.sqrt(cycles), sx / np.sqrt(cycles))  # the true ones
        ratios.append(weak_residual(system, fit, v, noise, inertia_from_x=False).ratio)
        assert fit.lines[0, 2, 1] == pytest.approx(5e7 + 1e5, rel=0.05)
    assert float(np.sqrt(np.mean(np.square(ratios)))) == pytest.approx(1.0, abs=0.12)


@pytest.mark.parametrize(
    ("frequency", "acceleration"), [(40.0, True), (100.0, True), (40.0, False)]
)
def test_independent_records_at_one_percent_noise_are_not_flagged_for_the_residual(
    tmp_path: Path, frequency: float, acceleration: bool
) -> None:
    """The independent simulator (tests/independent_joint.py: solve_ivp, a tanh friction
    law) with 1 % noise on every channel: the values meet the issue's targets and no
    value is doubtful for the residual (against a force-only floor they were, 3.1-5.2
    times). Without acceleration at 100 Hz the friction misses by 25-67 % and the
    residual flag stays (not tested here: docs/identify.md)."""
    joint = TrueJoint(frequency_hz=frequency)
    truth = steady_truth(joint)
    for seed in (1, 2):
        path = write_record(
            joint, tmp_path / f"{seed}.csv", noise=0.01, acceleration=acceleration, seed=seed
        )
        result = identify(read_record(path))
        s = result.summary
        assert s["clearance_m"] == pytest.approx(truth["clearance_m"], rel=0.01)
        for key in ("compression_stiffness_n_per_m", "tension_stiffness_n_per_m"):
            assert s[key] == pytest.approx(truth[key], rel=0.02), key
        assert s["friction_force_n"] == pytest.approx(truth["friction_force_n"], rel=0.10)
        assert s["energy_per_cycle_j"] == pytest.approx(truth["energy_per_cycle_j"], rel=0.01)
        assert "fit residual" not in result.flag_reason, (seed, result.flag_reason)
        assert "velocity's sign" not in result.flag_reason


@pytest.mark.parametrize(("noise", "seed"), [(0.0, 0), (0.01, 1)])
def test_a_smooth_loop_forced_into_the_weak_form_is_flagged(
    monkeypatch: pytest.MonkeyPatch, noise: float, seed: int
) -> None:
    """The Bouc-Wen loop read as a joint's three stages (as in the sample-fit test) by the
    weak form (its interpolated stack goes there): doubtful on every fitted quantity,
    noise-free for its residual (36 times its floor), at 1 % noise because the spectral
    velocity's sign is noise on most samples (the floor then covers the residual)."""
    _joint_stages(monkeypatch)
    seen = _spy_residual(monkeypatch, "weak_residual")
    result = identify(bouc_wen(noise, seed))
    assert result.model == "joint"
    assert len(seen) == 1  # the weak form
    why = "fit residual" if noise == 0.0 else "velocity's sign is flipped by its noise"
    for q in ("compression_stiffness_n_per_m", "friction_force_n", "gap_stiffness_n_per_m"):
        flag, reason = result.flags[q]
        assert flag == "doubtful", q
        assert why in reason, q
