"""Craig-Bampton reduction of a finite-element model onto its joints (MODEL.md 5.2).

The DOFs split into the boundary B (every DOF a joint acts on, plus those kept: the
forced DOFs, the DOFs to watch) and the interior I. With the boundary held still, the
interior moves in its fixed-interface modes K_II phi = w^2 M_II phi; with the
interior static, it follows the boundary in the constraint modes -K_II^-1 K_IB. The
displacements are approximated as

    u = T q,    T = [[1, 0], [-K_II^-1 K_IB, Phi_m]]   (rows B then I)

with Phi_m the fixed-interface modes kept (up to a count or a cutoff frequency). The
joints act on boundary DOFs only, so b_j T = [b_j,B, 0]: the laws are untouched, and
K_II, K_IB are the same in every contact pattern. The reduced matrices are T^T M T,
T^T C T, T^T K T.

The solvers need a lumped mass, so the reduced coordinates are then changed once
more, to the reduced model's own closed-pattern modes: q = Psi y with
Psi^T (T^T M T) Psi = 1 and Psi^T (T^T K_closed T) Psi diagonal. The system
returned has M = 1 (exactly: this is its definition), K = Psi^T T^T K T Psi (the
linear part without the joints), C = Psi^T T^T C T Psi, b_j <- b_j T Psi. Its DOFs
"q1", "q2", ... are those modal coordinates; :meth:`ReducedSystem.expand` gives u back
on every DOF of the full model, :meth:`ReducedSystem.project_force` takes a force on
the full model's DOFs into the reduced ones, and :meth:`ReducedSystem.check` compares
the reduced model's closed and open modes with the full model's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.errors import ParameterTypeError
from clearjoint.structure.fe.matrices import FEModelError, dof_index
from clearjoint.system import Matrix, VibrationSystem, as_system, force_amplitudes

FloatArray = NDArray[np.float64]

#: Up to this many interior DOFs the fixed-interface modes are found by a dense eigh.
DENSE_INTERIOR_UP_TO = 200


def _csc(m: Matrix) -> scipy.sparse.csc_matrix:
    return scipy.sparse.csc_matrix(m, dtype=np.float64)


def pencil_modes(
    stiffness: Matrix, mass: Matrix, count: int, *, factor: Any = None
) -> tuple[FloatArray, FloatArray]:
    """The ``count`` lowest omega^2 (rad^2/s^2) and M-normalised shapes of K phi = w^2 M phi.

    Dense ``eigh`` for small matrices; else ``eigsh`` in shift-invert mode about 0
    (``factor`` a solve of K, else K's sparse LU), or just below 0 where K is exactly
    singular (a mechanism of an open pattern, a free model). M may be consistent, and semi-definite
    in the sparse case (massless DOFs have infinite frequencies, never the lowest).

    Raises
    ------
    FEModelError
        A negative eigenvalue (K not positive semi-definite).
    """
    n = int(mass.shape[0])
    count = int(count)
    if n <= DENSE_INTERIOR_UP_TO or count >= n - 1:
        k = stiffness.toarray() if scipy.sparse.issparse(stiffness) else np.asarray(stiffness)
        m = mass.toarray() if scipy.sparse.issparse(mass) else np.asarray(mass)
        try:
            w2, shapes = scipy.linalg.eigh(k, m, subset_by_index=(0, min(count, n) - 1))
        except np.linalg.LinAlgError:
            raise FEModelError(
                "the mass matrix is singular on these DOFs (a DOF without mass?): give every "
                "DOF a mass or keep the massless ones out of the boundary"
            ) from None
    else:
        if factor is None:
            try:  # shift-invert about 0 where K is nonsingular (the most accurate low modes)
                factor = scipy.sparse.linalg.splu(_csc(stiffness)).solve
            except RuntimeError:  # exactly singular (a mechanism): just below 0 instead
                factor = None
        if factor is not None:
            op = scipy.sparse.linalg.LinearOperator((n, n), matvec=factor, dtype=np.float64)
            w2, shapes = scipy.sparse.linalg.eigsh(
                _csc(stiffness), k=count, M=_csc(mass), sigma=0.0, OPinv=op
            )
        else:
            d_m = np.asarray(mass.diagonal(), dtype=np.float64)
            d_k = np.asarray(stiffness.diagonal(), dtype=np.float64)
            heavy = d_m > 0.0
            shift = 1e-12 * float(np.max(d_k[heavy] / d_m[heavy], initial=1.0))
            w2, shapes = scipy.sparse.linalg.eigsh(
                _csc(stiffness), k=count, M=_csc(mass), sigma=-shift
            )
        order = np.argsort(w2)
        w2, shapes = w2[order], shapes[:, order]
    top = max(float(np.max(np.abs(w2), initial=0.0)), 1e-300)
    if w2.size and w2[0] < -1e-8 * top:
        raise FEModelError(
            f"the stiffness is not positive semi-definite (eigenvalue {w2[0]:.3g} rad^2/s^2): "
            "check the model's constraints and the sign of its matrices"
        )
    return np.clip(w2, 0.0, None), shapes


@dataclass(frozen=True)
class ReductionCheck:
    """The reduced model's natural frequencies against the full model's, closed and open.

    Attributes
    ----------
    full_closed_hz, reduced_closed_hz : (n,) ndarray
        Closed-pattern frequencies (every joint in compression contact), Hz.
    full_open_hz, reduced_open_hz : (n,) ndarray
        Open-pattern frequencies (every joint in free-play), Hz.
    """

    full_closed_hz: FloatArray
    reduced_closed_hz: FloatArray
    full_open_hz: FloatArray
    reduced_open_hz: FloatArray

    @staticmethod
    def _error(full: FloatArray, reduced: FloatArray) -> FloatArray:
        floor = 1e-6 * float(np.max(full, initial=0.0))  # a mechanism's 0 Hz: to the top
        return np.abs(reduced - full) / np.maximum(full, max(floor, 1e-300))

    @property
    def closed_error(self) -> FloatArray:
        """abs(f_reduced - f_full) / f_full per closed mode."""
        return self._error(self.full_closed_hz, self.reduced_closed_hz)

    @property
    def open_error(self) -> FloatArray:
        """abs(f_reduced - f_full) / f_full per open mode (0 Hz modes: to the highest)."""
        return self._error(self.full_open_hz, self.reduced_open_hz)

    @property
    def worst(self) -> float:
        """The largest relative error over both patterns."""
        return float(max(np.max(self.closed_error), np.max(self.open_error)))

    def __repr__(self) -> str:
        return (
            f"ReductionCheck({self.full_closed_hz.size} modes up to "
            f"{float(self.full_closed_hz[-1]):.4g} Hz closed, worst relative error "
            f"{float(np.max(self.closed_error)):.2g} closed, "
            f"{float(np.max(self.open_error)):.2g} open)"
        )

    def to_xarray(self) -> Any:
        """The check as an xarray Dataset (frequencies in Hz, relative errors) per mode."""
        import xarray as xr

        return xr.Dataset(
            {
                "full_closed": ("mode", self.full_closed_hz, {"units": "Hz"}),
                "reduced_closed": ("mode", self.reduced_closed_hz, {"units": "Hz"}),
                "full_open": ("mode", self.full_open_hz, {"units": "Hz"}),
                "reduced_open": ("mode", self.reduced_open_hz, {"units": "Hz"}),
                "closed_error": ("mode", self.closed_error),
                "open_error": ("mode", self.open_error),
            },
            coords={"mode": np.arange(1, self.full_closed_hz.size + 1)},
        )

    def plot(self, ax: Any = None) -> Any:
        """Draw the relative frequency errors per mode, closed and open; return the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        mode = np.arange(1, self.full_closed_hz.size + 1)
        floor = 1e-17  # exact agreement drawn at the bottom of the log axis
        ax.semilogy(mode, np.maximum(self.closed_error, floor), "o-", label="closed")
        ax.semilogy(mode, np.maximum(self.open_error, floor), "s--", label="open")
        ax.set_xlabel("mode")
        ax.set_ylabel("|f reduced - f full| / f full")
        ax.legend()
        return ax


@dataclass(frozen=True, eq=False)
class ReducedSystem(VibrationSystem):
    """A Craig-Bampton reduced :class:`~clearjoint.system.VibrationSystem` (module docstring).

    Every solver takes it (its M is the identity). Beyond a VibrationSystem's fields:

    Attributes
    ----------
    basis : (N_full, n) ndarray
        T Psi: u = basis @ y on the full model's DOFs.
    full : VibrationSystem
        The full model.
    boundary : tuple of int
        The full model's boundary DOFs (joints and ``keep``).
    interface_omega : (m,) ndarray
        The fixed-interface modes kept, rad/s.
    """

    basis: FloatArray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    full: VibrationSystem | None = field(default=None, repr=False)
    boundary: tuple[int, ...] = ()
    interface_omega: FloatArray = field(default_factory=lambda: np.zeros(0), repr=False)

    def expand(self, u: ArrayLike) -> FloatArray:
        """The full model's displacements (..., N_full) from reduced ones (..., n)."""
        y = np.asarray(u, dtype=np.float64)
        if y.shape[-1:] != (self.n_dof,):
            raise FEModelError(
                f"expand takes reduced coordinates ending in {self.n_dof} values, got shape "
                f"{y.shape}"
            )
        return np.asarray(y @ self.basis.T, dtype=np.float64)

    def project_force(self, force: ArrayLike | dict[str, float]) -> FloatArray:
        """The reduced force amplitudes basis^T F from F on the full model's DOFs, N.

        ``force`` is (N_full,) or a dict {DOF name: amplitude}. A force on an interior
        DOF that is not kept is projected too, but its local effect is approximated:
        keep the forced DOFs (``reduce(..., keep=...)``) for the exact static response.
        """
        full = self._full()
        if isinstance(force, dict):
            f = np.zeros(full.n_dof)
            for name, value in force.items():
                f[dof_index("force", name, full.dof_names)] += _checks.real_scalar(
                    f"force on {name}", value, unit="N"
                )
        else:
            f = force_amplitudes(force, full.dof_names)
        return np.asarray(self.basis.T @ f, dtype=np.float64)

    def check(self, count: int | None = None) -> ReductionCheck:
        """The reduced model's ``count`` lowest closed and open modes against the full model's.

        Default ``count``: the reduced modes up to the highest fixed-interface mode kept
        (at most 10). Sparse shift-invert on the full model.
        """
        full = self._full()
        if count is None:
            top = float(np.max(self.interface_omega, initial=0.0))
            w_red = np.sqrt(np.clip(np.diag(self.closed_stiffness()), 0.0, None))
            count = min(10, max(1, int(np.count_nonzero(w_red <= top))))
        if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= self.n_dof:
            raise ParameterTypeError(
                f"count must be an integer from 1 to {self.n_dof} (the reduced DOFs), got {count!r}"
            )
        hz = []
        for system in (full, self):
            for k in (system.closed_stiffness(), system.open_stiffness()):
                w2, _ = pencil_modes(k, system.mass, count)
                hz.append(np.sqrt(w2) / (2.0 * math.pi))
        return ReductionCheck(hz[0], hz[2], hz[1], hz[3])

    def _full(self) -> VibrationSystem:
        if self.full is None:
            raise FEModelError("this reduced system has no full model attached")
        return self.full

    def __repr__(self) -> str:
        n_full = self.basis.shape[0]
        return (
            f"ReducedSystem({self.n_dof} DOF from {n_full}: {len(self.boundary)} boundary, "
            f"{self.interface_omega.size} fixed-interface modes; {self.n_joints} joints)"
        )


def _interface_modes(
    k_ii: Matrix,
    m_ii: Matrix,
    factor: Any,
    modes: int | None,
    cutoff: float | None,
) -> tuple[FloatArray, FloatArray]:
    """The fixed-interface modes kept: the ``modes`` lowest, or those below ``cutoff`` rad/s."""
    n_i = int(k_ii.shape[0])
    if cutoff is None:
        assert modes is not None
        w2, shapes = pencil_modes(k_ii, m_ii, min(modes, n_i), factor=factor)
        return np.sqrt(w2), shapes
    limit = n_i if modes is None else min(modes, n_i)
    count = min(limit, 20)
    while True:
        w2, shapes = pencil_modes(k_ii, m_ii, count, factor=factor)
        if count >= limit or w2[-1] > cutoff**2:
            keep = w2 <= cutoff**2
            return np.sqrt(w2[keep]), shapes[:, keep]
        count = min(limit, 2 * count)


def reduce(
    structure: Any,
    *,
    modes: int | None = None,
    cutoff_hz: Any = None,
    keep: Sequence[int | str] = (),
) -> ReducedSystem:
    """Return the Craig-Bampton reduction of a structure onto its joints (module docstring).

    Parameters
    ----------
    structure : VibrationSystem, Structure, ...
        Anything :func:`~clearjoint.system.as_system` takes: typically
        :func:`~clearjoint.structure.from_matrices`'s system; M lumped or consistent,
        dense or sparse.
    modes : int, optional
        The number of fixed-interface modes kept (the lowest).
    cutoff_hz : float or str, optional
        Keep the fixed-interface modes up to this frequency, Hz ("300Hz"); with
        ``modes`` too, at most ``modes`` of them. Give one or both.
    keep : sequence of int or str
        Further boundary DOFs (index or name): the forced DOFs, the DOFs to watch.

    Returns
    -------
    ReducedSystem
        A VibrationSystem with M = 1 (every solver runs on it), ``expand``,
        ``project_force`` and ``check``.

    Raises
    ------
    FEModelError
        Neither ``modes`` nor ``cutoff_hz``; a ``keep`` DOF that does not exist; no
        interior DOF left; an interior free to move with the boundary held.
    """
    full = as_system(structure)
    if modes is None and cutoff_hz is None:
        raise FEModelError("give modes (a count) or cutoff_hz (a frequency) to keep")
    if modes is not None and (isinstance(modes, bool) or not isinstance(modes, int) or modes < 0):
        raise ParameterTypeError(f"modes must be a whole number >= 0, got {modes!r}")
    cutoff = None
    if cutoff_hz is not None:
        cutoff = 2.0 * math.pi * _checks.positive("cutoff_hz", cutoff_hz, unit="Hz")
    n = full.n_dof
    if isinstance(keep, str | int):
        keep = (keep,)
    boundary_set = {int(i) for i in np.flatnonzero(np.any(full.directions != 0.0, axis=0))}
    boundary_set |= {dof_index(f"keep[{k}]", dof, full.dof_names) for k, dof in enumerate(keep)}
    boundary = np.array(sorted(boundary_set), dtype=np.int64)
    interior = np.setdiff1d(np.arange(n), boundary)
    if interior.size == 0:
        raise FEModelError("every DOF is a boundary DOF: there is nothing to reduce")
    k_full, m_full = _csc(full.stiffness), _csc(full.mass)
    k_ii = k_full[interior][:, interior].tocsc()
    k_ib = k_full[interior][:, boundary]
    m_ii = m_full[interior][:, interior].tocsc()
    try:
        lu = scipy.sparse.linalg.splu(k_ii)
    except RuntimeError:
        raise FEModelError(
            "with the boundary DOFs held, the rest of the model can still move freely (K_II "
            "is singular): keep more DOFs on the boundary (keep=...), e.g. a node's every DOF"
        ) from None
    constraint = -lu.solve(k_ib.toarray())
    if not np.all(np.isfinite(constraint)):
        raise FEModelError(
            "with the boundary DOFs held, the rest of the model can still move freely (K_II "
            "is singular): keep more DOFs on the boundary (keep=...)"
        )
    if modes == 0 and cutoff is None:
        omega_i, phi_i = np.zeros(0), np.zeros((interior.size, 0))
    else:
        omega_i, phi_i = _interface_modes(k_ii, m_ii, lu.solve, modes, cutoff)
    n_b, n_m = boundary.size, omega_i.size
    t = np.zeros((n, n_b + n_m))
    t[boundary, np.arange(n_b)] = 1.0
    t[interior, :n_b] = constraint
    t[interior, n_b:] = phi_i

    def project(matrix: Matrix) -> FloatArray:
        p = t.T @ (matrix @ t)
        return np.asarray(0.5 * (p + p.T), dtype=np.float64)

    m_r, k_r, c_r = project(full.mass), project(full.stiffness), project(full.damping)
    k_closed_r = project(full.closed_stiffness())
    try:
        _, psi = scipy.linalg.eigh(k_closed_r, m_r)
    except np.linalg.LinAlgError:
        raise FEModelError(
            "the reduced mass matrix is singular: a boundary DOF without mass (a rotation of a "
            "lumped-mass model?); keep only DOFs with mass, or give them rotational inertia"
        ) from None
    basis = t @ psi
    names = tuple(f"q{i + 1}" for i in range(psi.shape[1]))
    return ReducedSystem(
        mass=np.eye(psi.shape[1]),
        damping=_symmetric(psi.T @ c_r @ psi),
        stiffness=_symmetric(psi.T @ k_r @ psi),
        directions=full.directions @ basis,
        laws=full.laws,
        losses=full.losses,
        dof_names=names,
        source=full.source,
        basis=basis,
        full=full,
        boundary=tuple(int(i) for i in boundary),
        interface_omega=omega_i,
    )


def _symmetric(a: FloatArray) -> FloatArray:
    return np.asarray(0.5 * (a + a.T), dtype=np.float64)
