"""Sparse LU with a reused column ordering, and bordered solves by block elimination.

The linear algebra of pseudo-arclength continuation on a large sparse residual (MODEL.md
sec. 5.1; a structure's harmonic balance, MODEL.md 5.3): every corrector iteration and
every tangent solves a system bordered by one dense row and column,

    [[A, c], [r^T, e]] [x; s] = [f; g],      A (d, d) sparse, c, r (d,), e, g scalars.

Factoring that bordered matrix directly lets its dense row and column spoil the fill-reducing
ordering (at d = 2400 a sparse LU of it costs about 5x one of A). Here only A is factored,
and the border is eliminated (x1 = A^-1 f, x2 = A^-1 c, s = (g - r.x1) / (e - r.x2),
x = x1 - s x2), then one step of iterative refinement against the whole bordered matrix
recovers the accuracy a direct LU would have where A is ill-conditioned (near a fold).

The column ordering (COLAMD, scipy's default for ``splu``) depends only on A's sparsity
pattern, which stays the same along a branch, and it costs several times the numerical
factorization: it is computed once per pattern, kept in a small cache, and later
factorizations of a matrix with the same pattern run on the pre-permuted columns with
SuperLU's natural ordering (row pivoting as before). That is the "symbolic reuse" of
issue 25; the results are those of the plain ``splu`` to rounding.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["SparseLU", "bordered_solve"]

FloatArray = NDArray[np.float64]

#: Sparsity patterns whose column ordering is kept (least recently used dropped first).
_ORDERINGS_KEPT = 16

_ORDERINGS: OrderedDict[bytes, NDArray[np.intp]] = OrderedDict()
_LOCK = threading.Lock()


def _pattern_key(matrix: Any) -> bytes:
    """A digest of a CSC matrix's shape and sparsity pattern (not its values)."""
    digest = hashlib.blake2b(digest_size=16)
    digest.update(str(matrix.shape).encode())
    digest.update(np.ascontiguousarray(matrix.indptr).tobytes())
    digest.update(np.ascontiguousarray(matrix.indices).tobytes())
    return digest.digest()


class SparseLU:
    """LU factors of a square sparse matrix (scipy's SuperLU), the column ordering reused.

    Parameters
    ----------
    matrix : (d, d) scipy sparse matrix

    Raises
    ------
    RuntimeError
        The matrix is exactly singular (SuperLU's "Factor is exactly singular").
    """

    def __init__(self, matrix: Any) -> None:
        import scipy.sparse
        import scipy.sparse.linalg

        csc = scipy.sparse.csc_matrix(matrix)
        csc.sort_indices()
        self.shape = csc.shape
        key = _pattern_key(csc)
        with _LOCK:
            order = _ORDERINGS.get(key)
            if order is not None:
                _ORDERINGS.move_to_end(key)
        if order is None:
            # the first matrix of this pattern: COLAMD, and its ordering kept
            self._lu = scipy.sparse.linalg.splu(csc)
            order = np.argsort(self._lu.perm_c)
            with _LOCK:
                _ORDERINGS[key] = order
                while len(_ORDERINGS) > _ORDERINGS_KEPT:
                    _ORDERINGS.popitem(last=False)
            self._order: NDArray[np.intp] | None = None
        else:
            self._lu = scipy.sparse.linalg.splu(csc[:, order], permc_spec="NATURAL")
            self._order = order

    def solve(self, rhs: FloatArray) -> FloatArray:
        """Return x with matrix @ x = rhs, rhs (d,) or (d, k)."""
        z = np.asarray(self._lu.solve(np.asarray(rhs, dtype=np.float64)), dtype=np.float64)
        if self._order is None:
            return z
        x = np.empty_like(z)
        x[self._order] = z
        return x


def bordered_solve(
    matrix: Any,
    column: FloatArray,
    row: FloatArray,
    corner: float,
    rhs: FloatArray,
    last: float,
    lu: SparseLU | None = None,
) -> FloatArray:
    """Return [x; s] solving [[matrix, column], [row^T, corner]] [x; s] = [rhs; last].

    By block elimination on the LU of ``matrix`` alone, then one step of iterative
    refinement on the whole bordered system (module docstring).

    Parameters
    ----------
    matrix : (d, d) scipy sparse matrix
    column, row : (d,) ndarray
    corner, last : float
    rhs : (d,) ndarray
    lu : SparseLU, optional
        ``matrix``'s factors, if already at hand.

    Returns
    -------
    (d + 1,) ndarray

    Raises
    ------
    RuntimeError
        ``matrix`` is exactly singular, or the border's Schur complement is zero or not
        finite (the caller falls back to a direct LU of the bordered matrix).
    """
    factors = lu if lu is not None else SparseLU(matrix)
    out = _eliminate(factors, column, row, corner, rhs, last)
    # one refinement step: the residual of the whole bordered system, solved again
    d = rhs.size
    miss = np.empty(d + 1)
    miss[:d] = rhs - (matrix @ out[:d] + column * out[d])
    miss[d] = last - (float(row @ out[:d]) + corner * out[d])
    out += _eliminate(factors, column, row, corner, miss[:d], float(miss[d]))
    return out


def _eliminate(
    lu: SparseLU, column: FloatArray, row: FloatArray, corner: float, rhs: FloatArray, last: float
) -> FloatArray:
    """One block elimination of the border (see :func:`bordered_solve`)."""
    both = lu.solve(np.column_stack((rhs, column)))
    x1, x2 = both[:, 0], both[:, 1]
    schur = corner - float(row @ x2)
    if schur == 0.0 or not np.isfinite(schur):
        raise RuntimeError("the bordered system's Schur complement is zero or not finite")
    s = (last - float(row @ x1)) / schur
    out = np.empty(rhs.size + 1)
    out[:-1] = x1 - s * x2
    out[-1] = s
    return out
