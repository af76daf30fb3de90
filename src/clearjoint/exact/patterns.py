"""A contact pattern's exact linear flow expm(A t), decomposed once (MODEL.md 5.1, 5.2).

In one contact pattern a structure (or a joint) is linear, y' = A y, so its flow over any
time t is expm(A t). Decomposing A = V B V^-1 once, with B real block-diagonal (1 x 1
blocks for real eigenvalues, [[a, b], [-b, a]] for a pair a +- i b) after a diagonal
balancing by powers of 2, gives expm(A t) = V expm(B t) V^-1 exactly, expm(B t) in closed
form (e^(a t) times a rotation by b t). The monodromy of a harmonic-balance orbit
(``clearjoint.harmonic.monodromy``) and the tangent flow of a structure's exact motion
(``clearjoint.structure.tangent``) chain these per stretch between gap-edge events.

A stretch too short to pay for a decomposition (a few oscillations of the fastest mode:
two joints crossing their edges a fraction of a millisecond apart make a pattern that
lasts that long and may never come back) is taken by :class:`ShortFlow` instead: the
Taylor series of expm(A t) applied to the block, with the sparse A, in substeps whose
scaled norm is at most ``SHORT_STEP`` (issue 25: no 2N x 2N eigendecomposition for it).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = [
    "MAX_CONDITION",
    "SHORT_STEP",
    "PatternFlow",
    "ShortFlow",
    "Stretch",
    "chain",
    "decompose",
]

#: A pattern's A = V B V^-1 is used when V's 1-norm condition number (balanced
#: coordinates) is at most this; above it (a defective or nearly defective A) the segment
#: keeps scipy.linalg.expm. The similarity's rounding is about cond(V) eps per segment.
MAX_CONDITION = 1e6


@dataclass(frozen=True)
class PatternFlow:
    """expm(A t) = vectors @ expm(B t) @ inverse for one contact pattern's A (2N, 2N).

    The columns are the ``real`` real eigenvectors, then Re v of each pair a +- i b,
    then Im v of each pair in the same order: B is ``rate`` on the diagonal, and for
    pair i the block [[a, b], [-b, a]] on (real + i, real + p + i), p pairs, with a =
    ``rate[real + i]`` and b = ``frequency[i]``.
    """

    vectors: FloatArray
    inverse: FloatArray
    rate: FloatArray
    real: int
    frequency: FloatArray

    def propagate(self, t: float, psi: FloatArray) -> FloatArray:
        """Return expm(B t) @ psi, psi (2N, m) in this pattern's eigen-coordinates."""
        out = psi * np.exp(self.rate * t)[:, None]
        p = self.frequency.size
        c = np.cos(self.frequency * t)[:, None]
        s = np.sin(self.frequency * t)[:, None]
        first = out[self.real : self.real + p].copy()
        second = out[self.real + p :]
        out[self.real : self.real + p] = c * first + s * second
        second *= c
        second -= s * first
        return out


def decompose(a: FloatArray) -> PatternFlow | None:
    """Return A's real block eigen-decomposition, or None where it is not to be trusted.

    Parameters
    ----------
    a : (2N, 2N) ndarray
        The pattern's state matrix, 1/s.

    Returns
    -------
    _Flow or None
        None when A (balanced by powers of 2) has an eigenvector matrix whose 1-norm
        condition number exceeds ``MAX_CONDITION`` or cannot be inverted.
    """
    balanced, (scale, _) = scipy.linalg.matrix_balance(a, permute=False, separate=True)
    lam, v = np.linalg.eig(balanced)
    upper = np.flatnonzero(lam.imag > 0.0)
    real = np.flatnonzero(lam.imag == 0.0)
    if real.size + 2 * upper.size != lam.size:  # not in conjugate pairs: let expm decide
        return None
    vectors = np.empty_like(a)
    rate = np.empty(lam.size)
    vectors[:, : real.size] = v[:, real].real
    rate[: real.size] = lam[real].real
    p, r = upper.size, real.size
    vectors[:, r : r + p] = v[:, upper].real
    vectors[:, r + p :] = v[:, upper].imag
    rate[r : r + p] = rate[r + p :] = lam[upper].real
    try:
        inverse = np.linalg.inv(vectors)
    except np.linalg.LinAlgError:
        return None
    condition = np.linalg.norm(vectors, 1) * np.linalg.norm(inverse, 1)
    if not condition <= MAX_CONDITION:
        return None
    # back to the unbalanced coordinates: A = D balanced D^-1, D = diag(scale) (powers of 2)
    return PatternFlow(
        vectors=scale[:, None] * vectors,
        inverse=inverse / scale[None, :],
        rate=rate,
        real=r,
        frequency=np.asarray(lam[upper].imag, dtype=np.float64),
    )


#: :class:`ShortFlow` takes substeps h with ``bound * h`` at most this: the Taylor terms
#: then stay below e^4 ~ 55 times the result, so cancellation costs at most ~6 eps.
SHORT_STEP = 4.0

#: Taylor terms per substep at most (4^40 / 40! ~ 1e-24: never reached when the bound holds).
_TERMS = 40


def _terms(theta: float) -> int:
    """Taylor terms m for expm(X) with ||X|| <= theta <= SHORT_STEP: the remainder,
    at most theta^(m+1) / (m+1)! e^theta in that norm, below 2^-56 (a priori: no test on
    the terms, whose cost would match the products' on a few columns)."""
    m, last = 0, theta  # last: theta^(m+1) / (m+1)!
    while last * math.exp(theta) > 2.0**-56 and m < _TERMS:
        m += 1
        last *= theta / (m + 1)
    return m


