"""Sparse LU with a reused column ordering and bordered solves (clearjoint/bordered.py).

Checked against numpy's dense solve of the whole bordered matrix (an independent route),
also where the sparse block is nearly singular (a fold of the continued branch).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse

from clearjoint import bordered


def _matrix(seed: int, d: int = 60) -> scipy.sparse.csr_matrix:
    rng = np.random.default_rng(seed)
    a = scipy.sparse.random(d, d, density=0.08, random_state=rng, format="csr")
    return scipy.sparse.csr_matrix(a + scipy.sparse.diags(rng.uniform(1.0, 2.0, d)))


def _dense_bordered(a, column, row, corner, rhs, last):  # type: ignore[no-untyped-def]
    d = a.shape[0]
    full = np.zeros((d + 1, d + 1))
    full[:d, :d] = a.toarray()
    full[:d, d] = column
    full[d, :d] = row
    full[d, d] = corner
    return np.linalg.solve(full, np.append(rhs, last))


def test_sparse_lu_with_a_kept_ordering_solves_like_numpy() -> None:
    """The first matrix of a pattern orders its columns (COLAMD); a second one with the same
    pattern and other values is factored on those columns: both solve to rounding."""
    a = _matrix(1)
    b = scipy.sparse.csr_matrix((a.data * np.linspace(0.5, 1.5, a.nnz), a.indices, a.indptr))
    rhs = np.random.default_rng(2).standard_normal(a.shape[0])
    first, second = bordered.SparseLU(a), bordered.SparseLU(b)
    assert second._order is not None  # the kept ordering was used
    for matrix, lu in ((a, first), (b, second)):
        np.testing.assert_allclose(
            lu.solve(rhs), np.linalg.solve(matrix.toarray(), rhs), rtol=1e-12, atol=1e-12
        )


@pytest.mark.parametrize("near_fold", [False, True])
def test_bordered_solve_is_the_dense_solve(near_fold: bool) -> None:
    """Block elimination plus one refinement step: numpy's solve of the bordered matrix to
    1e-10, also with a sparse block of condition number about 1e10 (two rows nearly equal;
    the bordered matrix itself well conditioned, as at a fold)."""
    rng = np.random.default_rng(3)
    a = _matrix(4).toarray()
    if near_fold:  # row 5 = row 4 to 1e-10: the block's condition number about 1e10
        a[5] = a[4] * (1.0 + 1e-10)
        a[5, 5] += 1e-10
        assert np.linalg.cond(a) > 1e8
    matrix = scipy.sparse.csr_matrix(a)
    d = a.shape[0]
    column, row, rhs = rng.standard_normal((3, d))
    found = bordered.bordered_solve(matrix, column, row, 0.3, rhs, -0.7)
    expected = _dense_bordered(matrix, column, row, 0.3, rhs, -0.7)
    np.testing.assert_allclose(found, expected, rtol=1e-10, atol=1e-10 * np.abs(expected).max())


def test_singular_block_says_so() -> None:
    """An exactly singular sparse block raises RuntimeError (the callers then factor the
    whole bordered matrix)."""
    a = _matrix(5).tolil()
    a[3, :] = 0.0
    with pytest.raises(RuntimeError):
        bordered.bordered_solve(
            scipy.sparse.csr_matrix(a), np.ones(60), np.ones(60), 1.0, np.ones(60), 0.0
        )
