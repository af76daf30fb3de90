"""clearjoint.identify.loopcheck: the damper model's residual on the measured loop.

An exact elastic-plastic loop with a gap (tests/test_identify.friction_loop, built by
stepping the law, not by the model's formula) leaves a residual near zero; a smooth
Bouc-Wen hysteresis with no gap at all (another law, integrated here) leaves one far above
the noise floor and is flagged, on every quantity the damper fit gives.
"""

from __future__ import annotations

import numpy as np
import pytest

from clearjoint.identify import identify
from clearjoint.identify.core import _branches_of
from clearjoint.identify.cycles import cycle_bounds, excitation_frequency, stack, steady
from clearjoint.identify.damper import _damper_fit
from clearjoint.identify.loopcheck import damper_residual
from clearjoint.records import Record
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
    assert damper_residual(x, f, parts, fit) < 0.01 * friction
    # the same loop with its force shifted by a quarter cycle is not the model's
    assert damper_residual(x, np.roll(f, x.size // 4), parts, fit) > 0.3 * friction
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
