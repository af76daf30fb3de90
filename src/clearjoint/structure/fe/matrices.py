"""A finite-element model given as matrices, with clearance joints between its DOFs.

MODEL.md 5.2: the model's own M, C, K are the linear part of

    M u'' + C u' + K u + sum_j b_j f_j(b_j . u) = F sin(w t)

and each joint adds a law f_j of delta_j = b_j . u. A joint between two DOFs a and b
(``(a, b, law)``) has delta = u_a - u_b (b = None: u_a, against the ground); a joint
between two nodes along a unit direction n (``(a_dofs, b_dofs, n, law)``, a_dofs and
b_dofs the nodes' translation DOFs) has delta = n . (u_a - u_b). delta is positive in
compression, as for :class:`~clearjoint.Joint`: a joint closes in compression at
delta >= g_c. K is the model without the joints (a hinge is two coincident nodes,
unconnected but by the joint and whatever else the engineer put between them).

:func:`from_matrices` checks the matrices and the joints and returns the
:class:`~clearjoint.system.VibrationSystem` every solver takes; its ``source`` is a
:class:`MatrixModel` that keeps the DOF names, the node coordinates and the joints'
DOFs (what :func:`~clearjoint.structure.reduce` needs to pick the boundary).
"""

from __future__ import annotations

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
from clearjoint.joint import ClearanceJoint
from clearjoint.system import Matrix, VibrationSystem, VibrationSystemError

FloatArray = NDArray[np.float64]

#: Up to this many DOFs the definiteness checks are dense eigenvalue checks; above, the
#: matrices are checked symmetric with a non-negative diagonal and the definiteness is
#: left to the sparse eigen-solvers (modes, reduction), which refuse a negative eigenvalue.
DENSE_CHECK_UP_TO = 2000

#: Relative tolerances of the checks: symmetry (to the largest entry) and
#: semi-definiteness (the smallest eigenvalue to the largest).
SYMMETRY_TOLERANCE = 1e-10
DEFINITE_TOLERANCE = 1e-10


class FEModelError(VibrationSystemError):
    """A finite-element model that cannot be used as given (the message names the item)."""


@dataclass(frozen=True, eq=False)
class MatrixModel:
    """What a system built from matrices was made from: names, coordinates, joint DOFs.

    Attributes
    ----------
    dof_names : tuple of str
        One name per DOF of the full model.
    coordinates : (N, 3) ndarray or None
        The position of each DOF's node, m (None when not given).
    joint_dofs : tuple of tuple of int
        The DOF indices each joint acts on (its nonzero entries of b_j).
    """

    dof_names: tuple[str, ...]
    coordinates: FloatArray | None = field(default=None, repr=False)
    joint_dofs: tuple[tuple[int, ...], ...] = ()

    def __repr__(self) -> str:
        return f"MatrixModel({len(self.dof_names)} DOF, {len(self.joint_dofs)} joints)"


def dof_index(what: str, value: Any, names: Sequence[str]) -> int:
    """The index of a DOF given by index (0-based) or by name; one clear line if none.

    Raises
    ------
    FEModelError
        No such DOF.
    ParameterTypeError
        Neither an integer nor a string.
    """
    n = len(names)
    if isinstance(value, str):
        try:
            return list(names).index(value)
        except ValueError:
            shown = ", ".join(names[:6]) + (", ..." if n > 6 else "")
            raise FEModelError(
                f"{what} names DOF {value!r}, which does not exist (the DOFs are {shown})"
            ) from None
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ParameterTypeError(f"{what} must be a DOF index or name, got {value!r}")
    if not 0 <= int(value) < n:
        raise FEModelError(
            f"{what} names DOF {int(value)}, which does not exist (DOF indices are 0 to {n - 1})"
        )
    return int(value)


