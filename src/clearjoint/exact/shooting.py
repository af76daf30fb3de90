"""The exact stroboscopic map over p forcing periods, its monodromy matrix, and Newton on it.

MODEL.md sec. 5.1: the map P_p(z0) carries z0 = (x, x') at forcing phase 0 over
p forcing periods with the exact event-driven flow (the same kernel as
``time_response``). Its Jacobian, the monodromy matrix, is exact: in each
state the flow is linear, Phi = exp(A tau) in closed form, and at each event on
a surface h(z) = 0 with jump z+ = R z- the saltation matrix

    S = R + (f+ - R f-) grad(h)^T / (grad(h) . f-)

is applied (Leine & Nijmeijer 2004, ch. 7), so M = Phi_k S_k ... S_1 Phi_1.
Events: a gap edge (grad h = (1, 0), R = diag(1, e) on entering contact), a
velocity zero (grad h = (0, 1); the vector field after it is that of the new
slip direction, or zero when the mass sticks), the release from stick (the
acceleration just after release is zero, so S = I). A sticking state's flow is
diag(1, 0): x' stays 0. Grazing (grad h . f- -> 0) makes S singular; the
smallest normalised approach speed at a gap edge is returned so that callers
can flag it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from clearjoint.compiled import prefer
from clearjoint.continuation import extrapolate, tangent_solve
from clearjoint.exact import kernel as kn
from clearjoint.jit import njit  # numba.njit that survives a read-only install

FloatArray = NDArray[np.float64]

# output vector layout of ``shoot_map``
O_XMAX, O_XMIN, O_EDGE_SPEED, O_EVENTS, O_M00, O_M01, O_M10, O_M11 = range(8)
O_DL0, O_DL1, O_DL_EXACT = 8, 9, 10  # dP/dlambda (x, x') and 1.0 when it was computed exactly
N_OUT = 11

# parameters whose sensitivity ``shoot_map`` can carry
NO_PARAMETER, PARAMETER_OMEGA, PARAMETER_FORCE = -1, 0, 1


@njit(cache=True)
def _acceleration(p: np.ndarray, region: int, slip: int, x: float, v: float, phi: float) -> float:
    """x'' from the equation of motion in a state (0 while sticking)."""
    if slip == 0:
        return 0.0
    k, fc = kn.region_force(p, region)
    if kn.friction_active(p, region):
        fc -= slip * p[kn.P_FF]
    return float((p[kn.P_F0] * math.sin(phi) + fc - k * x - p[kn.P_DAMP] * v) / p[kn.P_MASS])


@njit(cache=True)
def _flow(q: np.ndarray, slip: int, tau: float, phi_out: np.ndarray) -> None:
    """Write exp(A tau), the state's homogeneous flow over tau, into the 2x2 ``phi_out``."""
    if slip == 0:
        phi_out[0, 0] = 1.0
        phi_out[0, 1] = 0.0
        phi_out[1, 0] = 0.0
        phi_out[1, 1] = 0.0
        return
    alpha = q[kn.Q_ALPHA]
    e_part, g_part = kn.homogeneous_parts(alpha, q[kn.Q_D2], q[kn.Q_ROOT], tau)
    kq = q[kn.Q_K] / q[kn.Q_M]
    phi_out[0, 0] = e_part - g_part * alpha
    phi_out[0, 1] = g_part
    phi_out[1, 0] = -g_part * kq
    phi_out[1, 1] = e_part + g_part * alpha


@njit(cache=True)
def _left_multiply(a: np.ndarray, m: np.ndarray) -> None:
    """m <- a @ m for 2x2 arrays, in place."""
    m00 = a[0, 0] * m[0, 0] + a[0, 1] * m[1, 0]
    m01 = a[0, 0] * m[0, 1] + a[0, 1] * m[1, 1]
    m10 = a[1, 0] * m[0, 0] + a[1, 1] * m[1, 0]
    m11 = a[1, 0] * m[0, 1] + a[1, 1] * m[1, 1]
    m[0, 0] = m00
    m[0, 1] = m01
    m[1, 0] = m10
    m[1, 1] = m11