@dataclass(frozen=True)
class ShortFlow:
    """expm(A t) @ psi by A's Taylor series, for one pattern's stretches of short duration.

    Parameters
    ----------
    generator : (2N, 2N) scipy sparse matrix
        The pattern's A, 1/s.
    bound : float
        A bound on the norm of A in scaled coordinates, 1/s (:meth:`for_structure`):
        the substeps are chosen from it.
    velocity_scale : float
        sigma, 1/s: the series runs on (y, y' / sigma), where A's blocks are of one size.
    """

    generator: Any
    bound: float
    velocity_scale: float

    @classmethod
    def for_structure(cls, inverse_mass: FloatArray, stiffness: Any, damping: Any) -> ShortFlow:
        """The flow of M y'' + C y' + K y = 0 (M diagonal, its inverse given as a vector).

        With sigma^2 = ||M^-1 K||_inf, A in the coordinates (y, y' / sigma) is
        [[0, sigma I], [-M^-1 K / sigma, -M^-1 C]], whose infinity norm is at most
        ``bound`` = sigma + ||M^-1 C||_inf.
        """
        import scipy.sparse

        n = inverse_mass.size
        k = scipy.sparse.csr_matrix(inverse_mass[:, None] * np.asarray(stiffness))
        c = scipy.sparse.csr_matrix(inverse_mass[:, None] * np.asarray(damping))
        sigma = math.sqrt(max(float(abs(k).sum(axis=1).max()), 1e-300))
        c_norm = float(abs(c).sum(axis=1).max()) if c.nnz else 0.0
        generator = scipy.sparse.bmat(
            [[None, scipy.sparse.identity(n) * sigma], [-k / sigma, -c]], format="csr"
        )
        return cls(generator=generator, bound=sigma + c_norm, velocity_scale=sigma)

    def steps(self, t: float) -> int:
        """Substeps a stretch of t seconds takes (its cost is about 30 of them per product)."""
        return max(1, math.ceil(self.bound * t / SHORT_STEP))

    def propagate(self, t: float, phi: FloatArray) -> FloatArray:
        """Return expm(A t) @ phi, phi (2N, m) in physical coordinates (y, y')."""
        n = phi.shape[0] // 2
        z = np.array(phi, dtype=np.float64)
        z[n:] /= self.velocity_scale
        s = self.steps(t)
        h = t / s
        terms = _terms(self.bound * h)
        for _ in range(s):
            total = z.copy()
            term = z
            for j in range(1, terms + 1):
                term = self.generator @ term
                term *= h / j
                total += term
            z = total
        z[n:] *= self.velocity_scale
        return z


#: What a stretch's pattern gives :func:`chain`: its decomposition, its Taylor series
#: (:class:`ShortFlow`, a short stretch), or its generator A (a pattern whose V is
#: ill-conditioned: its exponential is taken by scipy.linalg.expm).
Stretch = PatternFlow | ShortFlow | FloatArray


def chain(
    start: FloatArray,
    times: Sequence[float] | FloatArray,
    keys: Sequence[bytes],
    flow_of: Callable[[int], Stretch],
    transition: Callable[[bytes, PatternFlow, bytes, PatternFlow], FloatArray | None],
) -> FloatArray:
    """Return expm(A_k t_k) ... expm(A_1 t_1) @ start over stretches of the given patterns.

    The product is carried in the patterns' eigen-coordinates (module docstring): one
    change of coordinates where the pattern changes, ``transition(key_from, flow_from,
    key_to, flow_to)`` = V_to^-1 V_from (the caller caches it), and a closed-form
    scaling per stretch (where ``transition`` returns None, the change goes through y
    and y' instead: two products, V_to^-1 (V_from phi)). Stretch i lasts ``times[i]``
    (s; those not positive are skipped) in the pattern ``keys[i]``, whose ``flow_of(i)``
    is a :class:`PatternFlow`, a :class:`ShortFlow` or, where V is ill-conditioned, the
    generator A itself (its exponential then by ``scipy.linalg.expm``; A is used at once,
    so the caller may reuse its array).

    Parameters
    ----------
    start : (2N, m) ndarray
    times : (k,) sequence of float
    keys : (k,) sequence of bytes
    flow_of : callable
    transition : callable

    Returns
    -------
    (2N, m) ndarray
    """
    phi = np.array(start, dtype=np.float64)
    here: PatternFlow | None = None  # the pattern whose eigen-coordinates phi is in
    here_key = b""
    for i, (t, key) in enumerate(zip(times, keys, strict=True)):
        if t <= 0.0:
            continue
        flow = flow_of(i)
        if isinstance(flow, ShortFlow):  # Taylor's series on the block, in y and y'
            if here is not None:
                phi = here.vectors @ phi
                here = None
            phi = flow.propagate(float(t), phi)
            continue
        if not isinstance(flow, PatternFlow):  # the plain exponential
            if here is not None:
                phi = here.vectors @ phi
                here = None
            phi = scipy.linalg.expm(flow * t) @ phi
            continue
        if here is None:
            phi = flow.inverse @ phi
        elif here_key != key:
            change = transition(here_key, here, key, flow)  # None: not formed, through y
            phi = flow.inverse @ (here.vectors @ phi) if change is None else change @ phi
        phi = flow.propagate(float(t), phi)
        here, here_key = flow, key
    if here is not None:
        phi = here.vectors @ phi
    return np.asarray(phi, dtype=np.float64)
