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

from clearjoint.harmonic.aft import Basis
from clearjoint.harmonic.system import LinearSystem

FloatArray = NDArray[np.float64]

#: Converged when max abs(R) / (k_ref x_scale) is below this.
TOLERANCE = 1e-11

#: Newton's linear solves use a sparse LU (scipy's splu) above this many unknowns. A
#: structure's HB Jacobian holds N x N blocks only where D or a joint couples two
#: harmonics, a few % of its entries for the mast; below this size the dense LU is faster
#: (``python benchmarks/bench_harmonic.py --mast`` times both).
SPARSE_ABOVE = 400


def linear_solve(jacobian: FloatArray, rhs: FloatArray) -> FloatArray:
    """Solve jacobian x = rhs: dense LU, or sparse LU above :data:`SPARSE_ABOVE` unknowns.

    A singular matrix falls back to least squares (dense) in both cases.
    """
    if jacobian.shape[0] > SPARSE_ABOVE:
        import scipy.sparse
        import scipy.sparse.linalg

        try:
            lu = scipy.sparse.linalg.splu(scipy.sparse.csc_matrix(jacobian))
            x = lu.solve(rhs)
            if np.all(np.isfinite(x)):
                return np.asarray(x, dtype=np.float64)
        except RuntimeError:  # "Factor is exactly singular"
            pass
    else:
        try:
            return np.asarray(np.linalg.solve(jacobian, rhs), dtype=np.float64)
        except np.linalg.LinAlgError:
            pass
    return np.asarray(np.linalg.lstsq(jacobian, rhs, rcond=None)[0], dtype=np.float64)


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
    function: Callable[[FloatArray], tuple[FloatArray, FloatArray]],
    q0: FloatArray,
    scale: float,
    *,
    max_iterations: int = 80,
    residual: Callable[[FloatArray], FloatArray] | None = None,
) -> tuple[FloatArray, int] | None:
    """Damped Newton on a dimensionless residual: ``function(q) -> (R, dR/dq)``.

    Steps are halved (up to 12 times) until max abs(R) falls; ``scale`` (m) makes q
    dimensionless in the convergence test. ``residual(q) -> R``, if given, is used
    for the halved trial steps (no Jacobian needed there). Returns (q, iterations)
    or None.
    """
    q = q0.copy()
    r, jac = function(q)
    size = float(np.max(np.abs(r)))
    for iteration in range(max_iterations):
        if not np.isfinite(size):
            return None
        if size <= TOLERANCE * scale:
            return q, iteration
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
    return (q, max_iterations) if size <= TOLERANCE * scale else None


class SparseResidual:
    """A continuation residual whose arclength corrector solves its bordered systems sparse.

    :func:`clearjoint.continuation.continue_branch` hands the correction to a
    residual's ``corrector`` method when ``ContinuationSettings.chord_parameter`` is
    set. This one runs the same Newton iteration as the continuation's own corrector
    (rows scaled by the unknowns' sizes, converged when every scaled residual is below
    the tolerance) but factors the bordered matrix [[dR/du, dR/dlam], [t^T or e_lam]]
    by a sparse LU (scipy's splu) instead of a dense solve: a structure's HB Jacobian
    is mostly zero blocks.

    Parameters
    ----------
    function : callable
        function(u, lam) -> (R (d,), dR/du (d, d), dR/dlam (d,), data), as
        :data:`clearjoint.continuation.Residual`.
    """

    def __init__(
        self,
        function: Callable[[FloatArray, float], tuple[FloatArray, FloatArray, FloatArray, object]],
    ) -> None:
        self.function = function

    def __call__(
        self, u: FloatArray, lam: float, want_lambda: bool = True
    ) -> tuple[FloatArray, FloatArray, FloatArray, object]:
        """R, dR/du, dR/dlam and the data at (u, lam) (``want_lambda`` is accepted, unused)."""
        return self.function(u, lam)

    def corrector(
        self,
        y0: FloatArray,
        tangent: FloatArray,
        scale: FloatArray,
        settings: Any,
        fixed_lambda: bool,
    ) -> tuple[FloatArray, FloatArray, object, int] | None:
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
            (y (d + 1,), the scaled [dR/du, dR/dlam] (d, d + 1), data, iterations).
        """
        import scipy.sparse
        import scipy.sparse.linalg

        from clearjoint.errors import ClearjointError

        y = y0.copy()
        d = y.size - 1
        u_scale = scale[:d]
        border = np.zeros(d + 1)
        border[d] = 1.0
        last_row = border if fixed_lambda else tangent
        for iteration in range(settings.max_iterations + 1):
            try:
                r, jac_u, r_lam, data = self.function(y[:d] * u_scale, float(y[d] * scale[d]))
            except ClearjointError:
                return None
            a = np.empty((d, d + 1))
            a[:, :d] = jac_u * (u_scale / u_scale[:, None])
            a[:, d] = r_lam * (scale[d] / u_scale)
            rs = r / u_scale
            size = float(np.max(np.abs(rs)))
            if not math.isfinite(size) or not np.all(np.isfinite(a)):
                return None
            if size <= settings.tolerance:
                return y, a, data, iteration
            if iteration == settings.max_iterations:
                return None
            rhs = np.empty(d + 1)
            rhs[:d] = -rs
            rhs[d] = 0.0 if fixed_lambda else -float(tangent @ (y - y0))
            matrix = scipy.sparse.vstack(
                (scipy.sparse.csr_matrix(a), scipy.sparse.csr_matrix(last_row[None, :]))
            ).tocsc()
            try:
                dy = scipy.sparse.linalg.splu(matrix).solve(rhs)
            except RuntimeError:  # "Factor is exactly singular"
                return None
            if not np.all(np.isfinite(dy)):
                return None
            y = y + dy
        return None
