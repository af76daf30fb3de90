"""Newton's method on the harmonic-balance residual, and the linear first guesses (MODEL.md 5.3).

Shared by the frequency response and the nonlinear modes. Residuals are made
dimensionless by a reference stiffness and a length, so one tolerance serves
every system.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.bordered import SparseLU, bordered_solve
from clearjoint.harmonic.aft import Basis, Evaluation, _scatter
from clearjoint.harmonic.system import LinearSystem

FloatArray = NDArray[np.float64]

#: Converged when max abs(R) / (k_ref x_scale) is below this.
TOLERANCE = 1e-11

#: Newton's linear solves use a sparse LU (scipy's splu) above this many unknowns. A
#: structure's HB Jacobian holds N x N blocks only where D or a joint couples two
#: harmonics, a few % of its entries for the mast; below this size the dense LU is faster
#: (``python benchmarks/bench_harmonic.py --mast`` times both).
SPARSE_ABOVE = 400


def linear_solve(jacobian: Any, rhs: FloatArray) -> FloatArray:
    """Solve jacobian x = rhs: dense LU, or sparse LU above :data:`SPARSE_ABOVE` unknowns.

    ``jacobian`` is a dense array or a scipy sparse matrix (:class:`SparseJacobian`),
    which is always factored sparse. A singular matrix falls back to least squares
    (dense) in both cases.
    """
    if not isinstance(jacobian, np.ndarray) or jacobian.shape[0] > SPARSE_ABOVE:
        try:
            x = SparseLU(jacobian).solve(rhs)  # the column ordering reused along Newton
            if np.all(np.isfinite(x)):
                return np.asarray(x, dtype=np.float64)
        except RuntimeError:  # "Factor is exactly singular"
            pass
    else:
        try:
            return np.asarray(np.linalg.solve(jacobian, rhs), dtype=np.float64)
        except np.linalg.LinAlgError:
            pass
    dense = jacobian if isinstance(jacobian, np.ndarray) else jacobian.toarray()
    return np.asarray(np.linalg.lstsq(dense, rhs, rcond=None)[0], dtype=np.float64)


class SparseJacobian:
    """The HB Jacobian dR/dq of a structure assembled sparse (CSR), never dense.

    The same sum as :func:`clearjoint.harmonic.aft.evaluate`'s dense Jacobian
    (MODEL.md 5.3): I x K - diag((h w)^2) x M + w D x C_eff on the diagonal and the
    derivative's blocks, plus sum over joints of G_j x b_j b_j^T. Its pattern (where an
    entry can be non-zero: K, M, C and each joint's DOFs) is found once; each call only
    adds the values into it, so a (2H + 1) N square matrix is never formed.

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    """

    def __init__(self, system: LinearSystem, basis: Basis) -> None:
        import scipy.sparse

        self.system, self.basis = system, basis
        n, n_c = system.n_dof, 2 * basis.harmonics + 1
        self.size = n * n_c
        m, k, c = system.mass, system.stiffness, system.damping
        r_mk, c_mk = np.nonzero((k != 0.0) | (m != 0.0))
        # EPMC's damping C - xi M: the pattern of C and M
        r_c, c_c = np.nonzero((c != 0.0) | (m != 0.0))
        self._mk = (r_mk, c_mk)
        self._cm = (r_c, c_c)
        d_rows, d_cols = np.nonzero(basis.derivative)
        self._d_values = basis.derivative[d_rows, d_cols]
        blocks = np.arange(n_c)
        rows = [(blocks[:, None] * n + r_mk).ravel(), (d_rows[:, None] * n + r_c).ravel()]
        cols = [(blocks[:, None] * n + c_mk).ravel(), (d_cols[:, None] * n + c_c).ravel()]
        self._joints = system.directions.shape[0] > 0
        if self._joints:
            index, self._weights = _scatter(
                n_c, system.directions.shape, system.directions.tobytes()
            )
            rows.append(index // self.size)
            cols.append(index % self.size)
        row, col = np.concatenate(rows), np.concatenate(cols)
        # each entry's place among the matrix's unique (row, col) pairs, in CSR order
        flat = row * self.size + col
        unique, self._where = np.unique(flat, return_inverse=True)
        self._nnz = unique.size
        pattern = scipy.sparse.csr_matrix(
            (np.ones(unique.size), (unique // self.size, unique % self.size)),
            shape=(self.size, self.size),
        )
        pattern.sort_indices()
        self._indices, self._indptr = pattern.indices, pattern.indptr

    def __call__(self, evaluation: Evaluation, omega: float, damping: FloatArray) -> Any:
        """dR/dq at the point ``evaluation`` was taken, N/m, as a scipy CSR matrix.

        Parameters
        ----------
        evaluation : Evaluation
            :func:`clearjoint.harmonic.aft.evaluate` at (q, w) (its Jacobian may be
            skipped): the joints' sampled tangents.
        omega : float
            w, rad/s.
        damping : (N, N) ndarray
            The damping matrix the residual used (C, or C - xi M for EPMC), N s/m.

        Returns
        -------
        ((2H + 1) N, (2H + 1) N) scipy.sparse.csr_matrix
        """
        import scipy.sparse

        system, basis = self.system, self.basis
        w2h2 = (omega * basis.order) ** 2
        r_mk, c_mk = self._mk
        r_c, c_c = self._cm
        diagonal = system.stiffness[r_mk, c_mk] - w2h2[:, None] * system.mass[r_mk, c_mk]
        coupling = (omega * self._d_values)[:, None] * damping[r_c, c_c]
        values = [diagonal.ravel(), coupling.ravel()]
        if self._joints:
            blocks = basis.products(evaluation.tangent)  # (n_j, 2H + 1, 2H + 1): P diag(k_j) E
            if evaluation.velocity_tangent is not None:
                blocks = blocks + omega * (
                    basis.products(evaluation.velocity_tangent) @ basis.derivative
                )
            values.append((blocks[:, :, None, :, None] * self._weights).ravel())
        data = np.bincount(self._where, weights=np.concatenate(values), minlength=self._nnz)
        return scipy.sparse.csr_matrix(
            (data, self._indices, self._indptr), shape=(self.size, self.size)
        )


def linear_guess(
    system: LinearSystem, basis: Basis, omega: float, force: FloatArray, stiffness: FloatArray
) -> FloatArray:
    """First-harmonic response of M u'' + C u' + K_s u = F sin(w t), flattened as HB unknowns.

    With X = (K_s - w^2 M + i w C)^-1 F, u = Im(X e^(i w t)), so a_1 = Im X, b_1 = Re X.
    A singular K_s - w^2 M (a free mechanism) is solved in the least-squares sense.
    """
    n = system.n_dof
    z = stiffness - omega**2 * system.mass + 1j * omega * system.damping
    x = np.linalg.lstsq(z, force.astype(np.complex128), rcond=None)[0]
    coef = np.zeros((2 * basis.harmonics + 1, n))
    coef[1] = x.imag
    coef[2] = x.real
    return coef.ravel()


def newton(
    function: Callable[[FloatArray], tuple[FloatArray, Any]],
    q0: FloatArray,
    scale: float,
    *,
    max_iterations: int = 80,
    residual: Callable[[FloatArray], FloatArray] | None = None,
    stall: int | None = None,
) -> tuple[FloatArray, int] | None:
    """Damped Newton on a dimensionless residual: ``function(q) -> (R, dR/dq)``.

    dR/dq dense or scipy sparse (:func:`linear_solve`).

    Steps are halved (up to 12 times) until max abs(R) falls; ``scale`` (m) makes q
    dimensionless in the convergence test. ``residual(q) -> R``, if given, is used
    for the halved trial steps (no Jacobian needed there). ``stall``: give up when
    max abs(R) has not halved in that many iterations (a Newton that creeps: from a
    poor guess on a large structure it stalls within a few iterations and would spend
    the rest of ``max_iterations`` with a sparse LU and a dozen evaluations each).
    Returns (q, iterations) or None.
    """
    q = q0.copy()
    r, jac = function(q)
    size = float(np.max(np.abs(r)))
    history = [size]
    for iteration in range(max_iterations):
        if not np.isfinite(size):
            return None
        if size <= TOLERANCE * scale:
            return q, iteration
        if stall is not None and iteration >= stall and size > 0.5 * history[-stall - 1]:
            return None
        dq = linear_solve(jac, -r)
        step = 1.0
        jac_t: FloatArray | None = None
        for _ in range(13):
            trial = q + step * dq
            if step == 1.0 or residual is None:
                r_t, jac_t = function(trial)
            else:
                r_t, jac_t = residual(trial), None
            size_t = float(np.max(np.abs(r_t)))
            if size_t < size or size_t <= TOLERANCE * scale:
                break
            step *= 0.5
        if jac_t is None:
            r_t, jac_t = function(trial)
        q, r, jac, size = trial, r_t, jac_t, size_t
        history.append(size)
    return (q, max_iterations) if size <= TOLERANCE * scale else None


class SparseResidual:
    """A continuation residual whose arclength corrector solves its bordered systems sparse.

    :func:`clearjoint.continuation.continue_branch` hands the correction to a
    residual's ``corrector`` method when ``ContinuationSettings.chord_parameter`` is
    set. This one runs the same Newton iteration as the continuation's own corrector
    (rows scaled by the unknowns' sizes, converged when every scaled residual is below
    the tolerance) but factors the bordered matrix [[dR/du, dR/dlam], [t^T or e_lam]]
    by a sparse LU (scipy's splu) instead of a dense solve: a structure's HB Jacobian
    is mostly zero blocks. The scaled [dR/du, dR/dlam] it returns is sparse too, so the
    continuation's tangent is a sparse solve as well (``continuation._tangent``).

    Parameters
    ----------
    function : callable
        function(u, lam) -> (R (d,), dR/du (d, d), dR/dlam (d,), data), as
        :data:`clearjoint.continuation.Residual`; dR/du a scipy sparse matrix (see
        :class:`SparseJacobian`) or a dense array.
    """

    def __init__(
        self,
        function: Callable[[FloatArray, float], tuple[FloatArray, Any, FloatArray, object]],
    ) -> None:
        self.function = function

    def __call__(
        self, u: FloatArray, lam: float, want_lambda: bool = True
    ) -> tuple[FloatArray, FloatArray, FloatArray, object]:
        """R, dR/du (dense), dR/dlam and the data at (u, lam) (``want_lambda`` unused)."""
        r, jac_u, r_lam, data = self.function(u, lam)
        dense = jac_u if isinstance(jac_u, np.ndarray) else jac_u.toarray()
        return r, np.asarray(dense, dtype=np.float64), r_lam, data

    def corrector(
        self,
        y0: FloatArray,
        tangent: FloatArray,
        scale: FloatArray,
        settings: Any,
        fixed_lambda: bool,
    ) -> tuple[FloatArray, Any, object, int] | None:
        """Newton on [R(y); t . (y - y0)] = 0 (or R at fixed lambda), sparse; None if it fails.

        Parameters
        ----------
        y0 : (d + 1,) ndarray
            The predicted point in scaled coordinates (u / u_scale, lam / lam_scale).
        tangent : (d + 1,) ndarray
            The arclength direction.
        scale : (d + 1,) ndarray
            u_scale then lam_scale.
        settings : ContinuationSettings
        fixed_lambda : bool
            Correct at the fixed parameter instead.

        Returns
        -------
        tuple or None
            (y (d + 1,), the scaled [dR/du, dR/dlam] (d, d + 1) as a scipy CSR matrix,
            data, iterations).
        """
        import scipy.sparse

        from clearjoint.errors import ClearjointError

        y = y0.copy()
        d = y.size - 1
        u_scale = scale[:d]
        if fixed_lambda:
            row, corner = np.zeros(d), 1.0
        else:
            row, corner = tangent[:d], float(tangent[d])
        for iteration in range(settings.max_iterations + 1):
            try:
                r, jac_u, r_lam, data = self.function(y[:d] * u_scale, float(y[d] * scale[d]))
            except ClearjointError:
                return None
            # rows scaled by the unknowns' sizes, columns by the scaled unknowns
            jac = _scaled(jac_u, u_scale)
            column = r_lam * (scale[d] / u_scale)
            rs = r / u_scale
            size = float(np.max(np.abs(rs)))
            finite = np.all(np.isfinite(jac.data)) and np.all(np.isfinite(column))
            if not (math.isfinite(size) and finite):
                return None
            if size <= settings.tolerance:
                a = scipy.sparse.hstack(
                    (jac, scipy.sparse.csr_matrix(column[:, None])), format="csr"
                )
                return y, a, data, iteration
            if iteration == settings.max_iterations:
                return None
            last = 0.0 if fixed_lambda else -float(tangent @ (y - y0))
            dy = _bordered(jac, column, row, corner, -rs, last)
            if dy is None or not np.all(np.isfinite(dy)):
                return None
            y = y + dy
        return None


def _scaled(jacobian: Any, u_scale: FloatArray) -> Any:
    """diag(1 / u_scale) @ jacobian @ diag(u_scale) as a CSR matrix (the pattern kept)."""
    import scipy.sparse

    jac = scipy.sparse.csr_matrix(jacobian, dtype=np.float64, copy=True)
    rows = np.repeat(np.arange(jac.shape[0]), np.diff(jac.indptr))
    jac.data *= u_scale[jac.indices] / u_scale[rows]
    return jac


def _bordered(
    jac: Any, column: FloatArray, row: FloatArray, corner: float, rhs: FloatArray, last: float
) -> FloatArray | None:
    """Solve [[jac, column], [row^T, corner]] dy = [rhs; last]; None if singular.

    Block elimination on the sparse LU of ``jac`` alone (its column ordering reused along
    the branch: :mod:`clearjoint.bordered`); where ``jac`` is exactly singular, a direct
    sparse LU of the whole bordered matrix, as before issue 25.
    """
    import scipy.sparse
    import scipy.sparse.linalg

    try:
        return bordered_solve(jac, column, row, corner, rhs, last)
    except RuntimeError:
        pass
    matrix = scipy.sparse.vstack(
        (
            scipy.sparse.hstack((jac, scipy.sparse.csr_matrix(column[:, None]))),
            scipy.sparse.csr_matrix(np.append(row, corner)[None, :]),
        ),
        format="csc",
    )
    try:
        return np.asarray(
            scipy.sparse.linalg.splu(matrix).solve(np.append(rhs, last)), dtype=np.float64
        )
    except RuntimeError:  # "Factor is exactly singular"
        return None
