"""Independent reference routes used by the tests (never by the package).

The free-vibration period is integrated here with scipy's solve_ivp (DOP853),
one smooth state at a time, with event location at the gap edges and at the
turning points. Nothing from clearjoint.stiffness is used.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import simpson, solve_ivp

from clearjoint import Joint


def _region_force(joint: Joint, region: str) -> tuple[float, float]:
    """(stiffness, offset) with f(x) = stiffness * x - offset in that region."""
    k0 = joint.gap_stiffness
    if region == "compression":
        return k0 + joint.compression_stiffness, joint.compression_stiffness * joint.compression_gap
    if region == "tension":
        return k0 + joint.tension_stiffness, -joint.tension_stiffness * joint.tension_gap
    return k0, 0.0


def _half_swing(joint: Joint, x: float, direction: int, rtol: float) -> tuple[float, float]:
    """Integrate from a turning point x (v = 0) to the next turning point; return (time, x_end).

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

        def rhs(
            _t: float, y: np.ndarray, k: float = k, offset: float = offset, origin: float = origin
        ) -> list[float]:
            return [y[1], -(k * (y[0] + origin) - offset) / m]

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
            [x - origin, v],
            method="DOP853",
            rtol=rtol,
            atol=[1e-15 * scale, 1e-15 * scale * w_max],
            events=events,
            max_step=max_step,
        )
        if sol.status != 1:
            raise RuntimeError(f"reference integration did not reach an event: {sol.message}")
        hit = [i for i, te in enumerate(sol.t_events) if len(te)]
        i = hit[0]
        total += float(sol.t_events[i][0])
        x, v = (float(val) for val in sol.y_events[i][0])
        x += origin
        if i == 0:  # turning point
            return total, x
        x = edge  # land exactly on the edge before the next piece


def reference_period(joint: Joint, amplitude: float, rtol: float = 1e-11) -> float:
    """The free-vibration period at penetration A by numerical integration (solve_ivp)."""
    x_max = joint.compression_gap + amplitude
    t_down, x_min = _half_swing(joint, x_max, -1, rtol)
    t_up, _ = _half_swing(joint, x_min, +1, rtol)
    return t_down + t_up


def reference_describing_stiffness(joint: Joint, amplitude: float, n: int = 200_001) -> float:
    """First-harmonic stiffness by numerical Fourier projection of f(X sin theta)."""
    theta = np.linspace(0.0, 2.0 * math.pi, n)
    force = joint.restoring_force(amplitude * np.sin(theta))
    return float(simpson(force * np.sin(theta), x=theta) / (math.pi * amplitude))