def _joint_row(index: int, spec: Any, names: Sequence[str]) -> tuple[FloatArray, ClearanceJoint]:
    """Row b_j and law of one joint spec: (a, b, law) or (a_dofs, b_dofs, direction, law)."""
    what = f"joints[{index}]"
    if not isinstance(spec, tuple | list) or len(spec) not in (3, 4):
        raise ParameterTypeError(
            f"{what} must be (a, b, law) or (a_dofs, b_dofs, direction, law), got {spec!r}"
        )
    law = spec[-1]
    if not isinstance(law, ClearanceJoint):
        raise ParameterTypeError(
            f"{what}: its law must be a clearjoint.ClearanceJoint, got {law!r}"
        )
    row = np.zeros(len(names))
    if len(spec) == 3:
        a, b = spec[0], spec[1]
        row[dof_index(f"{what} a", a, names)] += 1.0
        if b is not None:
            j = dof_index(f"{what} b", b, names)
            if row[j] != 0.0:
                raise FEModelError(f"{what} joins DOF {names[j]!r} to itself; give two DOFs")
            row[j] -= 1.0
        return row, law
    a_dofs, b_dofs, direction = spec[0], spec[1], spec[2]
    try:
        n = np.asarray(direction, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterTypeError(f"{what}: direction must be numbers, got {direction!r}") from None
    a_list = list(a_dofs) if isinstance(a_dofs, tuple | list) else None
    if a_list is None or len(a_list) != n.size or n.ndim != 1 or not 1 <= n.size <= 3:
        raise FEModelError(
            f"{what}: give the node's translation DOFs (up to 3) and a direction of as many "
            f"components, got {a_dofs!r} and {direction!r}"
        )
    if not np.all(np.isfinite(n)) or abs(float(np.linalg.norm(n)) - 1.0) > 1e-9:
        raise FEModelError(
            f"{what}: direction {n.tolist()} must be a unit vector (its norm is "
            f"{float(np.linalg.norm(n))!r}); divide it by its length"
        )
    for side, dofs, sign in (("a_dofs", a_list, 1.0), ("b_dofs", b_dofs, -1.0)):
        if dofs is None and side == "b_dofs":
            continue
        dofs = list(dofs) if isinstance(dofs, tuple | list) else None
        if dofs is None or len(dofs) != n.size:
            raise FEModelError(f"{what}: {side} must list {n.size} DOFs, got {spec[1]!r}")
        for k, dof in enumerate(dofs):
            j = dof_index(f"{what} {side}[{k}]", dof, names)
            if side == "b_dofs" and row[j] != 0.0 and n[k] != 0.0:
                raise FEModelError(f"{what} joins DOF {names[j]!r} to itself; give two nodes")
            row[j] += sign * n[k]
    return row, law


def _symmetric(name: str, m: Matrix) -> None:
    top = float(abs(m).max()) if scipy.sparse.issparse(m) else float(np.max(np.abs(m), initial=0.0))
    gap = abs(m - m.T)
    worst = float(gap.max()) if scipy.sparse.issparse(gap) else float(np.max(gap, initial=0.0))
    if worst > SYMMETRY_TOLERANCE * max(top, 1e-300):
        raise FEModelError(
            f"{name} is not symmetric (largest |A - A^T| is {worst:.3g}, {worst / top:.2g} of its "
            "largest entry); give the full symmetric matrix, not one triangle"
        )


def _semidefinite(name: str, m: Matrix, *, definite: bool) -> None:
    """Refuse a negative (or, if ``definite``, a zero) eigenvalue; dense models only."""
    diagonal = np.asarray(m.diagonal(), dtype=np.float64)
    if np.any(diagonal < 0.0):
        j = int(np.argmin(diagonal))
        raise FEModelError(
            f"{name} has a negative diagonal entry ({diagonal[j]:.3g} at DOF {j}): it cannot be "
            "positive semi-definite; check the sign convention of the file"
        )
    n = diagonal.size
    off = m - scipy.sparse.diags(diagonal) if scipy.sparse.issparse(m) else m - np.diag(diagonal)
    lumped = not (off.count_nonzero() if scipy.sparse.issparse(off) else np.count_nonzero(off))
    kind = "positive definite" if definite else "positive semi-definite"
    if lumped:  # a diagonal matrix: its eigenvalues are its diagonal
        if definite and np.any(diagonal <= 0.0):
            j = int(np.argmin(diagonal))
            raise FEModelError(f"{name} is not {kind}: DOF {j} has {diagonal[j]!r} on the diagonal")
        return
    if n > DENSE_CHECK_UP_TO:
        return
    dense = m.toarray() if scipy.sparse.issparse(m) else m
    dense = 0.5 * (dense + dense.T)
    # Cholesky of A shifted by the tolerance (down for definite, up for semi-definite)
    # succeeds exactly when no eigenvalue is below it; the eigenvalue only for the message
    top = max(float(np.max(np.sum(np.abs(dense), axis=1))), 1e-300)  # >= the largest
    shift = (-1.0 if definite else 1.0) * DEFINITE_TOLERANCE * top
    try:
        scipy.linalg.cholesky(dense + shift * np.eye(n), lower=True, check_finite=False)
    except np.linalg.LinAlgError:
        low = float(scipy.linalg.eigvalsh(dense, subset_by_index=(0, 0))[0])
        raise FEModelError(
            f"{name} is not {kind} (smallest eigenvalue {low:.3g}, largest at most {top:.3g})"
        ) from None


def from_matrices(
    mass: Any,
    stiffness: Any,
    *,
    damping: Any = None,
    rayleigh: tuple[Any, Any] | None = None,
    joints: Sequence[Any],
    dof_names: Sequence[str] | None = None,
    coordinates: ArrayLike | None = None,
) -> VibrationSystem:
    """Return the vibration system of a finite-element model given as matrices.

    MODEL.md 5.2 (module docstring): M, C, K the model's linear part, each joint a law
    of delta_j = b_j . u between two DOFs or two nodes.

    Parameters
    ----------
    mass, stiffness : (N, N) ndarray or scipy.sparse matrix
        M in kg (kg m^2 on rotations), K in N/m (N m/rad, ...), the model without its
        clearance joints. Sparse stays sparse. A lumped (diagonal) M runs every solver; a
        consistent one runs ``system_modes`` and :func:`~clearjoint.structure.reduce`,
        whose reduced system runs every solver.
    damping : (N, N) matrix, optional
        C in N s/m. Default none.
    rayleigh : (alpha, beta), optional
        C += alpha M + beta K_closed (1/s, s; K_closed with every joint in compression
        contact, as for a :class:`~clearjoint.structure.Structure`); numbers or unit text.
    joints : sequence
        Each ``(a, b, law)``: DOFs a and b (index or name; b None for the ground),
        delta = u_a - u_b; or ``(a_dofs, b_dofs, direction, law)``: two nodes'
        translation DOFs and a unit direction n, delta = n . (u_a - u_b). ``law`` is a
        :class:`~clearjoint.ClearanceJoint`.
    dof_names : sequence of str, optional
        One distinct name per DOF; default "u1", "u2", ...
    coordinates : (N, 3) array_like, optional
        The position of each DOF's node, m (kept for drawing and examples).

    Returns
    -------
    VibrationSystem
        Its ``source`` is a :class:`MatrixModel`.

    Raises
    ------
    FEModelError
        A matrix not square, of another size, not symmetric, not finite; M not positive
        definite or K with the joints closed not positive semi-definite (dense checks up
        to ``DENSE_CHECK_UP_TO`` DOFs, a negative diagonal above); a joint on a DOF that
        does not exist, a direction that is not a unit vector; names not one per DOF.
    """
    shape = mass.shape if scipy.sparse.issparse(mass) else np.shape(mass)
    if len(shape) != 2 or shape[0] != shape[1] or shape[0] == 0:
        raise FEModelError(f"mass must be a square (N, N) matrix, got shape {tuple(shape)}")
    n = int(shape[0])
    names = tuple(f"u{i + 1}" for i in range(n))
    if dof_names is not None:
        names = tuple(str(s) for s in dof_names)
        if len(names) != n or len(set(names)) != n:
            raise FEModelError(
                f"dof_names must be {n} distinct names, one per DOF, got {len(names)} "
                f"({len(set(names))} distinct)"
            )
    if isinstance(joints, ClearanceJoint) or not isinstance(joints, Sequence):
        raise ParameterTypeError(
            f"joints must be a list of (a, b, law) or (a_dofs, b_dofs, direction, law), got "
            f"{joints!r}"
        )
    rows, laws = [], []
    for index, spec in enumerate(joints):
        row, law = _joint_row(index, spec, names)
        rows.append(row)
        laws.append(law)
    zero = scipy.sparse.csr_matrix((n, n)) if scipy.sparse.issparse(stiffness) else np.zeros((n, n))
    system = VibrationSystem(
        mass=mass,
        damping=zero if damping is None else damping,
        stiffness=stiffness,
        directions=np.array(rows).reshape(len(rows), n),
        laws=tuple(laws),
        dof_names=names,
    )
    for name in ("mass", "stiffness", "damping"):
        _symmetric(name, getattr(system, name))
    # a DOF without mass (a rotation of a lumped-mass model) is allowed: reduce() takes it
    massless = bool(np.any(np.asarray(system.mass.diagonal()) == 0.0))
    _semidefinite("the mass matrix", system.mass, definite=not massless)
    closed = system.closed_stiffness()
    _semidefinite("the stiffness with the joints closed", closed, definite=False)
    c = system.damping
    if damping is not None:
        _semidefinite("the damping matrix", c, definite=False)
    if rayleigh is not None:
        if not isinstance(rayleigh, tuple | list) or len(rayleigh) != 2:
            raise FEModelError(f"rayleigh must be (alpha, beta) in (1/s, s), got {rayleigh!r}")
        alpha = _checks.non_negative("rayleigh alpha", rayleigh[0], unit="1/s")
        beta = _checks.non_negative("rayleigh beta", rayleigh[1], unit="s")
        c = c + alpha * system.mass + beta * closed  # a sum of semi-definite matrices
    joint_dofs = tuple(tuple(int(i) for i in np.flatnonzero(row)) for row in system.directions)
    xyz = None
    if coordinates is not None:
        xyz = np.asarray(coordinates, dtype=np.float64)
        if xyz.ndim != 2 or xyz.shape[0] != n or not 1 <= xyz.shape[1] <= 3:
            raise FEModelError(
                f"coordinates must be (N, 3) = ({n}, 3), one node position per DOF, got "
                f"shape {xyz.shape}"
            )
    return VibrationSystem(
        mass=system.mass,
        damping=scipy.sparse.csr_matrix(c) if system.is_sparse else c,
        stiffness=system.stiffness,
        directions=system.directions,
        laws=system.laws,
        losses=system.losses,
        dof_names=names,
        source=MatrixModel(names, xyz, joint_dofs),
    )