@njit(cache=True)
def _forced_sensitivity(
    p: np.ndarray, q: np.ndarray, parameter: int, theta: float
) -> tuple[float, float, bool]:
    """d/dlambda at fixed forcing phase ``theta`` of the forced particular solution.

    The particular solution of F0 sin(theta) in the state ``q`` is
    x_f = a sin(theta) + b cos(theta), x_f' = w (a cos(theta) - b sin(theta)), with
    a = F0 (k - m w^2) / D, b = -F0 c w / D, D = (k - m w^2)^2 + (c w)^2. Returns
    (d x_f, d x_f', True), or False when the state is undamped at exact resonance
    (the secular solution, not carried here).
    """
    k = q[kn.Q_K]
    c = q[kn.Q_C]
    m = q[kn.Q_M]
    w = p[kn.P_W]
    u = k - m * w * w
    det = u * u + (c * w) ** 2
    if not det > 0.0:
        return 0.0, 0.0, False
    sn = math.sin(theta)
    cs = math.cos(theta)
    if parameter == PARAMETER_FORCE:
        a1 = u / det
        b1 = -c * w / det
        return a1 * sn + b1 * cs, w * (a1 * cs - b1 * sn), True
    f0 = p[kn.P_F0]
    a = f0 * u / det
    b = -f0 * c * w / det
    det_w = -4.0 * m * w * u + 2.0 * c * c * w
    a_w = f0 * (-2.0 * m * w * det - u * det_w) / (det * det)
    b_w = -f0 * c * (det - w * det_w) / (det * det)
    return a_w * sn + b_w * cs, (a * cs - b * sn) + w * (a_w * cs - b_w * sn), True


