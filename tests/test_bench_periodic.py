"""benchmarks/bench_periodic.py: the per-state solve_ivp reference the stiff-contact ratio uses.

Independent routes: the closed form of the undamped linear oscillator (inside the
gap) and the event-driven ``time_response`` (stiff impacting case).
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path
from types import ModuleType

import pytest

from clearjoint import Joint, Losses
from clearjoint.simulate import time_response

STIFF = Joint(
    mass=1.0,
    clearance=0.2,
    gap_stiffness=1.0,
    compression_stiffness=1e8,
    tension_stiffness=1e8,
)


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    path = Path(__file__).parents[1] / "benchmarks" / "bench_periodic.py"
    spec = importlib.util.spec_from_file_location("bench_periodic", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_inside_the_gap_it_is_the_linear_closed_form(bench: ModuleType) -> None:
    f0, omega, t = 0.01, 0.5, 20.0  # |x| < 0.02: never reaches the edges at 0.1
    x, v = bench.per_state_reference(STIFF, f0, omega, t, 0.8, rtol=1e-12)
    # x'' + x = f0 sin(w t) from rest: x = f0 / (1 - w^2) (sin w t - w sin t)
    amp = f0 / (1.0 - omega**2)
    assert x == pytest.approx(amp * (math.sin(omega * t) - omega * math.sin(t)), abs=1e-13)
    assert v == pytest.approx(amp * omega * (math.cos(omega * t) - math.cos(t)), abs=1e-13)


def test_stiff_impacting_case_agrees_with_time_response(bench: ModuleType) -> None:
    duration = 2.0 * math.pi
    x, v = bench.per_state_reference(STIFF, 1.0, 1.0, duration, 0.8, rtol=1e-12)
    motion = time_response(STIFF, 1.0, 1.0, duration, losses=Losses(restitution=0.8))
    assert motion.impact_times.size > 3  # it does hit the edges, with the restitution jump
    assert abs(motion.final_state[0] - x) / 0.1 < 1e-9
    assert abs(motion.final_state[1] - v) / abs(v) < 1e-7


def test_longdouble_reference_is_the_closed_form_in_the_gap_resonant_or_not(
    bench: ModuleType,
) -> None:
    # x'' + x = f0 sin(w t) from rest: f0 / (1 - w^2) (sin w t - w sin t); at w = 1 the
    # resonant f0 / 2 (sin t - t cos t)
    f0, t = 0.002, 20.0
    x, v, impacts = bench.closed_form_reference(STIFF, f0, 0.5, t, 0.8)
    amp = f0 / (1.0 - 0.25)
    assert impacts == 0
    assert x == pytest.approx(amp * (math.sin(0.5 * t) - 0.5 * math.sin(t)), abs=1e-16)
    assert v == pytest.approx(amp * 0.5 * (math.cos(0.5 * t) - math.cos(t)), abs=1e-16)
    x, v, impacts = bench.closed_form_reference(STIFF, f0, 1.0, t, 0.8)
    assert impacts == 0
    assert x == pytest.approx(0.5 * f0 * (math.sin(t) - t * math.cos(t)), abs=1e-16)
    assert v == pytest.approx(0.5 * f0 * t * math.sin(t), abs=1e-16)


def test_longdouble_reference_with_impacts_agrees_with_both_solvers(bench: ModuleType) -> None:
    duration = 2.0 * math.pi
    x, v, impacts = bench.closed_form_reference(STIFF, 1.0, 1.0, duration, 0.8)
    assert impacts == 7
    ivp = bench.per_state_reference(STIFF, 1.0, 1.0, duration, 0.8, rtol=1e-12)
    exact = time_response(STIFF, 1.0, 1.0, duration, losses=Losses(restitution=0.8))
    assert abs(ivp[0] - x) < 1e-9
    assert abs(ivp[1] - v) < 1e-9
    assert abs(exact.final_state[0] - x) < 1e-12
    assert abs(exact.final_state[1] - v) < 1e-12


@pytest.mark.parametrize("method", ["RK45", "Radau", "BDF", "LSODA"])
def test_every_solve_ivp_method_the_benchmark_tries_solves_the_impacting_case(
    bench: ModuleType, method: str
) -> None:
    # the implicit methods get the state's exact Jacobian; one period, 7 impacts, against
    # the longdouble closed form, to the accuracy each reaches at a loose rtol
    duration = 2.0 * math.pi
    x, v, _ = bench.closed_form_reference(STIFF, 1.0, 1.0, duration, 0.8)
    ivp = bench.per_state_reference(STIFF, 1.0, 1.0, duration, 0.8, rtol=1e-9, method=method)
    assert abs(ivp[0] - x) < 1e-5
    assert abs(ivp[1] - v) < 1e-5


def test_a_failed_solve_ivp_run_raises_instead_of_returning_its_last_state(
    bench: ModuleType,
) -> None:
    with pytest.raises(RuntimeError, match="BDF at rtol 1e-13 failed"):
        bench.per_state_reference(STIFF, 1.0, 1.0, 2.0 * math.pi, 0.8, rtol=1e-13, method="BDF")
