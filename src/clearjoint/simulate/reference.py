"""Reference path: the same equations solved with scipy's solve_ivp and event location.

Slow but independent of the closed forms: each smooth state (region, slip
direction or stick) is integrated numerically (DOP853) until solve_ivp locates
its first event. The event rules (restitution on entering contact, stick or
slip at a velocity zero) are those of MODEL.md sec. 2. Used by the tests to
cross-check the event-driven solver and by ``benchmarks/bench_simulate.py``.
Its independence is the integration and the event location: each state's linear law
K x - Fc is the kernel's ``region_force`` (:func:`clearjoint.laws.clearance.state_law`),
which ``tests/test_laws_clearance.py`` checks against a law written out in the test.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp

from clearjoint.exact import kernel as kn
from clearjoint.exact.single import initial_state, setup
from clearjoint.joint import Joint, Losses, takes_losses
from clearjoint.system import VibrationSystem

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ReferenceResponse:
    """States at the end of every forcing period from the solve_ivp reference.

    ``strobe`` is (n_periods, 2): x (m) and v (m/s) at t = T, 2T, ...;
    ``events`` counts edges, velocity zeros and stick releases;
    ``x_max`` / ``x_min`` are the extremes of x over the whole run.
    """

    strobe: FloatArray
    events: int
    x_max: float
    x_min: float


Rhs = Callable[[float, FloatArray], list[float]]
Event = Callable[[float, FloatArray], float]


def _event(fun: Event) -> Event:
    """A terminal event that fires when ``fun`` falls through zero."""
    fun.terminal = True  # type: ignore[attr-defined]
    fun.direction = -1  # type: ignore[attr-defined]
    return fun


def _state_equations(
    p: FloatArray, region: int, slip: int, k: float, fc: float, x_stuck: float
) -> tuple[Rhs, list[Event]]:
    """Right-hand side and events of one state; each event is positive inside the state.

    Sticking: release when the net force leaves [-F_f, F_f] (events 0: up, 1: down).
    Moving: event 0 is the velocity zero, then the gap edges that end the state.
    """
    m, c, f0, w = p[kn.P_MASS], p[kn.P_DAMP], p[kn.P_F0], p[kn.P_W]
    g_c, g_t, ff = p[kn.P_GC], p[kn.P_GT], p[kn.P_FF]
    if slip == 0:
        rest = fc - k * x_stuck

        def still(_t: float, _y: FloatArray) -> list[float]:
            return [0.0, 0.0]

        def release_up(t: float, _y: FloatArray) -> float:
            return float(ff - (f0 * math.sin(w * t) + rest))

        def release_down(t: float, _y: FloatArray) -> float:
            return float(ff + (f0 * math.sin(w * t) + rest))

        return still, [_event(release_up), _event(release_down)]

    def moving(t: float, y: FloatArray) -> list[float]:
        return [y[1], (f0 * math.sin(w * t) + fc - k * y[0] - c * y[1]) / m]

    def velocity_zero(_t: float, y: FloatArray) -> float:
        return float(slip * y[1])

    def below_compression_edge(_t: float, y: FloatArray) -> float:
        return float(g_c - y[0])

    def above_tension_edge(_t: float, y: FloatArray) -> float:
        return float(y[0] + g_t)

    def in_compression(_t: float, y: FloatArray) -> float:
        return float(y[0] - g_c)

    def in_tension(_t: float, y: FloatArray) -> float:
        return float(-g_t - y[0])

    events = [_event(velocity_zero)]
    if region == kn.FREE:
        events += [_event(below_compression_edge), _event(above_tension_edge)]
    elif region == kn.COMPRESSION:
        events.append(_event(in_compression))
    else:
        events.append(_event(in_tension))
    return moving, events


@takes_losses
def reference_time_response(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega: float,
    n_periods: int,
    *,
    initial: ArrayLike | None = None,
    losses: Losses | None = None,
    rtol: float = 1e-11,
    steps_per_period: float = 20.0,
) -> ReferenceResponse:
    """Integrate ``n_periods`` forcing periods with solve_ivp (DOP853) and event location.

    The step is capped at the shortest period of the system over
    ``steps_per_period``. solve_ivp sees an event only where the event function
    changes sign between two steps, so an excursion shorter than a step (an orbit
    that leaves a contact by a hair and comes straight back) is missed; raise
    ``steps_per_period`` to see finer ones. The event-driven solver has no such
    blind spot. ``losses``: the damping ratio, friction and restitution (its pin is not
    used); a one-DOF system given as ``joint`` carries its own.
    """
    joint, losses, p = setup(joint, force_amplitude, omega, losses)
    state = initial_state(p, initial)
    x, v = float(state[kn.S_X]), float(state[kn.S_V])
    region, slip = int(state[kn.S_REGION]), int(state[kn.S_SLIP])
    f0, w = p[kn.P_F0], p[kn.P_W]
    g_c, g_t, e, ff = p[kn.P_GC], p[kn.P_GT], p[kn.P_E], p[kn.P_FF]
    tf = p[kn.P_TF]
    t_scale = kn.time_scale(p)
    x_scale = max(joint.clearance, f0 / joint.large_amplitude_stiffness)
    atol = [1e-14 * x_scale, 1e-14 * x_scale * 2 * math.pi / t_scale]
    strobe = np.zeros((n_periods, 2))
    events = 0
    t = 0.0
    x_max, x_min = -math.inf, math.inf
    for period in range(n_periods):
        t_end = (period + 1) * tf
        while True:
            k, fc = kn.region_force(p, region)
            if slip != 0 and kn.friction_active(p, region):
                fc -= slip * ff
            rhs, evs = _state_equations(p, region, slip, k, fc, x)
            sol = solve_ivp(
                rhs,
                (t, t_end),
                [x, v],
                method="DOP853",
                rtol=rtol,
                atol=atol,
                events=evs,
                max_step=t_scale / steps_per_period,
            )
            x_max = max(x_max, float(np.max(sol.y[0])))
            x_min = min(x_min, float(np.min(sol.y[0])))
            hit = [i for i, te in enumerate(sol.t_events) if len(te)]
            if not hit:
                t = t_end
                x, v = float(sol.y[0, -1]), float(sol.y[1, -1])
                break
            i = min(hit, key=lambda n: sol.t_events[n][0])
            t = float(sol.t_events[i][0])
            x, v = (float(val) for val in sol.y_events[i][0])
            events += 1
            phi = w * t
            if slip == 0:
                slip = 1 if i == 0 else -1
                v = 0.0
            elif i == 0:  # velocity zero
                v = 0.0
                slip = kn.decide_slip(p, region, x, phi)
            elif region == kn.FREE:
                side = 1 if i == 1 else -1
                x = g_c if side == 1 else -g_t
                v = e * v
                region = side
                if v == 0.0:
                    slip = kn.decide_slip(p, region, x, phi)
            else:
                x = g_c if region == kn.COMPRESSION else -g_t
                region = kn.FREE
        strobe[period] = (x, v)
    return ReferenceResponse(strobe=strobe, events=events, x_max=x_max, x_min=x_min)
