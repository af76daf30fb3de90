"""The event-driven core: exact piecewise closed-form motion, compiled with numba.

Equation of motion (MODEL.md sec. 2, without the contact-friction term):

    m x'' + c_v x' + f(x) + F_f s = F0 sin(w t),   s = sign(x') while slipping

In each state (region free / compression / tension, slip direction or stick)
this is linear with constant coefficients, so the motion is

    x(tau) = homogeneous(tau) + a sin(phi + w tau) + b cos(phi + w tau) + constant part

in closed form. Events (a gap edge reached, velocity zero, the end of a sticking
phase, the end of a forcing period) are the first roots of the closed form. They
are found by *certified marching*: at each point the Taylor polynomial of the event
function to second order, minus a rigorous bound on its third derivative, is a
lower bound valid over the whole state; stepping to the first root of that bound
never passes a root, grazing included, and converges like Newton's method near a
transversal crossing.

Why numba: a pure-Python evaluation of the closed form costs microseconds and an
event needs ten to twenty of them, so plain Python reaches about 10^4 events per
second; the issue's target is 10^5. The loop is inherently sequential (each event
starts from the last), so numpy vectorisation does not apply.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from clearjoint.jit import njit  # numba.njit that survives a read-only install
from clearjoint.laws import clearance

# ---- parameter vector layout -------------------------------------------------------------
P_MASS, P_DAMP, P_K0, P_KC, P_KT, P_GC, P_GT, P_F0, P_W, P_FF, P_E, P_FMODE, P_TF = range(13)
N_PARAMS = 13

# friction modes
FRICTION_NONE, FRICTION_EVERYWHERE, FRICTION_FREE_PLAY = 0, 1, 2

# regions: the law's contact states (FREE is the kernel's name of OPEN)
FREE, COMPRESSION, TENSION = clearance.OPEN, clearance.COMPRESSION, clearance.TENSION

# state vector layout: x, v, region, slip (-1, 0 = stick, +1)
S_X, S_V, S_REGION, S_SLIP = range(4)

# event codes
EV_ENTER_COMPRESSION = 1
EV_ENTER_TENSION = 2
EV_LEAVE_COMPRESSION = 3
EV_LEAVE_TENSION = 4
EV_VELOCITY_ZERO = 5
EV_RELEASE_UP = 6
EV_RELEASE_DOWN = 7
EV_PERIOD_END = 8
EV_MARCH_FAILED = 9

# segment record layout
SEG_PERIOD, SEG_T0, SEG_DT, SEG_REGION, SEG_SLIP, SEG_X0, SEG_V0, SEG_PHI = range(8)
SEG_WIDTH = 8
# impact record layout: period, time in period, approach speed, side (+1 / -1)
IMP_WIDTH = 4
# ledger layout per period
L_INPUT, L_VISCOUS, L_SLIDING, L_IMPACT = range(4)
LEDGER_WIDTH = 4

STATUS_OK, STATUS_SEGMENTS_FULL, STATUS_TOO_MANY_EVENTS, STATUS_MARCH_FAILED = 0, 1, 2, 3

MAX_EVENTS_PER_PERIOD = 100_000
#: Certified steps allowed to reach one event; a state that needs more is an error
#: (``EV_MARCH_FAILED``), never a silent jump to the end of the period.
MAX_MARCH_STEPS = 100_000

# 8-point Gauss-Legendre rule on [-1, 1]
_GL_X = np.array(
    [
        -0.9602898564975363,
        -0.7966664774136267,
        -0.5255324099163290,
        -0.1834346424956498,
        0.1834346424956498,
        0.5255324099163290,
        0.7966664774136267,
        0.9602898564975363,
    ]
)
_GL_W = np.array(
    [
        0.1012285362903763,
        0.2223810344533745,
        0.3137066458778873,
        0.3626837833783620,
        0.3626837833783620,
        0.3137066458778873,
        0.2223810344533745,
        0.1012285362903763,
    ]
)

# phase-coefficient vector layout
Q_K, Q_C, Q_M, Q_ALPHA, Q_D2, Q_ROOT, Q_XH, Q_VH, Q_A, Q_B = range(10)
Q_SEC, Q_SECULAR, Q_CONST_KIND, Q_FC, Q_PHI, Q_W, Q_XSTICK, Q_V0 = range(10, 18)
N_Q = 18


@njit(cache=True)
def region_force(p: np.ndarray, region: int) -> tuple[float, float]:
    """(K, Fc): the restoring force in ``region`` is K x - Fc (MODEL.md sec. 0).

    :func:`clearjoint.laws.clearance.state_law` on the parameter vector's law.
    """
    return clearance.state_law(region, p[P_K0], p[P_KC], p[P_KT], p[P_GC], p[P_GT])


@njit(cache=True)
def friction_active(p: np.ndarray, region: int) -> bool:
    """Whether sliding friction acts in ``region``."""
    mode = int(p[P_FMODE])
    if p[P_FF] <= 0.0 or mode == FRICTION_NONE:
        return False
    return mode == FRICTION_EVERYWHERE or region == FREE


@njit(cache=True)
def phase_coefficients(
    p: np.ndarray, region: int, slip: int, x0: float, v0: float, phi: float
) -> np.ndarray:
    """Coefficients of the closed-form motion in one state, from (x0, v0) at forcing phase phi."""
    q = np.zeros(N_Q)
    m = p[P_MASS]
    c = p[P_DAMP]
    w = p[P_W]
    f0 = p[P_F0]
    k, fc = region_force(p, region)
    if slip != 0 and friction_active(p, region):
        fc -= slip * p[P_FF]
    q[Q_K] = k
    q[Q_C] = c
    q[Q_M] = m
    q[Q_FC] = fc
    q[Q_PHI] = phi
    q[Q_W] = w
    q[Q_XSTICK] = x0
    q[Q_V0] = v0
    if slip == 0:
        return q  # sticking: x stays at x0
    alpha = -c / (2.0 * m)
    d2 = alpha * alpha - k / m
    q[Q_ALPHA] = alpha
    q[Q_D2] = d2
    q[Q_ROOT] = math.sqrt(abs(d2))
    # particular solution of the harmonic force
    det = (k - m * w * w) ** 2 + (c * w) ** 2
    sn = math.sin(phi)
    cs = math.cos(phi)
    if det > 0.0:
        a = f0 * (k - m * w * w) / det
        b = -f0 * c * w / det
        q[Q_A] = a
        q[Q_B] = b
        xp0 = a * sn + b * cs
        vp0 = w * (a * cs - b * sn)
    else:  # undamped state exactly at resonance: C tau cos(phi + w tau)
        sec = -f0 / (2.0 * m * w)
        q[Q_SEC] = sec
        q[Q_SECULAR] = 1.0
        xp0 = 0.0
        vp0 = sec * cs
    # particular solution of the constant force
    if k > 0.0:
        q[Q_CONST_KIND] = 0.0
        xc0 = fc / k
        vc0 = 0.0
    elif c > 0.0:
        q[Q_CONST_KIND] = 1.0
        xc0 = 0.0
        vc0 = fc / c
    else:
        q[Q_CONST_KIND] = 2.0
        xc0 = 0.0
        vc0 = 0.0
    q[Q_XH] = x0 - xp0 - xc0
    q[Q_VH] = v0 - vp0 - vc0
    return q


@njit(cache=True)
def homogeneous_parts(alpha: float, d2: float, root: float, tau: float) -> tuple[float, float]:
    """e(tau) and g(tau) of the homogeneous flow x_h = e x_h0 + g (v_h0 - alpha x_h0).

    Under-damped (d2 < 0), over-damped (d2 > 0, with expm1 for small root tau) and
    critical; shared by evaluate and the monodromy flow of the shooting (exact/shooting.py).
    """
    if d2 < 0.0:
        ea = math.exp(alpha * tau)
        e_part = ea * math.cos(root * tau)
        g_part = ea * math.sin(root * tau) / root
    elif d2 > 0.0:
        em = math.exp((alpha - root) * tau)
        ep = math.exp((alpha + root) * tau)
        e_part = 0.5 * (ep + em)
        if 2.0 * root * tau < 1.0:
            g_part = em * math.expm1(2.0 * root * tau) / (2.0 * root)
        else:
            g_part = (ep - em) / (2.0 * root)
    else:
        e_part = math.exp(alpha * tau)
        g_part = tau * e_part
    return e_part, g_part


@njit(cache=True)
def evaluate(q: np.ndarray, slip: int, tau: float) -> tuple[float, float, float, float]:
    """x, x', x'', x''' at time tau into the state described by ``q``."""
    if slip == 0:
        return q[Q_XSTICK], 0.0, 0.0, 0.0
    k = q[Q_K]
    m = q[Q_M]
    alpha = q[Q_ALPHA]
    xh0 = q[Q_XH]
    vh0 = q[Q_VH]
    e_part, g_part = homogeneous_parts(alpha, q[Q_D2], q[Q_ROOT], tau)
    kq = k / m
    xh = e_part * xh0 + g_part * (vh0 - alpha * xh0)
    vh = e_part * vh0 + g_part * (alpha * vh0 - kq * xh0)
    ah = -kq * xh + 2.0 * alpha * vh
    jh = -kq * vh + 2.0 * alpha * ah
    w = q[Q_W]
    theta = q[Q_PHI] + w * tau
    sn = math.sin(theta)
    cs = math.cos(theta)
    if q[Q_SECULAR] == 0.0:
        a = q[Q_A]
        b = q[Q_B]
        xp = a * sn + b * cs
        vp = w * (a * cs - b * sn)
        ap = -w * w * xp
        jp = -w * w * vp
    else:
        sec = q[Q_SEC]
        xp = sec * tau * cs
        vp = sec * cs - sec * w * tau * sn
        ap = -2.0 * sec * w * sn - sec * w * w * tau * cs
        jp = -3.0 * sec * w * w * cs + sec * w * w * w * tau * sn
    kind = q[Q_CONST_KIND]
    fc = q[Q_FC]
    if kind == 0.0:
        xc = fc / k
        vc = 0.0
        ac = 0.0
    elif kind == 1.0:
        xc = fc * tau / q[Q_C]
        vc = fc / q[Q_C]
        ac = 0.0
    else:
        xc = 0.5 * fc * tau * tau / m
        vc = fc * tau / m
        ac = fc / m
    return xh + xp + xc, vh + vp + vc, ah + ap + ac, jh + jp


@njit(cache=True)
def derivative_bounds(q: np.ndarray, tau_max: float) -> tuple[float, float]:
    """Bounds on abs(x''') and abs(x'''') over 0 <= tau <= tau_max in one state.

    Homogeneous part: its energy (m v^2 + k x^2)/2 never grows, so each
    derivative is bounded by (w_k + c/m)^n sqrt(x_h^2 + v_h^2 m/k); with k = 0 it
    is a decaying exponential. Forced part: its amplitude times w^n.
    """
    k = q[Q_K]
    m = q[Q_M]
    c = q[Q_C]
    w = q[Q_W]
    xh0 = q[Q_XH]
    vh0 = q[Q_VH]
    if k > 0.0:
        base = math.sqrt(xh0 * xh0 + vh0 * vh0 * m / k)
        rate = math.sqrt(k / m) + c / m
        b3 = base * rate**3
        b4 = base * rate**4
    elif c > 0.0:
        rate = c / m
        b3 = abs(vh0) * rate**2
        b4 = abs(vh0) * rate**3
    else:
        b3 = 0.0
        b4 = 0.0
    if q[Q_SECULAR] == 0.0:
        amp = math.hypot(q[Q_A], q[Q_B])
        b3 += amp * w**3
        b4 += amp * w**4
    else:
        sec = abs(q[Q_SEC])
        b3 += sec * (3.0 * w * w + w**3 * tau_max)
        b4 += sec * (4.0 * w**3 + w**4 * tau_max)
    return b3, b4


@njit(cache=True)
def _cubic(g0: float, g1: float, g2: float, bound: float, h: float) -> float:
    return g0 + h * (g1 + h * (0.5 * g2 - bound * h / 6.0))


@njit(cache=True)
def _monotone_root(g0: float, g1: float, g2: float, bound: float, lo: float, hi: float) -> float:
    """A point just below the root of the cubic bound on [lo, hi] (> 0 at lo, <= 0 at hi).

    Newton's method safeguarded by the bracket; the value returned always keeps
    the bound positive, so the step it gives stays certified. The bracket is
    first cut at the inflection point g2 / bound, so that the cubic is convex
    or concave on it and Newton's iterates approach the root from one side: from
    ``lo`` on a convex piece; on a concave piece from the root of the quadratic
    Taylor polynomial at ``lo``, which lies right of the root (the cubic's third
    derivative is negative). Once a step moves less than 1e-10 of the point, the
    point 5e-10 of it below the root is returned (or ``lo``, if higher) when the
    bound is positive there. About five evaluations, where bisection from the far end of a long
    bracket took thirty or more.
    """
    inflection = g2 / bound
    if lo < inflection < hi:
        if _cubic(g0, g1, g2, bound, inflection) > 0.0:
            lo = inflection
        else:
            hi = inflection
    x = lo
    if lo >= inflection:  # concave on [lo, hi]: start right of the root
        value = _cubic(g0, g1, g2, bound, lo)
        slope = g1 + lo * (g2 - 0.5 * bound * lo)
        curvature = g2 - bound * lo
        denominator = -slope + math.sqrt(max(slope * slope - 2.0 * curvature * value, 0.0))
        x = min(lo + 2.0 * value / denominator, hi) if denominator > 0.0 else hi
    for _ in range(100):
        value = _cubic(g0, g1, g2, bound, x)
        if value > 0.0:
            lo = x
        else:
            hi = x
        if hi - lo <= 1e-9 * hi:
            break
        slope = g1 + x * (g2 - 0.5 * bound * x)
        step = x - value / slope if slope < 0.0 else hi
        if abs(step - x) <= 1e-10 * x:  # Newton has converged on the root: step just below it
            trial = step - 5e-10 * x  # (below lo the bound is positive already)
            if trial > 0.0 and (trial <= lo or _cubic(g0, g1, g2, bound, trial) > 0.0):
                return max(trial, lo)
        x = step if lo < step < hi else 0.5 * (lo + hi)
    return lo


@njit(cache=True)
def certified_step(
    g0: float,
    g1: float,
    g2: float,
    bound: float,
    h_max: float,
    g3: float = 0.0,
    bound4: float = 0.0,
) -> float:
    """Largest h <= h_max with g > 0 on (0, h) guaranteed, given g(0) = g0 >= 0.

    g(h) >= g0 + g1 h + g2 h^2/2 - bound h^3/6 =: p(h); return the first positive
    root of p (or h_max if p stays positive up to it). When g0 = g1 = g2 = 0 the
    third derivative g3 decides, with ``bound4`` bounding the fourth:
    g(h) >= g3 h^3/6 - bound4 h^4/24 > 0 for h < 4 g3 / bound4.
    """
    if g0 <= 0.0 and g1 == 0.0 and g2 == 0.0 and g3 > 0.0 and bound4 > 0.0:
        return min(h_max, 4.0 * g3 / bound4)
    if g0 <= 0.0 and (g1 < 0.0 or (g1 == 0.0 and g2 <= 0.0)):
        return 0.0
    g0 = max(g0, 0.0)
    if bound <= 0.0:
        bound = 1e-300
    # critical points of p: g1 + g2 h - bound h^2 / 2 = 0
    lo = 0.0
    disc = g2 * g2 + 2.0 * bound * g1
    if disc > 0.0:
        sq = math.sqrt(disc)
        r1 = (g2 - sq) / bound
        r2 = (g2 + sq) / bound
        for r in (r1, r2):
            if r > lo:
                if r >= h_max:
                    break
                if _cubic(g0, g1, g2, bound, r) <= 0.0:
                    return _monotone_root(g0, g1, g2, bound, lo, r)
                lo = r
    if _cubic(g0, g1, g2, bound, h_max) > 0.0:
        return h_max
    return _monotone_root(g0, g1, g2, bound, lo, h_max)


@njit(cache=True)
def decide_slip(p: np.ndarray, region: int, x: float, phi: float) -> int:
    """Direction of motion (+1, -1) or 0 (stick) for a mass at rest at x, forcing phase phi."""
    k, fc = region_force(p, region)
    net = p[P_F0] * math.sin(phi) + fc - k * x
    if friction_active(p, region) and abs(net) <= p[P_FF]:
        return 0
    if net > 0.0:
        return 1
    if net < 0.0:
        return -1
    return 1 if math.cos(phi) >= 0.0 else -1


@njit(cache=True)
def region_of(p: np.ndarray, x: float, v: float) -> int:
    """The region of a position (an edge counts as the side the velocity points to).

    :func:`clearjoint.laws.clearance.contact_state` on the parameter vector's gap edges.
    """
    return clearance.contact_state(x, v, p[P_GC], p[P_GT])


@njit(cache=True)
def _next_event(
    p: np.ndarray, q: np.ndarray, region: int, slip: int, tau_end: float, t_scale: float
) -> tuple[float, int]:
    """March through one state to its first event; return (tau, event code)."""
    gc = p[P_GC]
    gt = p[P_GT]
    eps = 1e-14 * t_scale
    tau = 0.0
    if slip == 0:
        k, fc = region_force(p, region)
        f0 = p[P_F0]
        w = p[P_W]
        ff = p[P_FF]
        rest = fc - k * q[Q_XSTICK]
        bound = f0 * w**3
        for _ in range(MAX_MARCH_STEPS):
            theta = q[Q_PHI] + w * tau
            net = f0 * math.sin(theta) + rest
            d1 = f0 * w * math.cos(theta)
            d2 = -f0 * w * w * math.sin(theta)
            remaining = tau_end - tau
            h_up = certified_step(ff - net, -d1, -d2, bound, remaining, 0.0, 0.0)
            h_dn = certified_step(
                ff + net, d1, d2, bound, h_up, 0.0, 0.0
            )  # only: does it come first?
            h = min(h_up, h_dn)
            if h >= remaining:
                return tau_end, EV_PERIOD_END
            if h <= eps or tau + h == tau:  # converged, or below the resolution of tau
                return tau + h, EV_RELEASE_UP if h_up <= h_dn else EV_RELEASE_DOWN
            tau += h
        return tau, EV_MARCH_FAILED
    b3, b4 = derivative_bounds(q, tau_end)
    # at tau = 0 take the state and its derivatives from the equation of motion itself:
    # the closed form carries round-off there, and the event that started this state
    # sits exactly at g = 0
    k, fc = q[Q_K], q[Q_FC]
    m, c = q[Q_M], q[Q_C]
    x = q[Q_XSTICK]
    v = q[Q_V0]
    a = (p[P_F0] * math.sin(q[Q_PHI]) + fc - k * x - c * v) / m
    if (
        v == 0.0
        and slip * a < 0.0
        and abs(a) * m <= 1e-12 * (p[P_F0] + abs(fc) + abs(k * x) + p[P_FF])
    ):
        # a slip that starts from stick with the net force exactly at the friction limit:
        # an acceleration against the slip is round-off. One along it is kept, however
        # small: from rest just off zero (net force -k0 x0 tiny, its rate F0 w not) it
        # moves the mass that way for a moment; zeroed, the velocity zero came at once,
        # and decide_slip chose the same direction again, without end
        a = 0.0
    j = (p[P_F0] * p[P_W] * math.cos(q[Q_PHI]) - k * v - c * a) / m
    for it in range(MAX_MARCH_STEPS):
        if it > 0:
            x, v, a, j = evaluate(q, slip, tau)
        remaining = tau_end - tau
        best = remaining
        code = EV_PERIOD_END
        # each later event function is asked only whether it comes before ``best``: a
        # bound that stays positive up to there costs no root search
        h = certified_step(slip * v, slip * a, slip * j, b4, remaining, 0.0, 0.0)
        if h < best:
            best = h
            code = EV_VELOCITY_ZERO
        if region == FREE:
            h = certified_step(gc - x, -v, -a, b3, best, -j, b4)
            if h < best:
                best = h
                code = EV_ENTER_COMPRESSION
            h = certified_step(x + gt, v, a, b3, best, j, b4)
            if h < best:
                best = h
                code = EV_ENTER_TENSION
        elif region == COMPRESSION:
            h = certified_step(x - gc, v, a, b3, best, j, b4)
            if h < best:
                best = h
                code = EV_LEAVE_COMPRESSION
        else:
            h = certified_step(-gt - x, -v, -a, b3, best, -j, b4)
            if h < best:
                best = h
                code = EV_LEAVE_TENSION
        if code == EV_PERIOD_END:
            return tau_end, EV_PERIOD_END
        if best <= eps or tau + best == tau:  # converged, or below the resolution of tau
            return tau + best, code
        tau += best
    return tau, EV_MARCH_FAILED


@njit(cache=True)
def _moment(z: complex, n: int) -> complex:
    """E_n(z) = integral over 0 <= u <= 1 of u^n exp(z u) du, n = 0, 1, 2, without cancellation."""
    if abs(z) < 1.0:
        total = 0.0 + 0.0j
        term = 1.0 + 0.0j  # z^k / k!
        for k in range(30):
            total += term / (k + n + 1)
            term = term * z / (k + 1)
            if abs(term) < 1e-18:
                break
        return total
    ez = cmath.exp(z)
    if n == 0:
        return (ez - 1.0) / z
    if n == 1:
        return (ez * (z - 1.0) + 1.0) / (z * z)
    return (ez * (z * z - 2.0 * z + 2.0) - 2.0) / (z * z * z)


@njit(cache=True)
def _moments(z: complex, order: int) -> tuple[complex, complex, complex]:
    """E_0(z), E_1(z), E_2(z) of ``_moment`` up to ``order`` (the rest 0), sharing one exp(z).

    The same formulas and the same series, term for term, as ``_moment``.
    """
    e0 = 0.0j
    e1 = 0.0j
    e2 = 0.0j
    if abs(z) < 1.0:
        term = 1.0 + 0.0j  # z^k / k!
        for k in range(30):
            e0 += term / (k + 1)
            if order >= 1:
                e1 += term / (k + 2)
            if order >= 2:
                e2 += term / (k + 3)
            term = term * z / (k + 1)
            if abs(term) < 1e-18:
                break
        return e0, e1, e2
    ez = cmath.exp(z)
    e0 = (ez - 1.0) / z
    if order >= 1:
        e1 = (ez * (z - 1.0) + 1.0) / (z * z)
    if order >= 2:
        e2 = (ez * (z * z - 2.0 * z + 2.0) - 2.0) / (z * z * z)
    return e0, e1, e2


@njit(cache=True)
def _velocity_terms(
    q: np.ndarray, slip: int, rates: np.ndarray, consts: np.ndarray, slopes: np.ndarray
) -> tuple[int, float]:
    """Write x'(tau) = sum_j (consts_j + slopes_j tau) exp(rates_j tau); return (terms, size).

    ``size`` is the largest coefficient magnitude, to judge cancellation between terms.
    """
    k = q[Q_K]
    m = q[Q_M]
    alpha = q[Q_ALPHA]
    d2 = q[Q_D2]
    root = q[Q_ROOT]
    xh0 = q[Q_XH]
    vh0 = q[Q_VH]
    g = alpha * vh0 - (k / m) * xh0  # x_h'' at tau = 0
    n = 0
    if d2 < 0.0:
        c1 = 0.5 * vh0 + g / (2.0j * root)
        rates[0] = complex(alpha, root)
        consts[0] = c1
        slopes[0] = 0.0
        rates[1] = complex(alpha, -root)
        consts[1] = c1.conjugate()
        slopes[1] = 0.0
        n = 2
    elif d2 > 0.0:
        rates[0] = alpha + root
        consts[0] = 0.5 * vh0 + g / (2.0 * root)
        slopes[0] = 0.0
        rates[1] = alpha - root
        consts[1] = 0.5 * vh0 - g / (2.0 * root)
        slopes[1] = 0.0
        n = 2
    else:
        rates[0] = alpha
        consts[0] = vh0
        slopes[0] = g
        n = 1
    w = q[Q_W]
    e_phi = cmath.exp(1j * q[Q_PHI])
    if q[Q_SECULAR] == 0.0:
        cp = 0.5 * w * complex(q[Q_A], q[Q_B]) * e_phi
        sp = 0.0j
    else:
        cp = 0.5 * q[Q_SEC] * e_phi
        sp = 0.5j * q[Q_SEC] * w * e_phi
    rates[n] = 1j * w
    consts[n] = cp
    slopes[n] = sp
    rates[n + 1] = -1j * w
    consts[n + 1] = cp.conjugate()
    slopes[n + 1] = sp.conjugate()
    n += 2
    kind = q[Q_CONST_KIND]
    if kind == 1.0:
        rates[n] = 0.0
        consts[n] = q[Q_FC] / q[Q_C]
        slopes[n] = 0.0
        n += 1
    elif kind == 2.0:
        rates[n] = 0.0
        consts[n] = 0.0
        slopes[n] = q[Q_FC] / m
        n += 1
    size = 0.0
    for j in range(n):
        size = max(size, abs(consts[j]))
    return n, size


@njit(cache=True)
def _segment_energy_quadrature(
    p: np.ndarray, q: np.ndarray, slip: int, duration: float, scale: float
) -> tuple[float, float]:
    """Work of the excitation and viscous loss over one state, Gauss-Legendre on scale / 8."""
    f0 = p[P_F0]
    w = p[P_W]
    c = p[P_DAMP]
    pieces = max(1, math.ceil(duration / (scale / 8.0)))
    h = duration / pieces
    work = 0.0
    viscous = 0.0
    for i in range(pieces):
        mid = (i + 0.5) * h
        for n in range(8):
            tau = mid + 0.5 * h * _GL_X[n]
            _, v, _, _ = evaluate(q, slip, tau)
            weight = 0.5 * h * _GL_W[n]
            work += weight * f0 * math.sin(q[Q_PHI] + w * tau) * v
            viscous += weight * c * v * v
    return work, viscous


@njit(cache=True)
def _segment_energy(
    p: np.ndarray, q: np.ndarray, slip: int, duration: float, scratch: np.ndarray
) -> tuple[float, float]:
    """Work of the excitation and viscous loss over one state, in closed form.

    x'(tau) is a sum of (a + b tau) exp(s tau) terms (homogeneous, forced and
    constant parts), and so is F0 sin(phi + w tau); every product integrates to
    tau^n exp(s tau) moments (``_moment``, ``_moments``). Near-critical damping, where the
    exponential terms cancel each other, falls back to quadrature on the state's
    own time scale. ``scratch`` is a (3, 6) complex work array.
    """
    if slip == 0 or duration <= 0.0:
        return 0.0, 0.0
    rates = scratch[0]
    consts = scratch[1]
    slopes = scratch[2]
    n, size = _velocity_terms(q, slip, rates, consts, slopes)
    _, v_end, _, _ = evaluate(q, slip, duration)
    typical = abs(q[Q_V0]) + abs(v_end) + q[Q_W] * math.hypot(q[Q_A], q[Q_B])
    if size > 1e4 * typical:
        # the terms cancel: integrate numerically over the state's own time scale
        scale = 2.0 * math.pi / q[Q_W]
        if q[Q_ROOT] > 0.0:
            scale = min(scale, 2.0 * math.pi / q[Q_ROOT])
        if q[Q_ALPHA] < 0.0:
            scale = min(scale, -2.0 * math.pi / q[Q_ALPHA])
        return _segment_energy_quadrature(p, q, slip, duration, scale)
    f0 = p[P_F0]
    w = p[P_W]
    e_phi = cmath.exp(1j * q[Q_PHI])
    force_plus = f0 * e_phi / 2.0j  # F0 sin(phi + w tau) = force_plus e^{i w tau} + conj
    work = 0.0j
    viscous = 0.0j
    t = duration
    # The velocity's terms are closed under conjugation (a complex rate comes with its
    # conjugate, a real one has real coefficients), so the work's terms pair off as
    # (j, force_plus) with (conj j, conj force_plus): the real part of the sum is twice
    # that of the force_plus terms alone. The viscous sum is symmetric in (i, j).
    for j in range(n):
        sloped = slopes[j] != 0.0  # a term without a slope needs E_0 only
        z = (rates[j] + 1j * w) * t
        e0, e1, _ = _moments(z, 1 if sloped else 0)
        if sloped:
            work += force_plus * (consts[j] * t * e0 + slopes[j] * t * t * e1)
        else:
            work += force_plus * (consts[j] * t * e0)
        if p[P_DAMP] == 0.0:
            continue
        for i in range(j + 1):
            z = (rates[i] + rates[j]) * t
            order = 2 if sloped and slopes[i] != 0.0 else (1 if sloped or slopes[i] != 0.0 else 0)
            e0, e1, e2 = _moments(z, order)
            term = (
                consts[i] * consts[j] * t * e0
                + (consts[i] * slopes[j] + slopes[i] * consts[j]) * t * t * e1
                + slopes[i] * slopes[j] * t * t * t * e2
            )
            viscous += term if i == j else 2.0 * term
    return 2.0 * work.real, p[P_DAMP] * viscous.real


@njit(cache=True)
def time_scale(p: np.ndarray) -> float:
    """The shortest time scale of the system: forcing and state periods, viscous decay time."""
    t = float(p[P_TF])
    m = p[P_MASS]
    for region in (FREE, COMPRESSION, TENSION):
        k, _ = region_force(p, region)
        if k > 0.0:
            t = min(t, 2.0 * math.pi * math.sqrt(m / k))
    if p[P_DAMP] > 0.0:
        t = min(t, 2.0 * math.pi * m / p[P_DAMP])
    return t


@njit(cache=True)
def _store(state: np.ndarray, x: float, v: float, region: int, slip: int) -> None:
    state[S_X] = x
    state[S_V] = v
    state[S_REGION] = region
    state[S_SLIP] = slip


@njit(cache=True)
def apply_event(
    p: np.ndarray, code: int, x: float, v: float, region: int, slip: int, phi: float
) -> tuple[float, float, int, int, float, int]:
    """The state just after event ``code`` at forcing phase ``phi`` (MODEL.md sec. 2 event rules).

    Returns (x, v, region, slip, approach speed, side): side is +1 / -1 for an
    impact into compression / tension (x' -> e x'), 0 for any other event.
    """
    speed = 0.0
    side = 0
    if code in (EV_ENTER_COMPRESSION, EV_ENTER_TENSION):
        side = 1 if code == EV_ENTER_COMPRESSION else -1
        x = p[P_GC] if side == 1 else -p[P_GT]
        speed = abs(v)
        v = p[P_E] * v
        region = side
        if v == 0.0:
            slip = decide_slip(p, region, x, phi)
    elif code == EV_LEAVE_COMPRESSION:
        x = p[P_GC]
        region = FREE
    elif code == EV_LEAVE_TENSION:
        x = -p[P_GT]
        region = FREE
    elif code == EV_VELOCITY_ZERO:
        v = 0.0
        slip = decide_slip(p, region, x, phi)
    elif code == EV_RELEASE_UP:
        slip = 1
        v = 0.0
    elif code == EV_RELEASE_DOWN:
        slip = -1
        v = 0.0
    return x, v, region, slip, speed, side


@njit(cache=True)
def advance(
    p: np.ndarray,
    state: np.ndarray,
    n_periods: int,
    t_last: float,
    record: bool,
    segments: np.ndarray,
    impacts: np.ndarray,
    strobe: np.ndarray,
    ledger: np.ndarray,
) -> tuple[int, int, int, int]:
    """Advance ``state`` (x, v, region, slip) in place over ``n_periods`` forcing periods.

    Each period starts at forcing phase 0; the last one stops at ``t_last`` into
    it. ``strobe[i]`` receives the state at the end of period i, ``ledger[i]``
    its energies (excitation work and viscous loss only when ``record``), and
    with ``record`` every state is written to ``segments`` and every impact to
    ``impacts``. Returns (segments written, impacts written, events, status).
    """
    tf = p[P_TF]
    w = p[P_W]
    m = p[P_MASS]
    beta = 0.5 * (1.0 - p[P_E] ** 2)
    t_scale = time_scale(p)
    x = state[S_X]
    v = state[S_V]
    region = int(state[S_REGION])
    slip = int(state[S_SLIP])
    n_seg = 0
    n_imp = 0
    n_events = 0
    scratch = np.zeros((3, 6), dtype=np.complex128)
    for period in range(n_periods):
        t_end = t_last if period == n_periods - 1 else tf
        t_in = 0.0
        ledger[period, :] = 0.0
        events_here = 0
        while True:
            phi = w * t_in
            q = phase_coefficients(p, region, slip, x, v, phi)
            tau, code = _next_event(p, q, region, slip, t_end - t_in, t_scale)
            if code == EV_MARCH_FAILED:
                _store(state, x, v, region, slip)
                return n_seg, n_imp, n_events, STATUS_MARCH_FAILED
            if code == EV_PERIOD_END:
                tau = t_end - t_in
            x1, v1, _, _ = evaluate(q, slip, tau)
            if record:
                if n_seg >= segments.shape[0]:
                    _store(state, x, v, region, slip)
                    return n_seg, n_imp, n_events, STATUS_SEGMENTS_FULL
                row = segments[n_seg]
                row[SEG_PERIOD] = period
                row[SEG_T0] = t_in
                row[SEG_DT] = tau
                row[SEG_REGION] = region
                row[SEG_SLIP] = slip
                row[SEG_X0] = x
                row[SEG_V0] = v
                row[SEG_PHI] = phi
                n_seg += 1
                work, viscous = _segment_energy(p, q, slip, tau, scratch)
                ledger[period, L_INPUT] += work
                ledger[period, L_VISCOUS] += viscous
            if slip != 0 and friction_active(p, region):
                ledger[period, L_SLIDING] += p[P_FF] * abs(x1 - x)
            x = x1
            v = v1
            t_in += tau
            if code == EV_PERIOD_END:
                t_in = t_end
                break
            n_events += 1
            events_here += 1
            if events_here > MAX_EVENTS_PER_PERIOD:
                _store(state, x, v, region, slip)
                return n_seg, n_imp, n_events, STATUS_TOO_MANY_EVENTS
            phi = w * t_in
            x, v, region, slip, speed, side = apply_event(p, code, x, v, region, slip, phi)
            if side != 0:
                ledger[period, L_IMPACT] += beta * m * speed * speed
                if record and n_imp < impacts.shape[0]:
                    impacts[n_imp, 0] = period
                    impacts[n_imp, 1] = t_in
                    impacts[n_imp, 2] = speed
                    impacts[n_imp, 3] = side
                    n_imp += 1
        _store(strobe[period], x, v, region, slip)
        # the next period starts at forcing phase 0 with the same state
    _store(state, x, v, region, slip)
    return n_seg, n_imp, n_events, STATUS_OK


@njit(cache=True)
def sample(
    p: np.ndarray, segments: np.ndarray, n_seg: int, times: np.ndarray, out: np.ndarray
) -> None:
    """Evaluate x, v, a at sorted ``times`` (period index * T + time in period) from segments."""
    tf = p[P_TF]
    i = 0
    built = -1  # the segment whose closed-form coefficients ``q`` holds
    q = np.zeros(N_Q)
    for n in range(times.shape[0]):
        t = times[n]
        while i + 1 < n_seg and (segments[i + 1, SEG_PERIOD] * tf + segments[i + 1, SEG_T0] <= t):
            i += 1
        row = segments[i]
        slip = int(row[SEG_SLIP])
        if built != i:  # the same coefficients serve every sample of a segment
            q = phase_coefficients(
                p, int(row[SEG_REGION]), slip, row[SEG_X0], row[SEG_V0], row[SEG_PHI]
            )
            built = i
        tau = t - (row[SEG_PERIOD] * tf + row[SEG_T0])
        tau = min(max(tau, 0.0), row[SEG_DT])
        x, v, a, _ = evaluate(q, slip, tau)
        out[n, 0] = x
        out[n, 1] = v
        out[n, 2] = a