@njit(cache=True)
def shoot_map(
    p: np.ndarray, state: np.ndarray, n_periods: int, out: np.ndarray, parameter: int = -1
) -> int:
    """Advance ``state`` (x, v, region, slip) over ``n_periods`` periods, with the monodromy.

    ``out`` receives x_max, x_min over the stretch, the smallest approach speed
    at a gap edge (inf if none), the number of events and the monodromy matrix
    M = dz(end)/dz(start) row by row. With ``parameter`` 0 (omega) or 1 (F0) it
    also receives dP/dlambda, the sensitivity of the end point to that parameter
    at the fixed start z0 (MODEL.md sec. 5.1), and 1.0 in ``O_DL_EXACT`` when it
    was carried exactly (0.0 when a state was undamped at exact resonance: the
    caller must then difference the map). Returns a kernel status code.

    The sensitivity sigma = dz/dlambda is taken at fixed forcing *phase*
    theta = w t, so that the end of the period (theta = 2 pi p) does not move
    with omega. In a state with homogeneous flow Phi(tau) it obeys
    sigma' = A sigma - z'/w for omega (sigma' = A sigma + (0, sin(theta)/m) for
    F0), whose solution over a segment of length tau from phase theta0 to theta1 is

        sigma1 = Phi(tau) (sigma0 - sf(theta0)) + sf(theta1) - (tau / w) (z1' - zf1')

    (the last term for omega only), sf being the derivative of the forced
    particular solution at fixed phase (``_forced_sensitivity``) and zf' its
    time derivative. The event surfaces (x at a gap edge, x' = 0) do not depend on
    the phase or the parameter, so sigma jumps by the same saltation matrix as the
    monodromy; at the release from stick, whose surface does, the vector field is
    zero on both sides and the jump is the identity; while sticking sigma stays.
    """
    tf = p[kn.P_TF]
    w = p[kn.P_W]
    e = p[kn.P_E]
    t_scale = kn.time_scale(p)
    x = state[kn.S_X]
    v = state[kn.S_V]
    region = int(state[kn.S_REGION])
    slip = int(state[kn.S_SLIP])
    mono = np.zeros((2, 2))
    mono[0, 0] = 1.0
    mono[1, 1] = 1.0
    phi_m = np.zeros((2, 2))
    sal = np.zeros((2, 2))
    x_max = x
    x_min = x
    edge_speed = math.inf
    n_events = 0
    s0 = 0.0  # sigma = dz/dlambda at fixed phase, from sigma = 0 at the start
    s1 = 0.0
    exact = parameter >= 0
    for _period in range(n_periods):
        t_in = 0.0
        events_here = 0
        while True:
            phase = w * t_in
            q = kn.phase_coefficients(p, region, slip, x, v, phase)
            tau, code = kn._next_event(p, q, region, slip, tf - t_in, t_scale)
            if code == kn.EV_MARCH_FAILED:
                return kn.STATUS_MARCH_FAILED
            if code == kn.EV_PERIOD_END:
                tau = tf - t_in
            x, v, acc, _ = kn.evaluate(q, slip, tau)
            _flow(q, slip, tau, phi_m)
            _left_multiply(phi_m, mono)
            if exact and slip != 0:
                f_x, f_v, ok = _forced_sensitivity(p, q, parameter, phase)
                if not ok:
                    exact = False
                else:
                    d0 = s0 - f_x
                    d1 = s1 - f_v
                    s0 = phi_m[0, 0] * d0 + phi_m[0, 1] * d1
                    s1 = phi_m[1, 0] * d0 + phi_m[1, 1] * d1
                    theta = phase + w * tau
                    f_x, f_v, _ = _forced_sensitivity(p, q, parameter, theta)
                    s0 += f_x
                    s1 += f_v
                    if parameter == PARAMETER_OMEGA:
                        # - (tau / w) times the velocity and acceleration less the forced part's
                        xf = q[kn.Q_A] * math.sin(theta) + q[kn.Q_B] * math.cos(theta)
                        vf = w * (q[kn.Q_A] * math.cos(theta) - q[kn.Q_B] * math.sin(theta))
                        s0 -= (tau / w) * (v - vf)
                        s1 -= (tau / w) * (acc + w * w * xf)
            x_max = max(x_max, x)
            x_min = min(x_min, x)
            t_in += tau
            if code == kn.EV_PERIOD_END:
                break
            n_events += 1
            events_here += 1
            if events_here > kn.MAX_EVENTS_PER_PERIOD:
                return kn.STATUS_TOO_MANY_EVENTS
            phase = w * t_in
            a_before = _acceleration(p, region, slip, x, v, phase)
            v_before = v
            x, v, new_region, new_slip, _, _ = kn.apply_event(p, code, x, v, region, slip, phase)
            a_after = _acceleration(p, new_region, new_slip, x, v, phase)
            v_after = v if new_slip != 0 else 0.0
            # saltation matrix S = R + (f+ - R f-) grad(h)^T / (grad(h) . f-)
            sal[0, 0] = 1.0
            sal[0, 1] = 0.0
            sal[1, 0] = 0.0
            sal[1, 1] = 1.0
            if code in (kn.EV_ENTER_COMPRESSION, kn.EV_ENTER_TENSION):
                edge_speed = min(edge_speed, abs(v_before))
                if v_before != 0.0:
                    sal[1, 1] = e
                    sal[0, 0] = 1.0 + (v_after - v_before) / v_before
                    sal[1, 0] = (a_after - e * a_before) / v_before
            elif code in (kn.EV_LEAVE_COMPRESSION, kn.EV_LEAVE_TENSION):
                edge_speed = min(edge_speed, abs(v_before))
                if v_before != 0.0:
                    sal[1, 0] = (a_after - a_before) / v_before
            elif code == kn.EV_VELOCITY_ZERO and a_before != 0.0:
                sal[1, 1] = a_after / a_before
            _left_multiply(sal, mono)
            s0, s1 = sal[0, 0] * s0 + sal[0, 1] * s1, sal[1, 0] * s0 + sal[1, 1] * s1
            region = new_region
            slip = new_slip
            x_max = max(x_max, x)
            x_min = min(x_min, x)
    state[kn.S_X] = x
    state[kn.S_V] = v
    state[kn.S_REGION] = region
    state[kn.S_SLIP] = slip
    out[O_XMAX] = x_max
    out[O_XMIN] = x_min
    out[O_EDGE_SPEED] = edge_speed
    out[O_EVENTS] = n_events
    out[O_M00] = mono[0, 0]
    out[O_M01] = mono[0, 1]
    out[O_M10] = mono[1, 0]
    out[O_M11] = mono[1, 1]
    out[O_DL0] = s0
    out[O_DL1] = s1
    out[O_DL_EXACT] = 1.0 if exact else 0.0
    return kn.STATUS_OK


@njit(cache=True)
def start_state(p: np.ndarray, x: float, v: float, state: np.ndarray) -> None:
    """The full kernel state (x, v, region, slip) of the point (x, v) at forcing phase 0."""
    region = kn.region_of(p, x, v)
    state[kn.S_X] = x
    state[kn.S_V] = v
    state[kn.S_REGION] = region
    if v > 0.0:
        state[kn.S_SLIP] = 1
    elif v < 0.0:
        state[kn.S_SLIP] = -1
    else:
        state[kn.S_SLIP] = kn.decide_slip(p, region, x, 0.0)


