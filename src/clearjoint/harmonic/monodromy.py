"""Floquet multipliers of a harmonic-balance orbit of a structure, from its exact monodromy.

MODEL.md 5.3 (stability of the periodic response). Linearised about the HB orbit
u(t), a perturbation obeys M y'' + C y' + K_T(t) y = 0 with K_T(t) = K + sum_j
b_j k_j(t) b_j^T, and each joint's tangent k_j(t) is piecewise constant (k0, k0 + k_c
or k0 + k_t: MODEL.md section 0). Between two instants where some b_j^T u(t) crosses a
gap edge the perturbation equation is linear with constant coefficients, so the
monodromy matrix is exactly the ordered product of matrix exponentials

    Phi = expm(A_m dt_m) ... expm(A_1 dt_1),  A = [[0, I], [-M^-1 K_T, -M^-1 C]],

and the 2N Floquet multipliers are its eigenvalues. The crossing instants are
roots of the orbit's trigonometric polynomial, located between the AFT samples
where a joint's state changes. No exponent has to be picked out of Hill's
truncated eigenproblem (whose 2N (2H + 1) eigenvalues hold each family lambda + i k
w once per shift, and whose smallest-abs(Im) members are not the resolved ones when
the structure's higher modes lie above H w): the only approximation left is the
HB orbit itself (a crossing the samples do not see, shorter than 2 pi / N_t,
is missed).

With Coulomb friction (regularised, mu_s P tanh(v_j / v_eps) on each joint's relative
speed v_j = b_j^T u') the perturbation also sees a time-varying damping C_T(t) = C +
sum_j b_j c_j(t) b_j^T, c_j = mu_s P (1 - tanh^2(v_j / v_eps)) / v_eps, smooth but
steep where v_j passes 0. There the monodromy is integrated instead
(:func:`integrated_monodromy`): the matrix equation Phi' = A(t) Phi over one period
by scipy's adaptive DOP853, restarted at every gap-edge crossing (K_T jumps) and at
every zero of a rubbing joint's relative speed (the peak of c_j, which an adaptive
step must not skip). Its cost grows as (2N)^2 states, so it is meant for small
structures.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from clearjoint.harmonic.aft import Basis
from clearjoint.harmonic.system import HarmonicError, LinearSystem

FloatArray = NDArray[np.float64]

#: Bisection steps that place a gap-edge crossing between two samples (2^-40 of a sample).
_BISECTIONS = 40


def _states(delta: FloatArray, system: LinearSystem) -> NDArray[np.int64]:
    """Contact state of each joint: 1 beyond the compression edge, -1 beyond tension, 0 open."""
    return np.asarray(
        (delta > system.g_c).astype(np.int64) - (delta < -system.g_t).astype(np.int64)
    )


def crossings(system: LinearSystem, basis: Basis, coefficients: FloatArray) -> FloatArray:
    """Return the phases tau in [0, 2 pi) where some joint's b_j^T u crosses a gap edge.

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.

    Returns
    -------
    (k,) ndarray
        Sorted crossing phases, rad (tau = w t), each to 2^-40 of a sample interval.
    """
    rel = coefficients @ system.directions.T  # (2H + 1, n_j)
    n_t = basis.samples
    delta = basis.to_time @ rel  # (N_t, n_j)
    state = _states(delta, system)
    change = state != np.roll(state, -1, axis=0)
    rows, joints = np.nonzero(change)
    if rows.size == 0:
        return np.zeros(0)
    # the edge crossed: the compression one if either end is beyond it, else the tension one
    nxt = (rows + 1) % n_t
    compress = (state[rows, joints] == 1) | (state[nxt, joints] == 1)
    edge = np.where(compress, system.g_c[joints], -system.g_t[joints])
    return _bisect(basis, rel[:, joints], edge, rows)


def _bisect(
    basis: Basis, columns: FloatArray, level: FloatArray, rows: NDArray[np.intp]
) -> FloatArray:
    """Sorted phases where column k of ``columns`` (2H + 1, k) crosses ``level[k]`` inside the
    sample interval ``rows[k]`` (where its sign changes), by bisection to 2^-40 of it."""
    step = 2.0 * math.pi / basis.samples
    lo = np.asarray(rows * step, dtype=np.float64)
    hi = lo + step
    f_lo = _at(basis, columns, lo) - level
    for _ in range(_BISECTIONS):
        mid = np.asarray(0.5 * (lo + hi), dtype=np.float64)
        f_mid = _at(basis, columns, mid) - level
        same = np.sign(f_mid) == np.sign(f_lo)
        lo = np.where(same, mid, lo)
        f_lo = np.where(same, f_mid, f_lo)
        hi = np.where(same, hi, mid)
    return np.sort(np.mod(0.5 * (lo + hi), 2.0 * math.pi))


def _pattern_stiffness(system: LinearSystem, state: NDArray[np.int64]) -> FloatArray:
    """K plus each joint's tangent in its contact state (1 compression, -1 tension), N/m."""
    k_j = system.k0 + system.k_c * (state == 1) + system.k_t * (state == -1)
    b = system.directions
    return np.asarray(system.stiffness + (b.T * k_j) @ b, dtype=np.float64)


