"""A contact pattern's exact linear flow expm(A t), decomposed once (MODEL.md 5.1, 5.2).

In one contact pattern a structure (or a joint) is linear, y' = A y, so its flow over any
time t is expm(A t). Decomposing A = V B V^-1 once, with B real block-diagonal (1 x 1
blocks for real eigenvalues, [[a, b], [-b, a]] for a pair a +- i b) after a diagonal
balancing by powers of 2, gives expm(A t) = V expm(B t) V^-1 exactly, expm(B t) in closed
form (e^(a t) times a rotation by b t). The monodromy of a harmonic-balance orbit
(``clearjoint.harmonic.monodromy``) and the tangent flow of a structure's exact motion
(``clearjoint.structure.tangent``) chain these per stretch between gap-edge events.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

__all__ = ["MAX_CONDITION", "PatternFlow", "Stretch", "chain", "decompose"]

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


#: What a stretch's pattern gives :func:`chain`: its decomposition, or its generator A
#: (a pattern whose V is ill-conditioned: its exponential is taken by scipy.linalg.expm).
Stretch = PatternFlow | FloatArray


def chain(
    start: FloatArray,
    times: Sequence[float] | FloatArray,
    keys: Sequence[bytes],
    flow_of: Callable[[int], Stretch],
    transition: Callable[[bytes, PatternFlow, bytes, PatternFlow], FloatArray],
) -> FloatArray:
    """Return expm(A_k t_k) ... expm(A_1 t_1) @ start over stretches of the given patterns.

    The product is carried in the patterns' eigen-coordinates (module docstring): one
    change of coordinates where the pattern changes, ``transition(key_from, flow_from,
    key_to, flow_to)`` = V_to^-1 V_from (the caller caches it), and a closed-form
    scaling per stretch. Stretch i lasts ``times[i]`` (s; those not positive are
    skipped) in the pattern ``keys[i]``, whose ``flow_of(i)`` is a :class:`PatternFlow`
    or, where V is ill-conditioned, the generator A itself (its exponential then by
    ``scipy.linalg.expm``; A is used at once, so the caller may reuse its array).

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
        if not isinstance(flow, PatternFlow):  # the plain exponential
            if here is not None:
                phi = here.vectors @ phi
                here = None
            phi = scipy.linalg.expm(flow * t) @ phi
            continue
        if here is None:
            phi = flow.inverse @ phi
        elif here_key != key:
            phi = transition(here_key, here, key, flow) @ phi
        phi = flow.propagate(float(t), phi)
        here, here_key = flow, key
    if here is not None:
        phi = here.vectors @ phi
    return np.asarray(phi, dtype=np.float64)
