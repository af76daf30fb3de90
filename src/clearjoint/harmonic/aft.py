"""Multi-harmonic balance with alternating frequency-time (AFT) and Hill stability (MODEL.md 5.3).

u(t) = a_0 + sum_{h=1..H} (a_h cos h w t + b_h sin h w t). The coefficients of all
DOFs form Q, shape (2H + 1, N), rows ordered a_0, a_1, b_1, ..., a_H, b_H; the
unknown vector is Q flattened (row-major: index = coefficient * N + dof). Per
harmonic h the residual is

    R_h = (K - (h w)^2 M) q_h + h w C J q_h + f_nl,h(Q) - F_h

with f_nl from AFT: the joints' relative displacements delta_j = b_j^T u are
sampled at N_t instants (inverse DFT), each law f_j is evaluated sample by sample
and projected back (forward DFT). The Jacobian is exact: for joint j,
P diag(k_j(t_n)) E, sandwiched between b_j b_j^T. The piecewise-linear law makes R
piecewise linear in Q, so Newton converges in a few steps once the samples stop
crossing gap edges.

Stability by Hill's method (Lazarus & Thomas, C. R. Mecanique 338, 2010): a
perturbation e^(lambda t) s(t), s periodic, gives the quadratic eigenproblem
(Delta_0 + lambda Delta_1 + lambda^2 Delta_2) s = 0 with Delta_0 the HB Jacobian,
Delta_1 = I x C + 2 w D x M, Delta_2 = I x M; :func:`hill_exponents` keeps the 2N of
its 2 N (2H + 1) eigenvalues with the smallest imaginary parts, and the Floquet
multipliers are exp(lambda T), T = 2 pi / w. That sorting fails when modes lie above
H w / 2; the curves use the centroid sorting of :mod:`clearjoint.harmonic.hill`.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from clearjoint.compiled import prefer
from clearjoint.harmonic.system import HarmonicError, LinearSystem
from clearjoint.jit import njit  # numba.njit that survives a read-only install
from clearjoint.laws import clearance

FloatArray = NDArray[np.float64]


def check_harmonics(harmonics: int, samples: int | None) -> tuple[int, int]:
    """Return (H, N_t) after checking them; N_t defaults to a power of two >= 32 (2H + 1).

    Raises
    ------
    HarmonicError
        H < 1, or fewer than 2 (2H + 1) samples (the harmonics the kink of the law
        creates above H would alias back onto the H kept).
    """
    if isinstance(harmonics, bool) or not isinstance(harmonics, int | np.integer) or harmonics < 1:
        raise HarmonicError(f"harmonics must be an integer >= 1, got {harmonics!r}")
    h = int(harmonics)
    least = 2 * (2 * h + 1)
    if samples is None:
        return h, 1 << math.ceil(math.log2(32 * (2 * h + 1)))
    if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < least:
        raise HarmonicError(
            f"samples must be an integer >= 2 (2H + 1) = {least} for H = {h} harmonics "
            f"(fewer alias the kink's higher harmonics onto the kept ones), got {samples!r}; "
            "leave samples=None for 32 (2H + 1) rounded up to a power of two"
        )
    return h, int(samples)


@dataclass(frozen=True)
class Basis:
    """Real Fourier basis of H harmonics sampled at N_t instants over one period.

    Attributes
    ----------
    harmonics, samples : int
        H and N_t.
    to_time : (N_t, 2H + 1) ndarray
        E: coefficients to samples at tau_n = 2 pi n / N_t.
    to_coefficients : (2H + 1, N_t) ndarray
        P: samples to coefficients (P E = I).
    derivative : (2H + 1, 2H + 1) ndarray
        D: coefficients of d/dtau (multiply by w for d/dt).
    order : (2H + 1,) ndarray
        The harmonic number h of each coefficient (0, 1, 1, 2, 2, ...).
    gather : (4, 2H + 1, 2H + 1) ndarray of int
        Where :meth:`products` reads the two cosine/sine moments of each entry
        (rows 0-1: indices, rows 2-3: their weights).
    moments : (2 (2H + 1), N_t) ndarray
        Rows cos(m tau_n) / N_t, then sin(m tau_n) / N_t, m = 0..2H.
    assemble : (2 (2H + 1), (2H + 1)^2) ndarray or None
        ``gather`` as a matrix (moments to entries), kept for H <= 31 (larger ones
        would take tens of MB; :meth:`products` then gathers).
    """

    harmonics: int
    samples: int
    to_time: FloatArray
    to_coefficients: FloatArray
    derivative: FloatArray
    order: FloatArray
    gather: NDArray[np.int64] = field(repr=False)
    moments: FloatArray = field(repr=False)
    assemble: FloatArray | None = field(repr=False)

    @classmethod
    def make(cls, harmonics: int, samples: int) -> Basis:
        """Build the basis for H harmonics and N_t samples (built once per pair, then shared)."""
        return _basis(int(harmonics), int(samples))

    @classmethod
    def _build(cls, harmonics: int, samples: int) -> Basis:
        tau = 2.0 * math.pi * np.arange(samples) / samples
        h = np.arange(1, harmonics + 1)
        n_c = 2 * harmonics + 1
        e = np.empty((samples, n_c))
        e[:, 0] = 1.0
        e[:, 1::2] = np.cos(np.outer(tau, h))
        e[:, 2::2] = np.sin(np.outer(tau, h))
        p = e.T * (2.0 / samples)
        p[0] = 1.0 / samples
        d = np.zeros((n_c, n_c))
        d[2 * h - 1, 2 * h] = h  # (a cos + b sin)' = h b cos - h a sin
        d[2 * h, 2 * h - 1] = -h
        order = np.concatenate(([0.0], np.repeat(h.astype(np.float64), 2)))
        gather = _gather(harmonics)
        m = np.arange(n_c)
        moments = np.concatenate((np.cos(np.outer(m, tau)), np.sin(np.outer(m, tau)))) / samples
        assemble = None
        if harmonics <= 31:
            assemble = np.zeros((2 * n_c, n_c * n_c))
            cells = np.arange(n_c * n_c)
            for k in (0, 1):
                np.add.at(assemble, (gather[k].ravel(), cells), gather[2 + k].ravel())
            assemble[:, :n_c] *= 0.5  # the mean's row of P carries 1 / N_t, the others 2 / N_t
        return cls(harmonics, samples, e, p, d, order, gather, moments, assemble)

    def products(self, values: FloatArray) -> FloatArray:
        """Return P diag(v) E for each column v of ``values`` (N_t, n): shape (n, 2H + 1, 2H + 1).

        The matrix that maps the coefficients of u to those of v(t) u(t) (the
        Jacobian block of a sampled tangent v). Its entries are sums of two moments
        C_m = mean(v cos m tau), S_m = mean(v sin m tau), m = 0..2H (the product
        identities of cos and sin), so the cost is O(N_t H + H^3) per column instead
        of the O(N_t H^2) of the dense product P diag(v) E (equal to round-off,
        tests/test_harmonic_aft.py).
        """
        n_c = 2 * self.harmonics + 1
        moments = values.T @ self.moments.T  # (n, 2 (2H + 1)): C_0..C_2H, S_0..S_2H
        if self.assemble is not None:
            return np.asarray((moments @ self.assemble).reshape(-1, n_c, n_c), dtype=np.float64)
        g = self.gather
        out = moments[:, g[0]] * g[2] + moments[:, g[1]] * g[3]
        out[:, 0, :] *= 0.5  # the mean's row of P carries 1 / N_t, the others 2 / N_t
        return np.asarray(out, dtype=np.float64)

    def rows_at(self, tau: FloatArray) -> FloatArray:
        """Return E(tau) (n, 2H + 1): the rows that map coefficients to u at phases tau (n,)."""
        h = np.arange(1, self.harmonics + 1)
        e = np.empty((tau.size, 2 * self.harmonics + 1))
        e[:, 0] = 1.0
        e[:, 1::2] = np.cos(np.outer(tau, h))
        e[:, 2::2] = np.sin(np.outer(tau, h))
        return e

    def evaluate(self, coefficients: FloatArray, tau: FloatArray) -> FloatArray:
        """Return u(tau) for coefficients (2H + 1, ...) at phases tau (n,): shape (n, ...)."""
        return np.asarray(
            np.tensordot(self.rows_at(tau), coefficients, axes=(1, 0)), dtype=np.float64
        )

    def evaluate_each(self, coefficients: FloatArray, tau: FloatArray) -> FloatArray:
        """Return column k of coefficients (2H + 1, n) at its own phase tau[k]: shape (n,)."""
        return np.asarray(np.einsum("kc,ck->k", self.rows_at(tau), coefficients), dtype=np.float64)

    def extremes(self, coefficients: FloatArray, fine: int = 512) -> tuple[FloatArray, FloatArray]:
        """Return (max, min) over a period of each column of coefficients (2H + 1, n).

        A grid of ``fine`` phases, then three Newton steps on u'(tau) = 0 from the
        best grid point, so the extremes of the trigonometric polynomial are exact
        to round-off.
        """
        tau = 2.0 * math.pi * np.arange(fine) / fine
        values = self.evaluate(coefficients, tau)
        d1 = self.derivative @ coefficients
        d2 = self.derivative @ d1
        out = []
        for pick in (np.argmax, np.argmin):
            t = tau[pick(values, axis=0)]
            for _ in range(3):
                u1 = self.evaluate_each(d1, t)
                u2 = self.evaluate_each(d2, t)
                step = np.where(u2 != 0.0, u1 / np.where(u2 != 0.0, u2, 1.0), 0.0)
                t = t - np.clip(step, -math.pi / fine, math.pi / fine)
            out.append(self.evaluate_each(coefficients, t))
        return out[0], out[1]


@functools.lru_cache(maxsize=32)
def _basis(harmonics: int, samples: int) -> Basis:
    """The shared :class:`Basis` of (H, N_t): its arrays are read, never written."""
    return Basis._build(harmonics, samples)


def _gather(harmonics: int) -> NDArray[np.int64]:
    """The moment indices and weights of :meth:`Basis.products` (cos/sin product identities).

    With C_m at index m and S_m at 2H + 1 + m (C_-m = C_m, S_-m = -S_m), entry
    (row h, column g) is: cos-cos C_(h-g) + C_(h+g); cos-sin S_(g+h) + S_(g-h);
    sin-cos S_(h+g) + S_(h-g); sin-sin C_(h-g) - C_(h+g); the mean is cos 0.
    """
    n_c = 2 * harmonics + 1
    kind = np.array([0] + [0, 1] * harmonics)  # 0: cos, 1: sin
    order = np.array([0] + [h for h in range(1, harmonics + 1) for _ in (0, 1)])
    table = np.zeros((4, n_c, n_c), dtype=np.int64)

    def cos(m: int) -> tuple[int, int]:
        return abs(m), 1

    def sin(m: int) -> tuple[int, int]:
        return n_c + abs(m), (m > 0) - (m < 0)

    for r in range(n_c):
        h = int(order[r])
        for c in range(n_c):
            g = int(order[c])
            if kind[r] == 0 and kind[c] == 0:
                (i1, w1), (i2, w2) = cos(h - g), cos(h + g)
            elif kind[r] == 0:
                (i1, w1), (i2, w2) = sin(g + h), sin(g - h)
            elif kind[c] == 0:
                (i1, w1), (i2, w2) = sin(h + g), sin(h - g)
            else:
                (i1, w1), (i2, w2) = cos(h - g), cos(h + g)
                w2 = -w2
            table[:, r, c] = (i1, i2, w1, w2)
    return table


@dataclass(frozen=True)
class Evaluation:
    """The HB residual at one point, with its derivatives.

    Attributes
    ----------
    residual : (n_u,) ndarray
        R, N (force coefficients), n_u = (2H + 1) N.
    jacobian : (n_u, n_u) ndarray
        dR/dq, N/m.
    d_omega : (n_u,) ndarray
        dR/dw, N s.
    tangent : (N_t, n_j) ndarray
        Each joint's sampled tangent stiffness, N/m.
    velocity_tangent : (N_t, n_j) ndarray or None
        Each joint's sampled d(friction force)/dv, N s/m (None without friction).
    """

    residual: FloatArray
    jacobian: FloatArray
    d_omega: FloatArray
    tangent: FloatArray
    velocity_tangent: FloatArray | None = None


def evaluate(
    system: LinearSystem,
    basis: Basis,
    q: FloatArray,
    omega: float,
    force: FloatArray,
    *,
    negative_damping: float = 0.0,
    jacobian: bool = True,
) -> Evaluation:
    """Return R(q, w) of MODEL.md 5.3 with its exact Jacobian (AFT, dense).

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    q : ((2H + 1) N,) ndarray
        The coefficients, flattened row-major from (2H + 1, N), m.
    omega : float
        w, rad/s.
    force : (N,) ndarray
        Amplitude per DOF of F sin(w t), N (zeros for free motion).
    negative_damping : float
        xi of EPMC (MODEL.md 5.4): adds -xi M u', 1/s.
    jacobian : bool
        False: skip the Jacobian (a line search needs only R); ``jacobian`` is then
        an empty (0, 0) array.
    """
    n = system.n_dof
    if n == 1 and system.friction_force is None and basis.assemble is not None:
        out = prefer(_evaluate_one_dof)(
            q,
            omega,
            float(force[0]),
            float(system.mass[0, 0]),
            float(system.damping[0, 0]) - negative_damping * float(system.mass[0, 0]),
            float(system.stiffness[0, 0]),
            system.directions[:, 0].copy(),
            system.k0,
            system.k_c,
            system.k_t,
            system.g_c,
            system.g_t,
            basis.to_time,
            basis.to_coefficients,
            basis.derivative,
            basis.order,
            basis.moments,
            basis.assemble,
        )
        return Evaluation(*out)
    n_c = 2 * basis.harmonics + 1
    coef = q.reshape(n_c, n)
    m, c, k = system.mass, system.damping, system.stiffness
    c_eff = c - negative_damping * m
    w2h2 = (omega * basis.order) ** 2
    d = basis.derivative
    residual = coef @ k - (w2h2[:, None] * coef) @ m + omega * (d @ coef) @ c_eff
    residual[2] -= force
    d_omega = -2.0 * omega * (basis.order[:, None] ** 2 * coef) @ m + (d @ coef) @ c_eff
    b = system.directions
    e, p = basis.to_time, basis.to_coefficients
    delta = e @ (coef @ b.T)  # (N_t, n_j)
    f, kt = system.joint_forces(delta)
    residual += (p @ f) @ b
    blocks = basis.products(kt)  # (n_j, 2H + 1, 2H + 1): P diag(k_j) E
    kv = None
    if system.friction_force is not None:
        rel_rate = d @ (coef @ b.T)  # d delta / d tau, coefficients (2H + 1, n_j)
        speed = omega * (e @ rel_rate)
        f_fr, kv = system.friction_forces(speed)
        residual += (p @ f_fr) @ b
        d_omega += (p @ (kv * (e @ rel_rate))) @ b
        blocks = blocks + omega * (basis.products(kv) @ d)
    if not jacobian:
        return Evaluation(residual.ravel(), np.empty((0, 0)), d_omega.ravel(), kt, kv)
    jac = linear_jacobian(system, basis, omega, c_eff)
    add_joint_blocks(jac, blocks, b)
    return Evaluation(residual.ravel(), jac, d_omega.ravel(), kt, kv)


@njit(cache=True)
def _evaluate_one_dof(
    q: FloatArray,
    omega: float,
    force: float,
    m: float,
    c: float,
    k: float,
    b: FloatArray,
    k0: FloatArray,
    k_c: FloatArray,
    k_t: FloatArray,
    g_c: FloatArray,
    g_t: FloatArray,
    e: FloatArray,
    p: FloatArray,
    d: FloatArray,
    order: FloatArray,
    moments: FloatArray,
    assemble: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """:func:`evaluate` for one DOF without friction, compiled (the same sums, in one call)."""
    n_c = q.size
    n_t = e.shape[0]
    n_j = b.size
    dq = d @ q
    w2 = omega * omega
    residual = (k - m * w2 * order * order) * q + omega * c * dq
    residual[2] -= force
    d_omega = -2.0 * omega * m * order * order * q + c * dq
    u = e @ q
    f = np.empty((n_t, n_j))
    kt = np.empty((n_t, n_j))
    for n in range(n_t):
        for j in range(n_j):
            f[n, j], kt[n, j] = clearance.force_and_tangent(
                b[j] * u[n], k0[j], k_c[j], k_t[j], g_c[j], g_t[j]
            )
    jac = omega * c * d
    for i in range(n_c):
        jac[i, i] += k - m * w2 * order[i] * order[i]
    for j in range(n_j):
        residual += b[j] * (p @ np.ascontiguousarray(f[:, j]))
        block = (moments @ np.ascontiguousarray(kt[:, j])) @ assemble
        jac += (b[j] * b[j]) * block.reshape(n_c, n_c)
    return residual, jac, d_omega, kt


def linear_jacobian(
    system: LinearSystem, basis: Basis, omega: float, damping: FloatArray
) -> FloatArray:
    """Return the Jacobian of the linear part, I x K - diag((h w)^2) x M + w D x C (dense).

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    omega : float
        w, rad/s.
    damping : (N, N) ndarray
        The damping matrix to use (C, or C - xi M for EPMC), N s/m.

    Returns
    -------
    ((2H + 1) N, (2H + 1) N) ndarray
        Written block by block (no Kronecker products), N/m.
    """
    n, n_c = system.n_dof, 2 * basis.harmonics + 1
    w2h2 = (omega * basis.order) ** 2
    if n == 1:
        jac = omega * float(damping[0, 0]) * basis.derivative
        diagonal = jac.reshape(-1)[:: n_c + 1]  # a view of the diagonal
        diagonal += float(system.stiffness[0, 0]) - w2h2 * float(system.mass[0, 0])
        return jac
    jac4 = np.zeros((n_c, n, n_c, n))
    for r in range(n_c):
        jac4[r, :, r, :] = system.stiffness - w2h2[r] * system.mass
    rows, cols = np.nonzero(basis.derivative)
    for row, col in zip(rows.tolist(), cols.tolist(), strict=True):
        jac4[row, :, col, :] += (omega * basis.derivative[row, col]) * damping
    return jac4.reshape(n_c * n, n_c * n)


def add_joint_blocks(jac: FloatArray, blocks: FloatArray, directions: FloatArray) -> None:
    """Add sum over joints of G_j x b_j b_j^T to ``jac`` in place, touching only b_j's DOFs.

    Parameters
    ----------
    jac : ((2H + 1) N, (2H + 1) N) ndarray
        Dense Jacobian, coefficient-major (index = coefficient * N + dof).
    blocks : (n_j, 2H + 1, 2H + 1) ndarray
        G_j, each joint's harmonic block.
    directions : (n_j, N) ndarray
        b_j.
    """
    n_j, n_c, _ = blocks.shape
    n = directions.shape[1]
    if n == 1:
        if n_j == 1:
            jac += float(directions[0, 0]) ** 2 * blocks[0]
        else:
            jac += np.tensordot(directions[:, 0] ** 2, blocks, axes=1)
        return
    index, weights = _scatter(n_c, directions.shape, directions.tobytes())
    values = blocks[:, :, None, :, None] * weights  # (n_j, 2H + 1, k, 2H + 1, k)
    np.add.at(jac.reshape(-1), index, values.reshape(-1))


@functools.lru_cache(maxsize=8)
def _scatter(n_c: int, shape: tuple[int, ...], data: bytes) -> tuple[NDArray[np.int64], FloatArray]:
    """Where each joint's block lands in the flat Jacobian, and the b_j b_j^T weights.

    Each joint touches only the k DOFs where b_j is not zero (k the most any joint has;
    fewer are padded with weight 0). Returns the flat indices (n_j (2H + 1)^2 k^2,) and
    weights (n_j, 1, k, 1, k).
    """
    directions = np.frombuffer(data, dtype=np.float64).reshape(shape)
    n_j, n = shape
    k = max(int(np.max(np.count_nonzero(directions, axis=1))), 1)
    dofs = np.zeros((n_j, k), dtype=np.int64)
    b = np.zeros((n_j, k))
    for j in range(n_j):
        nz = np.flatnonzero(directions[j])
        dofs[j, : nz.size] = nz
        b[j, : nz.size] = directions[j, nz]
    r = np.arange(n_c)
    index = (
        (r[None, :, None, None, None] * n + dofs[:, None, :, None, None]) * n_c
        + r[None, None, None, :, None]
    ) * n + dofs[:, None, None, None, :]
    weights = (b[:, :, None] * b[:, None, :])[:, None, :, None, :]
    return index.reshape(-1), weights


def hill_exponents(
    system: LinearSystem,
    basis: Basis,
    jacobian: FloatArray,
    omega: float,
    velocity_tangent: FloatArray | None = None,
) -> NDArray[np.complex128]:
    """Return the 2N Floquet exponents (1/s) by Hill's method, from the HB Jacobian.

    Linearises (Delta_0 + lambda Delta_1 + lambda^2 Delta_2) s = 0 to a standard
    eigenproblem of size 2 (2H + 1) N (M is diagonal and positive, so Delta_2 is
    inverted exactly) and keeps the 2N eigenvalues with the smallest abs(Im lambda)
    (Lazarus & Thomas 2010). Kept as the reference sorting; the curves use
    :func:`clearjoint.harmonic.hill.spectrum` (centroid sorting).
    """
    lam = scipy.linalg.eigvals(
        hill_matrix(system, basis, jacobian, omega, velocity_tangent), check_finite=False
    )
    keep = np.argsort(np.abs(lam.imag), kind="stable")[: 2 * system.n_dof]
    return np.asarray(lam[keep], dtype=np.complex128)


def hill_matrix(
    system: LinearSystem,
    basis: Basis,
    jacobian: FloatArray,
    omega: float,
    velocity_tangent: FloatArray | None = None,
) -> FloatArray:
    """Return Hill's quadratic eigenproblem as a standard one, of size 2 (2H + 1) N.

    (Delta_0 + lambda Delta_1 + lambda^2 Delta_2) s = 0 with Delta_0 the HB Jacobian,
    Delta_1 = I x C + 2 w D x M (plus the friction's sampled viscous term) and Delta_2 =
    I x M, inverted exactly since M is diagonal: [[0, I], [-Delta_2^-1 Delta_0,
    -Delta_2^-1 Delta_1]], its first (2H + 1) N rows of an eigenvector being s.
    """
    n_c = 2 * basis.harmonics + 1
    delta1 = _damping_operator(system, basis, omega)
    if velocity_tangent is not None:  # regularised friction: a sampled viscous term
        add_joint_blocks(delta1, basis.products(velocity_tangent), system.directions)
    size = n_c * system.n_dof
    scale = np.tile(1.0 / np.diag(system.mass), n_c)[:, None]  # M is diagonal (lumped)
    a = np.zeros((2 * size, 2 * size))
    a[:size, size:] = np.eye(size)
    a[size:, :size] = -scale * jacobian
    a[size:, size:] = -scale * delta1
    return a


def _damping_operator(system: LinearSystem, basis: Basis, omega: float) -> FloatArray:
    """Delta_1 = I x C + 2 w D x M of Hill's problem, dense, coefficient-major."""
    n, n_c = system.n_dof, 2 * basis.harmonics + 1
    if n == 1:
        out = 2.0 * omega * float(system.mass[0, 0]) * basis.derivative
        out[np.diag_indices(n_c)] += float(system.damping[0, 0])
        return np.asarray(out, dtype=np.float64)
    d4 = np.zeros((n_c, n, n_c, n))
    for r in range(n_c):
        d4[r, :, r, :] = system.damping
    rows, cols = np.nonzero(basis.derivative)
    for row, col in zip(rows.tolist(), cols.tolist(), strict=True):
        d4[row, :, col, :] += (2.0 * omega * basis.derivative[row, col]) * system.mass
    return d4.reshape(n_c * n, n_c * n)


def hill_determinant_multipliers(
    system: LinearSystem, basis: Basis, jacobians: FloatArray, omega: FloatArray
) -> NDArray[np.complex128]:
    """Return the two Floquet multipliers of one DOF by Hill's infinite determinant.

    For m u'' + c u' + k(t) u = 0 (constant c), u = exp(-c t / 2m) z turns the
    perturbation into Hill's equation z'' + p(t) z = 0, p = k(t) / m - (c / 2m)^2.
    In tau = w t its truncated Hill matrix is A_0 = P diag(p / w^2) E - diag(h^2),
    and Hill's determinant (Whittaker & Watson, sec. 19.4; Magnus & Winkler, Hill's
    Equation, ch. 2) gives the trace of z's monodromy in closed form:

        tr = 2 - 4 pi^2 det(A_0) / (Gamma(H + 1 - a) Gamma(H + 1 + a))^2,  a^2 = mean(p) / w^2,

    the Gamma factors being sin^2(pi a) / (pi^2 a^2) without its first H factors
    (exact as H grows). The multipliers of z solve mu^2 - tr mu + 1 = 0; those of u
    are exp(-c T / 2m) times them. One determinant of size 2H + 1 instead of the
    eigenvalues of a matrix of size 2 (2H + 1): the same truncation, far cheaper.

    Parameters
    ----------
    system : LinearSystem
        One DOF, without friction.
    basis : Basis
    jacobians : (n, 2H + 1, 2H + 1) ndarray
        The HB Jacobian at each orbit, N/m.
    omega : (n,) ndarray
        w at each orbit, rad/s.

    Returns
    -------
    (n, 2) ndarray of complex
        The multipliers of each orbit, largest modulus first.
    """
    import scipy.special

    m = float(system.mass[0, 0])
    c = float(system.damping[0, 0])
    n_c = 2 * basis.harmonics + 1
    w = np.asarray(omega, dtype=np.float64)
    a0 = (jacobians - (w * c)[:, None, None] * basis.derivative) / (m * w * w)[:, None, None]
    a0[:, np.arange(n_c), np.arange(n_c)] -= ((c / (2.0 * m * w)) ** 2)[:, None]
    a = np.sqrt(a0[:, 0, 0].astype(np.complex128))  # mean(p) / w^2: no h^2 on the mean's row
    sign, logdet = np.linalg.slogdet(a0)
    h1 = basis.harmonics + 1.0
    log_gamma = (scipy.special.loggamma(h1 - a) + scipy.special.loggamma(h1 + a)).real
    trace = 2.0 - 4.0 * math.pi**2 * sign * np.exp(logdet - 2.0 * log_gamma)
    root = np.sqrt((trace * trace - 4.0).astype(np.complex128))
    decay = np.exp(-c * math.pi / (m * w))
    mu = np.stack(((trace + root) / 2.0, (trace - root) / 2.0), axis=1) * decay[:, None]
    order = np.argsort(-np.abs(mu), axis=1, kind="stable")
    return np.asarray(np.take_along_axis(mu, order, axis=1), dtype=np.complex128)


def hill_multipliers(exponents: NDArray[np.complex128], omega: float) -> NDArray[np.complex128]:
    """Floquet multipliers exp(lambda T), T = 2 pi / w, largest modulus first."""
    mu = np.exp(exponents * (2.0 * math.pi / omega))
    return np.asarray(mu[np.argsort(-np.abs(mu), kind="stable")], dtype=np.complex128)


@njit(cache=True)
def _correct_one_dof(
    y0: FloatArray,
    tangent: FloatArray,
    scale: FloatArray,
    tolerance: float,
    max_iterations: int,
    fixed_lambda: bool,
    k_ref: float,
    force: float,
    m: float,
    c: float,
    k: float,
    b: FloatArray,
    k0: FloatArray,
    k_c: FloatArray,
    k_t: FloatArray,
    g_c: FloatArray,
    g_t: FloatArray,
    e: FloatArray,
    p: FloatArray,
    d: FloatArray,
    order: FloatArray,
    moments: FloatArray,
    assemble: FloatArray,
) -> tuple[int, FloatArray, FloatArray, int, FloatArray, FloatArray, FloatArray, FloatArray]:
    """The continuation's arclength corrector for one DOF in w, compiled (see one_dof_corrector).

    Returns (status, y, a, iterations, R, dR/dq, dR/dw, tangent): status 1 converged,
    0 failed.
    """
    n = y0.size - 1
    y = y0.copy()
    system = np.empty((n + 1, n + 1))
    rhs = np.empty(n + 1)
    for iteration in range(max_iterations + 1):
        lam = y[n] * scale[n]
        if not lam > 0.0:
            break
        q = y[:n] * scale[:n]
        r, jac, d_omega, kt = _evaluate_one_dof(
            q, lam, force, m, c, k, b, k0, k_c, k_t, g_c, g_t, e, p, d, order, moments, assemble
        )
        size = 0.0
        finite = True
        for i in range(n):
            rs = r[i] / k_ref / scale[i]
            rhs[i] = -rs
            size = max(size, abs(rs))
            for j in range(n):
                system[i, j] = jac[i, j] / k_ref * (scale[j] / scale[i])
                finite = finite and math.isfinite(system[i, j])
            system[i, n] = d_omega[i] / k_ref * (scale[n] / scale[i])
            finite = finite and math.isfinite(system[i, n])
        if not (math.isfinite(size) and finite):
            break
        if size <= tolerance:
            return 1, y, system[:n].copy(), iteration, r, jac, d_omega, kt
        if iteration == max_iterations:
            break
        if fixed_lambda:
            system[n, :] = 0.0
            system[n, n] = 1.0
            rhs[n] = 0.0
        else:
            system[n, :] = tangent
            rhs[n] = -np.dot(tangent, y - y0)
        y = y + np.linalg.solve(system, rhs)
    empty = np.zeros(0)
    return 0, y, system[:n].copy(), 0, empty, system, empty, system


class OneDofResidual:
    """The HB residual of one DOF without friction in w, with a compiled arclength corrector.

    :func:`clearjoint.continuation.continue_branch` hands the correction to a
    residual's ``corrector`` when ``ContinuationSettings.chord_parameter`` is set; this
    one runs the continuation's own Newton iteration (rows scaled by the unknowns'
    sizes, the same tolerance) in one compiled call, with the compiled evaluation of
    :func:`evaluate`, instead of one Python round trip per iteration.

    Parameters
    ----------
    function : callable
        The plain residual(u, lam) -> (R, dR/du, dR/dlam, Evaluation), scaled by k_ref.
    system : LinearSystem
        One DOF, without friction.
    basis : Basis
        With ``assemble`` (H <= 31).
    force : float
        F0, N.
    k_ref : float
        The stiffness the residual is divided by, N/m.
    """

    def __init__(
        self,
        function: Callable[[FloatArray, float], tuple[FloatArray, FloatArray, FloatArray, Any]],
        system: LinearSystem,
        basis: Basis,
        force: float,
        k_ref: float,
    ) -> None:
        self.function = function
        self.system = system
        self.basis = basis
        self.force = force
        self.k_ref = k_ref

    def __call__(
        self, u: FloatArray, lam: float, want_lambda: bool = True
    ) -> tuple[FloatArray, FloatArray, FloatArray, Any]:
        """R, dR/du, dR/dlam and the Evaluation at (u, lam)."""
        return self.function(u, lam)

    def corrector(
        self,
        y0: FloatArray,
        tangent: FloatArray,
        scale: FloatArray,
        settings: Any,
        fixed_lambda: bool,
    ) -> tuple[FloatArray, FloatArray, Evaluation, int] | None:
        """Newton on [R(y); t . (y - y0)] = 0 (or R at fixed w), compiled; None if it fails.

        Parameters
        ----------
        y0, tangent : (d + 1,) ndarray
            Predicted point and arclength direction, scaled coordinates.
        scale : (d + 1,) ndarray
            u_scale then lam_scale.
        settings : ContinuationSettings
        fixed_lambda : bool

        Returns
        -------
        tuple or None
            (y, the scaled [dR/du, dR/dlam] (d, d + 1), Evaluation, iterations).
        """
        s, basis = self.system, self.basis
        assert basis.assemble is not None
        status, y, a, its, r, jac, d_omega, kt = prefer(_correct_one_dof)(
            np.ascontiguousarray(y0, dtype=np.float64),
            np.ascontiguousarray(tangent, dtype=np.float64),
            np.ascontiguousarray(scale, dtype=np.float64),
            float(settings.tolerance),
            int(settings.max_iterations),
            bool(fixed_lambda),
            self.k_ref,
            self.force,
            float(s.mass[0, 0]),
            float(s.damping[0, 0]),
            float(s.stiffness[0, 0]),
            s.directions[:, 0].copy(),
            s.k0,
            s.k_c,
            s.k_t,
            s.g_c,
            s.g_t,
            basis.to_time,
            basis.to_coefficients,
            basis.derivative,
            basis.order,
            basis.moments,
            basis.assemble,
        )
        if status != 1:
            return None
        return y, a, Evaluation(r, jac, d_omega, kt), int(its)