@dataclass(frozen=True)
class Shot:
    """One evaluation of the map P_p: end point, monodromy and extremes along the way.

    Attributes
    ----------
    end : (2,) ndarray
        (x, x') after the p periods, m and m/s.
    end_state : (4,) ndarray
        x, x', region, slip after the p periods (kernel layout).
    monodromy : (2, 2) ndarray
        dP_p / dz0.
    x_max, x_min : float
        Extremes of x along the stretch, m.
    edge_speed : float
        Smallest approach speed at a gap edge, m/s (inf when no edge is met).
    events : int
    """

    end: FloatArray
    end_state: FloatArray
    monodromy: FloatArray
    x_max: float
    x_min: float
    edge_speed: float
    events: int


class MapError(RuntimeError):
    """The kernel could not evaluate the map (carries the kernel status)."""

    def __init__(self, status: int) -> None:
        super().__init__(f"kernel status {status}")
        self.status = status


def shoot(p: FloatArray, z0: FloatArray, n_periods: int) -> Shot:
    """Evaluate the exact map P_p at z0 = (x, x') with its monodromy (MODEL.md sec. 5.1).

    Parameters
    ----------
    p : (13,) ndarray
        Kernel parameter vector (``core._parameters``).
    z0 : (2,) or (4,) ndarray
        (x, x') at forcing phase 0, or a full kernel state (x, x', region, slip).
    n_periods : int
        p, the number of forcing periods.

    Raises
    ------
    MapError
        The kernel stopped (a march out of steps, chattering).
    """
    state = np.zeros(4)
    if len(z0) == 4:
        state[:] = z0
    else:
        _start_state_compiled(p, float(z0[0]), float(z0[1]), state)
    out = np.zeros(N_OUT)
    status = _shoot_map_compiled(p, state, n_periods, out, NO_PARAMETER)
    if status != kn.STATUS_OK:
        raise MapError(status)
    return Shot(
        end=state[:2].copy(),
        end_state=state,
        monodromy=out[O_M00 : O_M11 + 1].reshape(2, 2).copy(),
        x_max=float(out[O_XMAX]),
        x_min=float(out[O_XMIN]),
        edge_speed=float(out[O_EDGE_SPEED]),
        events=int(out[O_EVENTS]),
    )


def newton_orbit(
    p: FloatArray,
    z0: FloatArray,
    n_periods: int,
    scale: FloatArray,
    *,
    tolerance: float = 1e-12,
    max_iterations: int = 30,
) -> tuple[FloatArray, Shot, int] | None:
    """Solve P_p(z) = z by Newton's method with the exact monodromy (MODEL.md sec. 5.1).

    Parameters
    ----------
    p : (13,) ndarray
        Kernel parameter vector.
    z0 : (2,) ndarray
        Starting guess (x, x') at forcing phase 0.
    n_periods : int
        p.
    scale : (2,) ndarray
        Sizes of x and x' that the tolerance is relative to.
    tolerance : float
        Converged when abs(P_p(z) - z) / scale <= tolerance in both components.

    Returns
    -------
    (z, shot, iterations), or None
        The fixed point, the map evaluated at it, and the Newton iterations used;
        None when Newton did not converge.
    """
    z = np.array(z0[:2], dtype=np.float64)
    for iteration in range(max_iterations + 1):
        try:
            shot = shoot(p, z, n_periods)
        except MapError:
            return None
        residual = shot.end - z
        if np.all(np.abs(residual) <= tolerance * scale):
            return z, shot, iteration
        jac = shot.monodromy - np.eye(2)
        try:
            step = np.linalg.solve(jac, -residual)
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(step)):
            return None
        # damp steps that would jump far across the state space
        size = float(np.max(np.abs(step) / scale))
        if size > 1.0:
            step /= size
        z = z + step
    return None


# residual vector layout of ``map_residual``
R_RES, R_JAC, R_DLAM, R_XMAX, R_XMIN, R_EDGE, R_EVENTS, R_EVALS = 0, 2, 6, 8, 9, 10, 11, 12
N_RES = 13


@njit(cache=True)
def set_parameter(p: np.ndarray, parameter: int, value: float) -> None:
    if parameter == 0:
        p[kn.P_W] = value
        p[kn.P_TF] = 2.0 * math.pi / value
    else:
        p[kn.P_F0] = value