def _at(basis: Basis, columns: FloatArray, tau: FloatArray) -> FloatArray:
    """Column k of ``columns`` (2H + 1, k) evaluated at its own phase tau[k]."""
    h = np.arange(1, basis.harmonics + 1)
    e = np.empty((tau.size, 2 * basis.harmonics + 1))
    e[:, 0] = 1.0
    e[:, 1::2] = np.cos(np.outer(tau, h))
    e[:, 2::2] = np.sin(np.outer(tau, h))
    return np.asarray(np.einsum("kc,ck->k", e, columns), dtype=np.float64)


def monodromy(
    system: LinearSystem, basis: Basis, coefficients: FloatArray, omega: float
) -> FloatArray:
    """Return the monodromy matrix of the HB orbit's linearisation, (2N, 2N).

    Parameters
    ----------
    system : LinearSystem
        Without friction (its tangent would not be piecewise constant): with
        friction use :func:`integrated_monodromy`.
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.

    Returns
    -------
    (2N, 2N) ndarray
        Phi, mapping (y(0), y'(0)) to (y(T), y'(T)), T = 2 pi / w.
    """
    n = system.n_dof
    inv_m = 1.0 / np.diag(system.mass)
    b = system.directions
    rel = coefficients @ b.T
    cuts = crossings(system, basis, coefficients)
    edges = np.concatenate(([0.0], cuts, [2.0 * math.pi]))
    widths = np.diff(edges)
    middles = 0.5 * (edges[:-1] + edges[1:])
    states = _states(basis.evaluate(rel, middles), system)  # (k + 1, n_j)
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, n:] = -inv_m[:, None] * system.damping
    phi = np.eye(2 * n)
    cache: dict[bytes, FloatArray] = {}
    for width, state in zip(widths, states, strict=True):
        if width <= 0.0:
            continue
        key = state.tobytes()
        if key not in cache:
            cache[key] = -inv_m[:, None] * _pattern_stiffness(system, state)
        a[n:, :n] = cache[key]
        phi = scipy.linalg.expm(a * (width / omega)) @ phi
    return phi


def multipliers(
    system: LinearSystem, basis: Basis, coefficients: FloatArray, omega: float
) -> NDArray[np.complex128]:
    """Return the 2N Floquet multipliers of the HB orbit, largest modulus first.

    The exact product of exponentials without friction (:func:`monodromy`), the
    integrated monodromy with it (:func:`integrated_monodromy`).

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.

    Returns
    -------
    (2N,) complex ndarray
    """
    if system.friction_force is None:
        phi = monodromy(system, basis, coefficients, omega)
    else:
        phi = integrated_monodromy(system, basis, coefficients, omega)
    mu = np.linalg.eigvals(phi)
    return np.asarray(mu[np.argsort(-np.abs(mu), kind="stable")], dtype=np.complex128)


def _roots(basis: Basis, columns: FloatArray, level: FloatArray) -> FloatArray:
    """Phases in [0, 2 pi) where some column of ``columns`` (2H + 1, k) crosses its ``level``."""
    values = basis.to_time @ columns - level  # (N_t, k)
    above = values > 0.0
    rows, cols = np.nonzero(above != np.roll(above, -1, axis=0))
    if rows.size == 0:
        return np.zeros(0)
    return _bisect(basis, columns[:, cols], level[cols], rows)


