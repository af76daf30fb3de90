"""analysis.py: the per-side dynamic stiffness k_d,s (MODEL.md section 3) by independent routes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from clearjoint import Joint
from clearjoint.analysis import side_dynamic_stiffness


def _half_period_by_integration(joint: Joint, side: int, penetration: float) -> float:
    """tau_s by solve_ivp: from side s's turning point back to its edge (x2), then across."""
    edge = joint.compression_gap if side > 0 else -joint.tension_gap
    other = -joint.tension_gap if side > 0 else joint.compression_gap

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -float(joint.restoring_force(y[0])) / joint.mass]

    def at(target: float):
        def event(_t: float, y: np.ndarray) -> float:
            return float(y[0] - target)

        event.terminal = True  # type: ignore[attr-defined]
        return event

    start = [edge + side * penetration, 0.0]
    leave = solve_ivp(rhs, (0, 1.0), start, events=at(edge), rtol=1e-12, atol=1e-15)
    t_contact = 2.0 * leave.t_events[0][0]
    cross = solve_ivp(rhs, (0, 1.0), leave.y_events[0][0], events=at(other), rtol=1e-12, atol=1e-15)
    return t_contact + cross.t_events[0][0]


def test_k0_zero_is_eq9_per_side_and_the_mass_cancels() -> None:
    c, a_c, a_t = 0.106e-3, 30e-6, 45e-6
    k_c, k_t = 1.8e8, 0.9e8
    for mass in (1.5, None):
        kdc, kdt = side_dynamic_stiffness(mass, c, k_c, k_t, 0.0, a_c, a_t)
        assert kdc == pytest.approx(k_c * (math.pi * a_c / (math.pi * a_c + c)) ** 2, rel=1e-12)
        assert kdt == pytest.approx(k_t * (math.pi * a_t / (math.pi * a_t + c)) ** 2, rel=1e-12)


def test_k0_positive_matches_an_integration_of_the_free_motion() -> None:
    m, c, k0, k_c, k_t = 1.5, 0.196e-3, 2e6, 1.6e8, 0.7e8  # slopes include k0
    joint = Joint(
        mass=m,
        clearance=c,
        compression_stiffness=k_c - k0,
        tension_stiffness=k_t - k0,
        gap_stiffness=k0,
    )
    a_c, a_t = 12e-6, 20e-6
    kdc, kdt = side_dynamic_stiffness(m, c, k_c, k_t, k0, a_c, a_t)
    assert kdc == pytest.approx(
        m * (math.pi / _half_period_by_integration(joint, 1, a_c)) ** 2, rel=1e-7
    )
    assert kdt == pytest.approx(
        m * (math.pi / _half_period_by_integration(joint, -1, a_t)) ** 2, rel=1e-7
    )


def test_no_clearance_gives_the_slope_and_bad_sides_give_nan() -> None:
    kdc, kdt = side_dynamic_stiffness(1.5, 0.0, 7e7, 6e7, 2e5, 20e-6, 20e-6)
    assert (kdc, kdt) == (pytest.approx(7e7), pytest.approx(6e7))
    kdc, kdt = side_dynamic_stiffness(1.5, 1e-4, 7e7, 6e7, 0.0, -1e-6, math.nan)
    assert math.isnan(kdc)
    assert math.isnan(kdt)


def test_damper_stages_follow_the_force_after_each_reversal() -> None:
    from clearjoint.identify import CycleResult, Identification
    from clearjoint.records import Record

    t = np.linspace(0.0, 2.0, 2001)
    x = np.sin(2 * np.pi * t)  # reversals at t = 0.25, 0.75, ...
    # friction 100 N while sliding; after each reversal the force falls through zero
    # (backlash, 0.05 s at zero force) before it reaches -100 N
    force = np.zeros_like(t)
    for k, start in enumerate(np.arange(-0.25, 2.0, 0.5)):
        sign = 1.0 if k % 2 == 0 else -1.0
        span = (t >= start) & (t < start + 0.5)
        since = t[span] - start
        force[span] = np.where(since < 0.1, sign * 100 * (1 - since / 0.1), 0.0)
        force[span] = np.where(since >= 0.15, -sign * 100.0, force[span])
    force = -force  # compression (+) while x rises toward its maximum
    record = Record(time=t, force=force, displacement=x, control="displacement")
    cycle = CycleResult(0, t.size, {}, 0.0, 0.0, "damper")
    ident = Identification(
        source="synthetic",
        frequency_hz=1.0,
        cycles_total=2,
        cycles=(cycle,),
        summary={"friction_force_n": 100.0},
        spread={},
        control="displacement",
        restoring_force=force,
        stage=np.zeros(t.size, dtype=np.int8),
    )
    free = [(a, b) for name, a, b in ident.stage_runs(record.time) if name == "free-play"]
    assert len(free) >= 3
    for a, b in free:
        # each free play sits just after a reversal (x at a turning point, 0.25 + k/2 s)
        since_reversal = (a - 0.25) % 0.5
        assert 0.05 < since_reversal < 0.12, (a, b)
        assert b - a == pytest.approx(0.07, abs=0.01)