@njit(cache=True)
def map_residual(
    p: np.ndarray,
    parameter: int,
    x: float,
    v: float,
    lam: float,
    out: np.ndarray,
    derivative: bool = True,
) -> int:
    """R = P_1(z) - z at parameter ``lam`` (0: omega, 1: F0), dR/dz and dR/dlam, in one call.

    ``out`` receives R (2), dR/dz = M - I row by row (4), dR/dlam (2), then
    x_max, x_min, the smallest approach speed at an edge and the number of
    events; ``out[R_EVALS]`` is incremented by the evaluations of the map made
    (1, or 2 with the difference), so that a caller can count them. dR/dlam =
    dP/dlam is carried exactly through the segments and events by ``shoot_map``
    (no second evaluation of the map); only where a state is undamped at exact
    resonance is it a forward difference of the exact map with step 1e-7 lam.
    Without ``derivative`` dR/dlam is not computed (left as it is in ``out``).
    Returns a kernel status code.
    """
    q = p.copy()
    set_parameter(q, parameter, lam)
    state = np.zeros(4)
    start_state(q, x, v, state)
    o1 = np.zeros(N_OUT)
    # int(1), not 1: numba compiles a callee afresh for a literal argument (Literal[int])
    once = int(1)  # noqa: UP018, RUF046
    status = shoot_map(q, state, once, o1, int(parameter if derivative else NO_PARAMETER))
    out[R_EVALS] += 1.0
    if status != kn.STATUS_OK:
        return status
    if derivative:
        if o1[O_DL_EXACT] == 1.0:
            out[R_DLAM] = o1[O_DL0]
            out[R_DLAM + 1] = o1[O_DL1]
        else:
            delta = 1e-7 * lam
            set_parameter(q, parameter, lam + delta)
            shifted = np.zeros(4)
            start_state(q, x, v, shifted)
            o2 = np.zeros(N_OUT)
            status = shoot_map(q, shifted, once, o2, int(NO_PARAMETER))
            out[R_EVALS] += 1.0
            if status != kn.STATUS_OK:
                return status
            out[R_DLAM] = (shifted[kn.S_X] - state[kn.S_X]) / delta
            out[R_DLAM + 1] = (shifted[kn.S_V] - state[kn.S_V]) / delta
    out[R_RES] = state[kn.S_X] - x
    out[R_RES + 1] = state[kn.S_V] - v
    out[R_JAC] = o1[O_M00] - 1.0
    out[R_JAC + 1] = o1[O_M01]
    out[R_JAC + 2] = o1[O_M10]
    out[R_JAC + 3] = o1[O_M11] - 1.0
    out[R_XMAX] = o1[O_XMAX]
    out[R_XMIN] = o1[O_XMIN]
    out[R_EDGE] = o1[O_EDGE_SPEED]
    out[R_EVENTS] = o1[O_EVENTS]
    return kn.STATUS_OK


@njit(cache=True)
def _solve3(a: np.ndarray, b: np.ndarray, x: np.ndarray) -> bool:
    """x <- a^-1 b for a 3x3 system by Gaussian elimination with partial pivoting.

    Returns False when a pivot vanishes (singular) or a value is not finite.
    """
    m = np.empty((3, 4))
    for i in range(3):
        for j in range(3):
            m[i, j] = a[i, j]
        m[i, 3] = b[i]
    for col in range(3):
        pivot = col
        for row in range(col + 1, 3):
            if abs(m[row, col]) > abs(m[pivot, col]):
                pivot = row
        if m[pivot, col] == 0.0 or not np.isfinite(m[pivot, col]):
            return False
        if pivot != col:
            for j in range(4):
                m[col, j], m[pivot, j] = m[pivot, j], m[col, j]
        for row in range(col + 1, 3):
            f = m[row, col] / m[col, col]
            for j in range(col, 4):
                m[row, j] -= f * m[col, j]
    for i in range(2, -1, -1):
        s = m[i, 3]
        for j in range(i + 1, 3):
            s -= m[i, j] * x[j]
        x[i] = s / m[i, i]
    return bool(np.isfinite(x[0]) and np.isfinite(x[1]) and np.isfinite(x[2]))