def integrated_monodromy(
    system: LinearSystem,
    basis: Basis,
    coefficients: FloatArray,
    omega: float,
    *,
    rtol: float = 1e-10,
) -> FloatArray:
    """Return the monodromy of the HB orbit's linearisation by integration, (2N, 2N).

    Integrates Phi' = A(t) Phi, A = [[0, I], [-M^-1 K_T(t), -M^-1 C_T(t)]], over one
    period (module docstring): K_T piecewise constant between gap-edge crossings,
    C_T(t) the viscous C plus each rubbing joint's regularised friction slope at the
    orbit's relative speed. Valid with or without friction (without, it reproduces
    :func:`monodromy` to about ``rtol``).

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.
    rtol : float
        Relative (and absolute, on the phase-scaled state) tolerance of DOP853.

    Returns
    -------
    (2N, 2N) ndarray
        Phi, mapping (y(0), y'(0)) to (y(T), y'(T)), T = 2 pi / w.

    Raises
    ------
    HarmonicError
        The integrator failed on a segment (the message names it).
    """
    n = system.n_dof
    inv_m = 1.0 / np.diag(system.mass)
    b = system.directions
    rel = coefficients @ b.T  # (2H + 1, n_j)
    rate = basis.derivative @ rel  # d delta / d tau
    cuts = [crossings(system, basis, coefficients)]
    rubbing = (
        np.zeros(0, dtype=np.int64)
        if system.friction_force is None
        else np.flatnonzero(system.friction_force > 0.0)
    )
    if rubbing.size:
        cuts.append(_roots(basis, rate[:, rubbing], np.zeros(rubbing.size)))
    edges = np.unique(np.concatenate([[0.0], *cuts, [2.0 * math.pi]]))
    middles = 0.5 * (edges[:-1] + edges[1:])
    states = _states(basis.evaluate(rel, middles), system)
    # phase-scaled state (y, y' / w) in tau = w t: d/dtau = [[0, I], [-M^-1 K / w^2, -M^-1 C / w]]
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    damping = -inv_m[:, None] * system.damping / omega
    phi = np.eye(2 * n)
    for lo, hi, state in zip(edges[:-1], edges[1:], states, strict=True):
        if hi <= lo:
            continue
        a[n:, :n] = -inv_m[:, None] * _pattern_stiffness(system, state) / omega**2

        def rhs(tau: float, y: FloatArray) -> FloatArray:
            gen = a.copy()
            gen[n:, n:] = damping
            if rubbing.size:
                speed = omega * basis.evaluate(rate, np.array([tau]))  # (1, n_j)
                _, slope = system.friction_forces(speed)
                gen[n:, n:] -= inv_m[:, None] * ((b.T * slope[0]) @ b) / omega
            return np.asarray((gen @ y.reshape(2 * n, 2 * n)).ravel(), dtype=np.float64)

        sol = solve_ivp(rhs, (lo, hi), phi.ravel(), method="DOP853", rtol=rtol, atol=rtol)
        if not sol.success:
            raise HarmonicError(
                f"the monodromy integration failed on the phase segment {lo:.6g} to {hi:.6g} "
                f"rad at w = {omega!r} rad/s ({sol.message}); use more samples or a larger "
                "friction_regularization"
            )
        phi = sol.y[:, -1].reshape(2 * n, 2 * n)
    scale = np.concatenate((np.ones(n), np.full(n, omega)))
    return np.asarray(scale[:, None] * phi / scale[None, :], dtype=np.float64)


def speed_reversals(system: LinearSystem, basis: Basis, coefficients: FloatArray) -> FloatArray:
    """Return how often each joint's relative speed b_j^T u' changes sign in one period.

    A joint that slides back and forth reverses twice; more reversals mean the HB
    orbit's speed ripples about 0, i.e. the joint sticks (with friction), where the
    regularised slope c_j swings between 0 and mu_s P / v_eps and the linearisation
    is not to be trusted.

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.

    Returns
    -------
    (n_j,) ndarray
        The number of sign changes per joint (as floats).
    """
    rate = basis.derivative @ (coefficients @ system.directions.T)
    return np.array(
        [float(_roots(basis, rate[:, [j]], np.zeros(1)).size) for j in range(rate.shape[1])]
    )
