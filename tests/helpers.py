"""Independent reference routes used by the tests (never by the package).

The free-vibration period is integrated here with scipy's solve_ivp (DOP853),
one smooth state at a time, with event location at the gap edges and at the
turning points. Nothing from clearjoint.stiffness is used.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from scipy.integrate import simpson, solve_ivp

from clearjoint import Joint

#: The paper's first clearance, m.
C1 = 0.106e-3


def joint(**changes: float) -> Joint:
    """A 2 kg joint with c = 0.106 mm and k_c = 80 MN/m, with ``changes`` applied."""
    values = {"mass": 2.0, "clearance": C1, "compression_stiffness": 8e7}
    values.update(changes)
    return Joint(**values)


#: Joints that exercise every branch of the period and the free cycle.
CASES = {
    "symmetric": joint(),
    "asymmetric": joint(tension_stiffness=3e7),
    "gap spring": joint(tension_stiffness=3e7, gap_stiffness=1e6),
    "off-centre": joint(tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=0.03e-3),
    "off-centre, tension edge far": joint(gap_stiffness=4e6, gap_offset=-0.045e-3),
    "off-centre, k0 = 0": joint(tension_stiffness=5e7, gap_offset=0.02e-3),
}


def _region_force(joint: Joint, region: str) -> tuple[float, float]:
    """(stiffness, offset) with f(x) = stiffness * x - offset in that region."""
    k0 = joint.gap_stiffness
    if region == "compression":
        return k0 + joint.compression_stiffness, joint.compression_stiffness * joint.compression_gap
    if region == "tension":
        return k0 + joint.tension_stiffness, -joint.tension_stiffness * joint.tension_gap
    return k0, 0.0


def _half_swing(
    joint: Joint, x: float, direction: int, rtol: float
) -> tuple[float, float, np.ndarray]:
    """Integrate from a turning point x (v = 0) to the next turning point.

    Returns (time, x_end, integrals) with integrals = [int v^2 dt, int v^2 dt in the
    gap, int |v| dt, int F_n^1.5 |v| dt], carried as extra states of the ODE.
    ``direction`` is -1 for a swing toward tension, +1 toward compression.
    Within a swing x is monotonic, so each smooth piece ends either at the next
    gap edge in the direction of travel or at the turning point.
    """
    m = joint.mass
    g_c, g_t = joint.compression_gap, joint.tension_gap
    scale = max(joint.clearance, abs(x), 1e-9)
    k_soft, k_hard = sorted((joint.compression_stiffness, joint.tension_stiffness))
    w_max = math.sqrt((joint.gap_stiffness + k_hard) / m)
    w_min = math.sqrt((joint.gap_stiffness + k_soft) / m)
    total = 0.0
    v = 0.0
    integrals = np.zeros(4)
    while True:
        probe = x + direction * 1e-12 * scale
        if probe > g_c:
            region = "compression"
        elif probe < -g_t:
            region = "tension"
        else:
            region = "free"
        k, offset = _region_force(joint, region)
        # integrate the distance from the region's own edge, so that rtol applies
        # to the penetration, not to the gap it sits beyond
        origin = {"compression": g_c, "tension": -g_t, "free": 0.0}[region]

        contact_k = {
            "compression": joint.compression_stiffness,
            "tension": -joint.tension_stiffness,
            "free": 0.0,
        }[region]
        in_gap = 1.0 if region == "free" else 0.0

        def rhs(
            _t: float,
            y: np.ndarray,
            k: float = k,
            offset: float = offset,
            origin: float = origin,
            contact_k: float = contact_k,
            in_gap: float = in_gap,
        ) -> list[float]:
            speed = abs(y[1])
            force = max(contact_k * y[0], 0.0)
            return [
                y[1],
                -(k * (y[0] + origin) - offset) / m,
                y[1] ** 2,
                in_gap * y[1] ** 2,
                speed,
                force**1.5 * speed,
            ]

        def turning(_t: float, y: np.ndarray) -> float:
            return float(y[1])

        turning.terminal = True  # type: ignore[attr-defined]
        # moving down (v < 0) ends where v rises through 0, and vice versa
        turning.direction = -direction  # type: ignore[attr-defined]
        events = [turning]
        if region == "compression" and direction < 0:
            edge = g_c
        elif region == "tension" and direction > 0:
            edge = -g_t
        elif region == "free":
            edge = -g_t if direction < 0 else g_c
        else:
            edge = None
        if edge is not None:

            def crossing(_t: float, y: np.ndarray, level: float = edge - origin) -> float:
                return float(y[0] - level)

            crossing.terminal = True  # type: ignore[attr-defined]
            crossing.direction = direction  # type: ignore[attr-defined]
            events.append(crossing)
        # a generous horizon: a hundred of the slowest oscillations or crossings
        omegas = [w for w in (math.sqrt(joint.gap_stiffness / m), w_min) if w > 0.0]
        slow = max(abs(v), 1e-3 * scale * w_min)
        horizon = 100.0 * (2.0 * math.pi / min(omegas) + 2.0 * scale / slow)
        # with k0 > 0 a free-play swing may pass an edge by a hair and come back
        # within one step; a bounded step keeps such a crossing from being missed
        max_step = np.inf
        if region == "free" and joint.gap_stiffness > 0.0:
            max_step = 2.0 * math.pi / math.sqrt(joint.gap_stiffness / m) / 2000.0
        sol = solve_ivp(
            rhs,
            (0.0, horizon),
            [x - origin, v, 0.0, 0.0, 0.0, 0.0],
            method="DOP853",
            rtol=rtol,
            atol=1e-15
            * np.array(
                [
                    scale,
                    scale * w_max,
                    scale**2 * w_max,
                    scale**2 * w_max,
                    scale,
                    (k_hard * scale) ** 1.5 * scale,
                ]
            ),
            events=events,
            max_step=max_step,
        )
        if sol.status != 1:
            raise RuntimeError(f"reference integration did not reach an event: {sol.message}")
        hit = [i for i, te in enumerate(sol.t_events) if len(te)]
        i = hit[0]
        total += float(sol.t_events[i][0])
        state = sol.y_events[i][0]
        x, v = float(state[0]) + origin, float(state[1])
        integrals += state[2:]
        if i == 0:  # turning point
            return total, x, integrals
        x = edge  # land exactly on the edge before the next piece


def reference_period(joint: Joint, amplitude: float, rtol: float = 1e-11) -> float:
    """The free-vibration period at penetration A by numerical integration (solve_ivp)."""
    return reference_cycle(joint, amplitude, rtol)[0]


def reference_cycle(
    joint: Joint, amplitude: float, rtol: float = 1e-11
) -> tuple[float, np.ndarray]:
    """(period, integrals over the free cycle) by numerical integration; see _half_swing."""
    x_max = joint.compression_gap + amplitude
    t_down, x_min, first = _half_swing(joint, x_max, -1, rtol)
    t_up, _, second = _half_swing(joint, x_min, +1, rtol)
    return t_down + t_up, first + second


def reference_describing_stiffness(joint: Joint, amplitude: float, n: int = 200_001) -> float:
    """First-harmonic stiffness by numerical Fourier projection of f(X sin theta)."""
    theta = np.linspace(0.0, 2.0 * math.pi, n)
    force = joint.restoring_force(amplitude * np.sin(theta))
    return float(simpson(force * np.sin(theta), x=theta) / (math.pi * amplitude))


def check_tangent_stiffness(
    force: object, tangent: object, points: np.ndarray, step: float, rtol: float = 1e-6
) -> None:
    """Assert that ``tangent(points)`` matches central differences of ``force`` (shared helper).

    ``force`` and ``tangent`` map an array of relative displacements (any shape) to an
    array of the same shape; ``points`` must stay at least ``step`` away from any kink.
    """
    points = np.asarray(points, dtype=np.float64)
    f_plus = np.asarray(force(points + step))  # type: ignore[operator]
    f_minus = np.asarray(force(points - step))  # type: ignore[operator]
    numeric = (f_plus - f_minus) / (2.0 * step)
    analytic = np.asarray(tangent(points))  # type: ignore[operator]
    assert analytic.shape == points.shape
    scale = max(float(np.max(np.abs(analytic))), 1e-300)
    np.testing.assert_allclose(analytic, numeric, rtol=0.0, atol=rtol * scale)


#: A study file of a joint without clearance, zeta = 0.05: the forced linear oscillator
#: (m = 2 kg, k = 80 MN/m) whose closed forms the sweep tests compare with.
LINEAR_STUDY = """
[joint]
mass = "2kg"
clearance = "0mm"
compression_stiffness = "8e7N/m"
[excitation]
force_amplitude = "100N"
frequency = "300Hz"
[losses]
damping_ratio = 0.05
"""


def with_losses(keywords: Mapping[str, Any]) -> dict[str, Any]:
    """``keywords`` with the loss keywords among them moved into one ``losses=Losses(...)``.

    For tests that build one set of keywords for several solvers (since issue 23 the
    solvers take the losses as one value).
    """
    from clearjoint import Losses
    from clearjoint.joint import LOSS_KEYWORDS

    rest = {k: v for k, v in keywords.items() if k not in LOSS_KEYWORDS}
    losses = {k: v for k, v in keywords.items() if k in LOSS_KEYWORDS}
    return {**rest, "losses": Losses(**losses)} if losses else rest


def check_progress_lines(err: str, first: str) -> None:
    """A command's stderr without a terminal: ``first``, then a line a report whose share
    rises to 100 % and which ends with the time left (the compile line of a first run
    left out)."""
    lines = [line for line in err.splitlines() if "compiling the solvers" not in line]
    assert lines[0] == first
    shares = [int(line.split(": ")[1].split(" %")[0]) for line in lines[1:]]
    assert len(shares) > 10  # about one a piece (the first starts the clock)
    assert shares == sorted(shares)
    assert shares[-1] == 100
    assert all(line.endswith(" left") for line in lines[1:])