@njit(cache=True)
def correct_orbit(
    p: np.ndarray,
    parameter: int,
    y0: np.ndarray,
    tangent: np.ndarray,
    scale: np.ndarray,
    fixed_lambda: bool,
    tolerance: float,
    max_iterations: int,
    y: np.ndarray,
    system: np.ndarray,
    out: np.ndarray,
) -> int:
    """The continuation's corrector for R(z, lam) = P_1(z; lam) - z, compiled (MODEL.md sec. 5.1).

    Newton in scaled coordinates y = (x, x', lam) / ``scale`` on R(y) = 0 together
    with ``tangent . (y - y0) = 0`` (or lam fixed), exactly as
    ``continuation._correct`` with a chord in the parameter column (dR/dlam, exact
    from ``map_residual``, taken at the first iteration only: full Newton steps
    across the square-root kink of a grazing with impacts, where the chord stops
    and the continuation finds and reports the kink). On success ``y`` holds the
    solution, ``system`` (3, 3) the scaled [dR/du, dR/dlam] in its first two rows, ``out`` the
    ``map_residual`` data there, and the iterations are returned; -1 on failure
    (a kernel failure, a parameter <= 0, a value not finite, no convergence).
    """
    for i in range(3):
        y[i] = y0[i]
    if fixed_lambda:
        system[2, 0] = 0.0
        system[2, 1] = 0.0
        system[2, 2] = 1.0
    else:
        for i in range(3):
            system[2, i] = tangent[i]
    rhs = np.empty(3)
    dy = np.empty(3)
    for iteration in range(max_iterations + 1):
        lam = y[2] * scale[2]
        if not lam > 0.0:
            return -1
        derivative = iteration == 0
        status = map_residual(p, parameter, y[0] * scale[0], y[1] * scale[1], lam, out, derivative)
        if status != kn.STATUS_OK:
            return -1
        if derivative:
            system[0, 2] = out[R_DLAM] * (scale[2] / scale[0])
            system[1, 2] = out[R_DLAM + 1] * (scale[2] / scale[1])
        system[0, 0] = out[R_JAC]
        system[0, 1] = out[R_JAC + 1] * (scale[1] / scale[0])
        system[1, 0] = out[R_JAC + 2] * (scale[0] / scale[1])
        system[1, 1] = out[R_JAC + 3]
        r0 = out[R_RES] / scale[0]
        r1 = out[R_RES + 1] / scale[1]
        size = max(abs(r0), abs(r1))
        if not np.isfinite(size):
            return -1
        for i in range(2):
            for j in range(3):
                if not np.isfinite(system[i, j]):
                    return -1
        if size <= tolerance:
            return iteration
        if iteration == max_iterations:
            return -1
        rhs[0] = -r0
        rhs[1] = -r1
        if fixed_lambda:
            rhs[2] = 0.0
        else:
            rhs[2] = -(
                tangent[0] * (y[0] - y0[0])
                + tangent[1] * (y[1] - y0[1])
                + tangent[2] * (y[2] - y0[2])
            )
        if not _solve3(system, rhs, dy):
            return -1
        for i in range(3):
            y[i] += dy[i]
    return -1


@njit(cache=True)
def arclength_step(
    p: np.ndarray,
    parameter: int,
    points: np.ndarray,
    h: float,
    tangent: np.ndarray,
    curvature: np.ndarray,
    scale: np.ndarray,
    tolerance: float,
    max_iterations: int,
    y: np.ndarray,
    system: np.ndarray,
    out: np.ndarray,
    t_new: np.ndarray,
) -> int:
    """One ordinary step of the continuation, compiled: predict, correct, new tangent.

    The predictor is ``continuation``'s: the polynomial through the rows of
    ``points`` (scaled) at chord length ``h`` past the last when it has more than
    one row, else ``points[0] + h tangent + (h^2 / 2) curvature``. Then
    ``correct_orbit`` (arclength condition along ``tangent``) and, on success, the
    unit tangent of the solution in ``t_new``, oriented along ``tangent``
    (``continuation._tangent``; NaN when that 3x3 solve is singular, for the caller
    to fall back on its SVD). Returns the corrector's iterations, -1 on failure.
    """
    if points.shape[0] > 1:
        predicted = extrapolate(points, h)
    else:
        predicted = np.empty(3)
        for i in range(3):
            predicted[i] = points[0, i] + h * tangent[i] + 0.5 * h * h * curvature[i]
    its = correct_orbit(
        p,
        parameter,
        predicted,
        tangent,
        scale,
        bool(False),  # noqa: UP018 (not a literal: one compiled copy of the callee)
        tolerance,
        max_iterations,
        y,
        system,
        out,
    )
    if its < 0:
        return its
    a = np.empty((2, 3))
    for i in range(2):
        for j in range(3):
            a[i, j] = system[i, j]
    if not tangent_solve(a, tangent, t_new):
        t_new[:] = np.nan
        return its
    if t_new[0] * tangent[0] + t_new[1] * tangent[1] + t_new[2] * tangent[2] < 0.0:
        for i in range(3):
            t_new[i] = -t_new[i]
    return its


# for Python callers: the kernels as compiled at install where that is usable (numba
# kernels above call the dispatchers themselves)
_start_state_compiled = prefer(start_state)
_shoot_map_compiled = prefer(shoot_map)
