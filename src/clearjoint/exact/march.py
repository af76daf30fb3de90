"""The event-by-event march of a structure's exact motion, compiled (MODEL.md 5.2).

One njit call runs the whole motion; Python is not entered per step. In a contact pattern
the augmented state y = (omega_ref u, v, v_ref sin w t, v_ref cos w t, v_ref) obeys
y' = A_s y, and A_s y is applied matrix-free from sparse pieces (plain members' K, C,
each joint's row b_j and its stiffness and offset in its current state), so a new pattern
costs nothing to set up: patterns differ only in the joints' table entries. The
constant scales (M^-1, 1 / v_ref) are folded into those pieces once per run, and each
term's damping product M^-1 C v_i is kept: the viscous loss integral reuses it instead of
multiplying by C again.

A step of length h is one Taylor expansion of the flow, y(s h) = sum_i y_i s^i on
s in [0, 1], y_{i+1} = h A_s y_i / (i + 1), summed until the terms fall below 1e-18 of y
with a rigorous tail: abs(y_(K+m)) <= abs(y_K) rho^m, rho = abs(A)_inf h / (K + 1) < 1/2, so
abs(y(s h) - sum_(i<=K) y_i s^i)_inf <= s^(K+1) abs(y_K)_inf rho / (1 - rho). Each
gap-edge distance g_e (positive inside its state) is then the polynomial P_e(s) up to
that tail T_e, and Q_e(s) = P_e(s) - T_e s^(K+1) <= g_e(s) on the whole step: the first
root of Q_e is never after the first root of g_e. That first root is isolated exactly in
the Bernstein basis (a polynomial lies within the hull of its Bernstein coefficients on
[0, 1]; de Casteljau halving; a single sign change of the coefficients means a single
root, then a bracket [lo, hi] with Q(lo) > 0 >= Q(hi) closed to 1e-15 of the step by
regula falsi, Illinois variant, falling back to bisection): a grazing contact is seen
however brief.
The step goes to that root, where the event is declared (within 1e-15 of the step of
Q's root; Q and g differ by round-off), or to h. The step h is the base step h_base after
an event and doubles after each step that met no edge, up to MAX_STEP_GROWTH h_base: a
longer step only takes more terms (and is halved if it needs more than MAX_TERMS or
rho >= 1/2), the tail bound and the root isolation hold for any h, so no edge is missed.
Before an edge's polynomial is built, its distance is compared with the joint's reach
over the step (the sum of abs(bu_i), i >= 1, and the tail bound): an edge beyond it has
Q > 0 on the whole step and is skipped. Samples, the input work
integral of F.v sin(w t) and the viscous loss integral of v^T C v over the step are
exact polynomial operations on the same series.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clearjoint.exact.kernel import certified_step
from clearjoint.jit import njit  # numba.njit that survives a read-only install
from clearjoint.laws import clearance

#: Most Taylor terms per step; a step that needs more is halved.
MAX_TERMS = 60
#: Terms are summed until they fall below this fraction of the state.
TERM_TOL = 1e-18
#: Width of the bracket (fraction of the step) a root is bisected to.
ROOT_TOL = 1e-15
#: Deepest Bernstein subdivision.
MAX_DEPTH = 64
#: After steps that met no edge the step doubles, up to this many base steps.
MAX_STEP_GROWTH = 4.0
#: A joint's reach over a step (sum of its series' sizes and tail) is widened by this
#: factor, far beyond the round-off of that sum, before an edge farther away is skipped.
REACH_MARGIN = 1.0 + 1e-9

#: The law's contact states.
OPEN, COMPRESSION, TENSION = clearance.OPEN, clearance.COMPRESSION, clearance.TENSION
#: Status codes of ``march``: PAUSED when it stopped at ``t_pause``, to be resumed.
DONE, CHATTER, NO_CONVERGENCE, PAUSED = 0, 1, 2, 3
#: Places in ``march``'s ``clock``: time reached, next step length, next sample, steps,
#: impact loss so far (what a paused march resumes from, so that the pieces make exactly
#: the steps of one whole march).
C_T, C_H, C_SAMPLE, C_STEPS, C_IMPACT = range(5)
N_CLOCK = 5


@njit(cache=True)
def _series(
    y: np.ndarray,
    out: np.ndarray,
    damp: np.ndarray,
    factor: float,
    n: int,
    omega: float,
    omega_ref: float,
    force_s: np.ndarray,
    ap: np.ndarray,
    ai: np.ndarray,
    a_u: np.ndarray,
    a_v: np.ndarray,
    bp: np.ndarray,
    bi: np.ndarray,
    bd: np.ndarray,
    bd_m: np.ndarray,
    k_now: np.ndarray,
    r_s: np.ndarray,
) -> float:
    """out = factor A_s y in scaled variables (sparse, matrix-free); returns abs(out)_inf.

    One Taylor term: y_(i+1) = (h / (i + 1)) A_s y_i is ``factor = h / (i + 1)``. Row i of
    the acceleration is force_s[i] y_sin - sum_p a_u[p] y_u[ai[p]] - damp[i] - the joints'
    forces along bd_m = M^-1 b_j over one CSR pattern ``ap, ai`` of the plain stiffness
    (a_u = M^-1 K_plain / omega_ref) and the damping (a_v = M^-1 C), with
    damp[i] = sum_p a_v[p] y_v[ai[p]] = (M^-1 C y_v)[i] (stored, unscaled by ``factor``, for the
    viscous loss integral), ``force_s`` = M^-1 F / v_ref, ``k_now`` the joints' stiffness
    over omega_ref (y holds omega_ref u) and ``r_s`` their offsets over v_ref.
    """
    sin_ = y[2 * n]
    one = y[2 * n + 2]
    for i in range(n):
        acc = force_s[i] * sin_
        d = 0.0
        for p in range(ap[i], ap[i + 1]):
            q = ai[p]
            acc -= a_u[p] * y[q]
            d += a_v[p] * y[n + q]
        damp[i] = d
        out[n + i] = acc - d
    for j in range(k_now.shape[0]):
        delta = 0.0
        for p in range(bp[j], bp[j + 1]):
            delta += bd[p] * y[bi[p]]
        f = k_now[j] * delta - r_s[j] * one
        for p in range(bp[j], bp[j + 1]):
            out[n + bi[p]] -= bd_m[p] * f
    top = 0.0
    scale_u = factor * omega_ref
    for i in range(n):
        a = scale_u * y[n + i]
        b = factor * out[n + i]
        out[i] = a
        out[n + i] = b
        top = max(top, abs(a), abs(b))
    a = factor * omega * y[2 * n + 1]
    b = -factor * omega * y[2 * n]
    out[2 * n] = a
    out[2 * n + 1] = b
    out[2 * n + 2] = 0.0
    return float(max(top, abs(a), abs(b)))


@njit(cache=True)
def _variations(beta: np.ndarray, deg: int) -> int:
    """Sign changes in beta[0..deg] (zeros count as negative: Q <= 0 is the event)."""
    count = 0
    positive = beta[0] > 0.0
    for k in range(1, deg + 1):
        now = beta[k] > 0.0
        if now != positive:
            count += 1
            positive = now
    return count


@njit(cache=True)
def _horner(c: np.ndarray, deg: int, s: float) -> float:
    value = c[deg]
    for i in range(deg - 1, -1, -1):
        value = value * s + c[i]
    return float(value)


@njit(cache=True)
def first_root(
    c: np.ndarray, deg: int, stack: np.ndarray, bounds: np.ndarray, limit: float = 1.0
) -> float:
    """First s in [0, limit] with Q(s) = sum_(i<=deg) c[i] s^i <= 0, from below; 2.0 if none.

    Returns s with Q > 0 on [0, s) and a point with Q <= 0 within ROOT_TOL after s (or
    s where the subdivision bottoms out). ``c[0] <= 0`` is read as a root at 0: if the
    first nonzero coefficient after it is negative the answer is 0, otherwise the root
    at 0 is divided out. ``stack`` (MAX_DEPTH + 2, deg + 1) and ``bounds`` (MAX_DEPTH + 2, 2)
    are work space.
    """
    start = 0
    if c[0] <= 0.0:
        start = 1
        while start <= deg and c[start] == 0.0:
            start += 1
        if start > deg or c[start] < 0.0:
            return 0.0
    d = deg - start
    if d == 0:
        return 2.0
    # quick exclusions on [0, limit], with s^i <= s^3 limit^(i - 3) for i >= 3:
    # Q >= c0 + c1 s + c2 s^2 - r s^3, r the sum of the negative coefficients' sizes
    r = 0.0
    power = 1.0
    for i in range(start + 3, deg + 1):
        if i - start > 3:
            power *= limit
        if c[i] < 0.0:
            r -= c[i] * power
    a0 = c[start]
    a1 = c[start + 1] if d >= 1 else 0.0
    a2 = c[start + 2] if d >= 2 else 0.0
    low = a0 + min(a1, 0.0) * limit + min(a2, 0.0) * limit * limit - r * limit**3
    if low > 0.0:
        return 2.0
    if certified_step(a0, a1, 2.0 * a2, 6.0 * r, limit, 0.0, 0.0) >= limit:
        return 2.0
    # Bernstein coefficients on [0, 1]: beta_k = sum_(i<=k) C(k,i)/C(d,i) a_i
    for k in range(d + 1):
        stack[0, k] = 0.0
    for i in range(d + 1):
        ratio = 1.0  # C(i, i) / C(d, i)
        for q in range(i):
            ratio *= (q + 1.0) / (d - q)
        a_i = c[start + i] * limit**i
        for k in range(i, d + 1):
            stack[0, k] += ratio * a_i
            ratio *= (k + 1.0) / (k + 1.0 - i)
    bounds[0, 0] = 0.0
    bounds[0, 1] = limit
    top = 1
    while top > 0:
        top -= 1
        a = bounds[top, 0]
        b = bounds[top, 1]
        beta = stack[top]
        lowest = beta[0]
        for k in range(1, d + 1):
            lowest = min(lowest, beta[k])
        if lowest > 0.0:
            continue
        if beta[0] <= 0.0:
            return float(a)
        if b - a <= ROOT_TOL * limit or top >= MAX_DEPTH:
            return float(a)
        if _variations(beta, d) == 1:
            # exactly one root in (a, b]: shrink the bracket [lo, hi] with Q(lo) > 0 and
            # Q(hi) <= 0 on the power form, by the Illinois variant of regula falsi (the
            # bracket closes from both sides, superlinearly) with a bisection whenever the
            # secant point is not strictly inside or the end values do not bracket
            lo, hi = a, b
            q_lo = _horner(c[start:], d, lo)
            q_hi = _horner(c[start:], d, hi)
            kept = 0  # +1: lo moved last, -1: hi moved last
            for _ in range(200):
                if hi - lo <= ROOT_TOL * limit:
                    break
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                x = mid
                if q_lo > 0.0 and q_hi <= 0.0 and q_lo - q_hi > 0.0:
                    x = lo + (hi - lo) * (q_lo / (q_lo - q_hi))
                    if not lo < x < hi:
                        x = mid
                q_x = _horner(c[start:], d, x)
                if q_x > 0.0:
                    lo = x
                    q_lo = q_x
                    if kept == 1:
                        q_hi *= 0.5
                    kept = 1
                else:
                    hi = x
                    q_hi = q_x
                    if kept == -1:
                        q_lo *= 0.5
                    kept = -1
            return float(lo)
        # de Casteljau at the midpoint: the left half goes on top of the stack (slot
        # top + 1, examined next), the right half below it (slot top)
        left = stack[top + 1]
        for k in range(d + 1):
            left[k] = beta[k]
        for r in range(1, d + 1):
            for k in range(d - r + 1):
                beta[k] = 0.5 * (beta[k] + beta[k + 1])
            left[r] = beta[0]
        # beta[d - r] now holds level r's last point: the right half's coefficient d - r
        mid = 0.5 * (a + b)
        bounds[top, 0] = mid
        bounds[top, 1] = b
        bounds[top + 1, 0] = a
        bounds[top + 1, 1] = mid
        top += 2
    return 2.0


@njit(cache=True)
def _grow(values: np.ndarray, size: int) -> np.ndarray:
    if size < values.shape[0]:
        return values
    bigger = np.empty(2 * values.shape[0] + 16, dtype=values.dtype)
    bigger[:size] = values[:size]
    return bigger


@njit(cache=True)
def march(
    y_start: np.ndarray,
    states_start: np.ndarray,
    t_end: float,
    times: np.ndarray,
    h_base: float,
    n: int,
    omega: float,
    omega_ref: float,
    v_ref: float,
    m_inv: np.ndarray,
    force: np.ndarray,
    ap: np.ndarray,
    ai: np.ndarray,
    a_u: np.ndarray,
    a_v: np.ndarray,
    cp: np.ndarray,
    ci: np.ndarray,
    cd: np.ndarray,
    bp: np.ndarray,
    bi: np.ndarray,
    bd: np.ndarray,
    k_table: np.ndarray,
    r_table: np.ndarray,
    g_c: np.ndarray,
    g_t: np.ndarray,
    restitution: np.ndarray,
    m_eff: np.ndarray,
    norm_a: float,
    max_events: int,
    out_y: np.ndarray,
    out_p: np.ndarray,
    energy: np.ndarray,
    clock: np.ndarray,
    t_pause: float,
) -> tuple[Any, ...]:
    """Run the exact motion from y_start (scaled) over [0, t_end]; see the module docstring.

    ``ap, ai, a_u, a_v``: one CSR pattern holding M^-1 K_plain / omega_ref and M^-1 C;
    ``cp, ci, cd``: C alone (for the viscous loss). ``k_table`` and ``r_table`` (J, 3)
    give each joint's stiffness and offset in state -1, 0, 1 (column state + 1).
    The samples go to ``out_y`` (S, n_aug) and ``out_p`` (S, J), the energy integrals
    (input, viscous) are added to ``energy`` (2,); ``clock`` (N_CLOCK,) holds where the
    march starts (t, step length, next sample, steps, impact; (0, h_base, 0, 0, 0) for a
    new one) and receives where it stopped. The march pauses between two steps once t
    reaches ``t_pause`` (``inf``: never): called again with what it returned, it goes on
    with the very steps it would have made, so a march in pieces (for progress reports)
    gives the whole march's result to the bit. Returns (y_end, states_end, impact,
    event_times, event_joints, event_states, steps, status) for this piece, impact and
    steps counted from the start; status DONE, PAUSED, CHATTER (more than
    ``max_events`` events in this piece) or NO_CONVERGENCE.
    """
    n_aug = 2 * n + 3
    n_j = states_start.shape[0]
    y = y_start.copy()
    states = states_start.copy()
    k_now = np.empty(n_j)
    r_now = np.empty(n_j)
    for j in range(n_j):
        k_now[j] = k_table[j, states[j] + 1] / omega_ref
        r_now[j] = r_table[j, states[j] + 1] / v_ref
    force_s = force * m_inv / v_ref
    damp = np.zeros((MAX_TERMS + 1, n))  # M^-1 C v_i of each term
    bd_m = np.empty_like(bd)
    for p in range(bd.shape[0]):
        bd_m[p] = bd[p] * m_inv[bi[p]]
    terms = np.zeros((MAX_TERMS + 1, n_aug))
    bu = np.zeros((n_j, MAX_TERMS + 1))
    coef = np.zeros(MAX_TERMS + 2)
    stack = np.zeros((MAX_DEPTH + 2, MAX_TERMS + 2))
    bounds = np.zeros((MAX_DEPTH + 2, 2))
    cv = np.zeros((MAX_TERMS + 1, n))
    f_in = np.zeros(MAX_TERMS + 1)
    norm_v = np.zeros(MAX_TERMS + 1)
    gram = np.zeros(2 * MAX_TERMS + 2)
    prod = np.zeros(2 * MAX_TERMS + 2)
    impact = clock[C_IMPACT]
    ev_t = np.empty(64)
    ev_j = np.empty(64, dtype=np.int64)
    ev_s = np.empty(64, dtype=np.int8)
    n_ev = 0
    m_diag = 1.0 / m_inv
    b_l1 = np.zeros(n_j)
    reach = np.zeros(n_j)
    for j in range(n_j):
        for p in range(bp[j], bp[j + 1]):
            b_l1[j] += abs(bd[p])
    next_sample = int(clock[C_SAMPLE])
    t = clock[C_T]
    h_next = clock[C_H]
    status = DONE
    steps = int(clock[C_STEPS])
    while t < t_end:
        if t >= t_pause:  # between two steps: nothing of the next one is computed yet
            status = PAUSED
            break
        steps += 1
        y[2 * n] = v_ref * math.sin(omega * t)
        y[2 * n + 1] = v_ref * math.cos(omega * t)
        y[2 * n + 2] = v_ref
        remaining = t_end - t
        h = min(h_next, remaining)
        last = h >= remaining
        size = 0.0
        for q in range(n_aug):
            size = max(size, abs(y[q]))
        # the Taylor series of the flow over [t, t + h], with its tail
        while True:
            for q in range(n_aug):
                terms[0, q] = y[q]
            n_terms = 0
            rho = 1.0
            top_term = 0.0
            for i in range(1, MAX_TERMS + 1):
                top_term = _series(
                    terms[i - 1],
                    terms[i],
                    damp[i - 1],
                    h / i,
                    n,
                    omega,
                    omega_ref,
                    force_s,
                    ap,
                    ai,
                    a_u,
                    a_v,
                    bp,
                    bi,
                    bd,
                    bd_m,
                    k_now,
                    r_now,
                )
                n_terms = i
                rho = norm_a * h / (i + 1.0)
                if top_term <= TERM_TOL * size and rho < 0.5:
                    break
            if top_term <= TERM_TOL * size and rho < 0.5:
                break
            h *= 0.5
            last = False
            if h <= 1e-12 * h_base:
                return (
                    y,
                    states,
                    impact,
                    ev_t[:n_ev],
                    ev_j[:n_ev],
                    ev_s[:n_ev],
                    steps,
                    NO_CONVERGENCE,
                )
        tail = top_term * rho / (1.0 - rho) / omega_ref
        # each joint's shortening delta_j(s h) = sum_i bu[j, i] s^i, and how far it can
        # move over the whole step: reach_j = sum_(i>=1) abs(bu[j, i]) + its tail bound
        for j in range(n_j):
            moved = 0.0
            for i in range(n_terms + 1):
                acc = 0.0
                for p in range(bp[j], bp[j + 1]):
                    acc += bd[p] * terms[i, bi[p]]
                bu[j, i] = acc / omega_ref
                if i > 0:
                    moved += abs(bu[j, i])
            reach[j] = (moved + tail * b_l1[j]) * REACH_MARGIN
        best = 2.0
        which = -1
        for j in range(n_j):
            for side in range(2):  # 0: compression edge, 1: tension edge
                state = states[j]
                if side == 0:
                    if state == TENSION:
                        continue
                    sign = 1.0 if state == COMPRESSION else -1.0
                    coef[0] = sign * (bu[j, 0] - g_c[j])
                else:
                    if state == COMPRESSION:
                        continue
                    sign = -1.0 if state == TENSION else 1.0
                    coef[0] = sign * (bu[j, 0] + g_t[j])
                if coef[0] > reach[j]:
                    # Q(s) >= coef[0] - reach_j > 0 on [0, 1]: no root, none to isolate
                    continue
                for i in range(1, n_terms + 1):
                    coef[i] = sign * bu[j, i]
                coef[n_terms + 1] = -tail * b_l1[j]
                s = first_root(coef, n_terms + 1, stack, bounds, min(best, 1.0))
                if s < best:
                    best = s
                    which = 2 * j + side
        event = which >= 0
        s_end = best if event else 1.0
        h_step = s_end * h
        # samples in [t, t + h_step)
        while next_sample < times.shape[0] and (
            times[next_sample] < t + h_step or (last and not event)
        ):
            s = (times[next_sample] - t) / h
            for q in range(n_aug):
                value = terms[n_terms, q]
                for i in range(n_terms - 1, -1, -1):
                    value = value * s + terms[i, q]
                out_y[next_sample, q] = value
            for j in range(n_j):  # loops, not slices: no shape-error text to compile
                out_p[next_sample, j] = states[j]
            next_sample += 1
        if s_end > 0.0:
            # energy integrals over [0, s_end]: input F.v sin(w t), viscous v^T C v;
            # a pair (i, k) of the viscous double sum is left out only when its bound
            # abs(v_i) abs(C) abs(v_k) is below 1e-19 of abs(v)_max^2 abs(C)
            top_v = 0.0
            for i in range(n_terms + 1):
                acc = 0.0
                size_v = 0.0
                for q in range(n):
                    acc += force[q] * terms[i, n + q]
                    size_v += terms[i, n + q] * terms[i, n + q]
                f_in[i] = acc
                norm_v[i] = math.sqrt(size_v)
                top_v = max(top_v, norm_v[i])
            floor = 1e-19 * top_v
            # C v_k = M (M^-1 C v_k), kept by the series for k < K; the last one here
            last_d = damp[n_terms]
            for q in range(n):
                d = 0.0
                for p in range(ap[q], ap[q + 1]):
                    d += a_v[p] * terms[n_terms, n + ai[p]]
                last_d[q] = d
            for k in range(n_terms + 1):
                if norm_v[k] <= floor:
                    continue
                for q in range(n):
                    cv[k, q] = m_diag[q] * damp[k, q]
            for m in range(2 * n_terms + 1):
                gram[m] = 0.0
                prod[m] = 0.0
            for i in range(n_terms + 1):
                for k in range(n_terms + 1):
                    prod[i + k] += f_in[i] * terms[k, 2 * n]
                for k in range(i, n_terms + 1):
                    if norm_v[i] * norm_v[k] <= floor * top_v:
                        continue
                    acc = 0.0
                    for q in range(n):
                        acc += terms[i, n + q] * cv[k, q]
                    gram[i + k] += acc if k == i else 2.0 * acc
            power = s_end
            e_in = 0.0
            e_visc = 0.0
            for m in range(2 * n_terms + 1):
                e_in += prod[m] * power / (m + 1.0)
                e_visc += gram[m] * power / (m + 1.0)
                power *= s_end
            energy[0] += h * e_in / v_ref
            energy[1] += h * e_visc
            # the state at s_end
            for q in range(n_aug):
                value = terms[n_terms, q]
                for i in range(n_terms - 1, -1, -1):
                    value = value * s_end + terms[i, q]
                y[q] = value
        if last and not event:
            t = t_end
            break
        t += h_step
        if not event:
            # no edge met: the next step may be longer, up to MAX_STEP_GROWTH h_base
            h_next = min(2.0 * h, MAX_STEP_GROWTH * h_base)
            continue
        h_next = h_base  # after an event, start again from the base step
        joint = which // 2
        entering = states[joint] == OPEN
        if which % 2 == 0:
            states[joint] = COMPRESSION if entering else OPEN
        else:
            states[joint] = TENSION if entering else OPEN
        k_now[joint] = k_table[joint, states[joint] + 1] / omega_ref
        r_now[joint] = r_table[joint, states[joint] + 1] / v_ref
        e = restitution[joint]
        if entering and e < 1.0:
            speed = 0.0
            for p in range(bp[joint], bp[joint + 1]):
                speed += bd[p] * y[n + bi[p]]
            impact += 0.5 * (1.0 - e * e) * m_eff[joint] * speed * speed
            for p in range(bp[joint], bp[joint + 1]):
                y[n + bi[p]] -= (1.0 - e) * speed * m_eff[joint] * bd[p] * m_inv[bi[p]]
        ev_t = _grow(ev_t, n_ev)
        ev_j = _grow(ev_j, n_ev)
        ev_s = _grow(ev_s, n_ev)
        ev_t[n_ev] = t
        ev_j[n_ev] = joint
        ev_s[n_ev] = states[joint]
        n_ev += 1
        if n_ev > max_events:
            status = CHATTER
            break
    clock[C_T] = t
    clock[C_H] = h_next
    clock[C_SAMPLE] = next_sample
    clock[C_STEPS] = steps
    clock[C_IMPACT] = impact
    return y, states, impact, ev_t[:n_ev], ev_j[:n_ev], ev_s[:n_ev], steps, status


@njit(cache=True)
def pattern_history(start: np.ndarray, joints: np.ndarray, new_states: np.ndarray) -> np.ndarray:
    """(E + 1, J) int8: the contact pattern at the start and after each event."""
    history = np.empty((joints.shape[0] + 1, start.shape[0]), dtype=np.int8)
    history[0] = start
    for k in range(joints.shape[0]):
        history[k + 1] = history[k]
        history[k + 1, joints[k]] = new_states[k]
    return history
