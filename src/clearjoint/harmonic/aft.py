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
Delta_1 = I x C + 2 w D x M, Delta_2 = I x M; of its 2 N (2H + 1) eigenvalues the 2N
with the smallest imaginary parts are kept, and the Floquet multipliers are
exp(lambda T), T = 2 pi / w.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from clearjoint.harmonic.system import HarmonicError, LinearSystem

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
    """

    harmonics: int
    samples: int
    to_time: FloatArray
    to_coefficients: FloatArray
    derivative: FloatArray
    order: FloatArray

    @classmethod
    def make(cls, harmonics: int, samples: int) -> Basis:
        """Build the basis for H harmonics and N_t samples."""
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
        return cls(harmonics, samples, e, p, d, order)

    def evaluate(self, coefficients: FloatArray, tau: FloatArray) -> FloatArray:
        """Return u(tau) for coefficients (2H + 1, ...) at phases tau (n,): shape (n, ...)."""
        h = np.arange(1, self.harmonics + 1)
        e = np.empty((tau.size, 2 * self.harmonics + 1))
        e[:, 0] = 1.0
        e[:, 1::2] = np.cos(np.outer(tau, h))
        e[:, 2::2] = np.sin(np.outer(tau, h))
        return np.asarray(np.tensordot(e, coefficients, axes=(1, 0)), dtype=np.float64)

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
                u1 = _diag_eval(self, d1, t)
                u2 = _diag_eval(self, d2, t)
                step = np.where(u2 != 0.0, u1 / np.where(u2 != 0.0, u2, 1.0), 0.0)
                t = t - np.clip(step, -math.pi / fine, math.pi / fine)
            out.append(_diag_eval(self, coefficients, t))
        return out[0], out[1]


def _diag_eval(basis: Basis, coefficients: FloatArray, tau: FloatArray) -> FloatArray:
    """u_k(tau_k) for each column k of coefficients (2H + 1, n) at its own phase tau (n,)."""
    h = np.arange(1, basis.harmonics + 1)
    e = np.empty((tau.size, 2 * basis.harmonics + 1))
    e[:, 0] = 1.0
    e[:, 1::2] = np.cos(np.outer(tau, h))
    e[:, 2::2] = np.sin(np.outer(tau, h))
    return np.asarray(np.einsum("kc,ck->k", e, coefficients), dtype=np.float64)


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
    """
    n = system.n_dof
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
    if n == 1:  # one DOF (a Joint): every block is a number
        jac = omega * float(c_eff[0, 0]) * d
        jac[np.diag_indices(n_c)] += float(k[0, 0]) - w2h2 * float(m[0, 0])
        for j in range(b.shape[0]):
            jac += (float(b[j, 0]) ** 2) * ((p * kt[:, j]) @ e)
    else:
        jac = np.kron(np.eye(n_c), k) - np.kron(np.diag(w2h2), m) + omega * np.kron(d, c_eff)
        for j in range(b.shape[0]):
            jac += np.kron((p * kt[:, j]) @ e, np.outer(b[j], b[j]))
    kv = None
    if system.friction_force is not None:
        rel_rate = d @ (coef @ b.T)  # d delta / d tau, coefficients (2H + 1, n_j)
        speed = omega * (e @ rel_rate)
        f_fr, kv = system.friction_forces(speed)
        residual += (p @ f_fr) @ b
        d_omega += (p @ (kv * (e @ rel_rate))) @ b
        for j in range(b.shape[0]):
            g = omega * (((p * kv[:, j]) @ e) @ d)
            jac += g if n == 1 else np.kron(g, np.outer(b[j], b[j]))
    return Evaluation(residual.ravel(), jac, d_omega.ravel(), kt, kv)


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
    (Lazarus & Thomas 2010).
    """
    n = system.n_dof
    n_c = 2 * basis.harmonics + 1
    inv_m = np.linalg.inv(system.mass)
    eye = np.eye(n_c)
    delta1 = np.kron(eye, system.damping) + 2.0 * omega * np.kron(basis.derivative, system.mass)
    if velocity_tangent is not None:  # regularised friction: a sampled viscous term
        b = system.directions
        for j in range(b.shape[0]):
            g = (basis.to_coefficients * velocity_tangent[:, j]) @ basis.to_time
            delta1 += np.kron(g, np.outer(b[j], b[j]))
    minv = np.kron(eye, inv_m)
    size = n_c * n
    a = np.zeros((2 * size, 2 * size))
    a[:size, size:] = np.eye(size)
    a[size:, :size] = -minv @ jacobian
    a[size:, size:] = -minv @ delta1
    lam = scipy.linalg.eigvals(a, check_finite=False)
    keep = np.argsort(np.abs(lam.imag), kind="stable")[: 2 * n]
    return np.asarray(lam[keep], dtype=np.complex128)


def hill_multipliers(exponents: NDArray[np.complex128], omega: float) -> NDArray[np.complex128]:
    """Floquet multipliers exp(lambda T), T = 2 pi / w, largest modulus first."""
    mu = np.exp(exponents * (2.0 * math.pi / omega))
    return np.asarray(mu[np.argsort(-np.abs(mu), kind="stable")], dtype=np.complex128)
