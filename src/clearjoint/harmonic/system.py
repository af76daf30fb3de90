"""A joint or a structure as harmonic balance sees it: linear matrices plus joint laws.

MODEL.md 5.2-5.3. Harmonic balance needs

    M u'' + C u' + K u + sum_j b_j f_j(b_j^T u) = F sin(w t)

with f_j the piecewise-linear law of section 0 (k0, k_c, k_t, g_c, g_t). A
:class:`~clearjoint.Joint` is the one-DOF case (M = m, K = 0, b = 1, the whole
restoring force in the law, C = c_v from the damping ratio); a
:class:`~clearjoint.structure.Structure` gives its matrices, its joint directions and
each joint's law in series with its member.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.sparse
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.errors import ClearjointError, ParameterError, ParameterTypeError
from clearjoint.joint import Friction, Joint, Losses, checked_losses
from clearjoint.laws import clearance
from clearjoint.system import VibrationSystem, as_system, force_amplitudes

FloatArray = NDArray[np.float64]


class HarmonicError(ClearjointError, ValueError):
    """Harmonic balance cannot be set up or solved as asked (the message says what to change)."""


@dataclass(frozen=True)
class LinearSystem:
    """The matrices and joint laws of one system, in SI, dense.

    Attributes
    ----------
    mass, damping, stiffness : (N, N) ndarray
        M (kg), C (N s/m), K (N/m) of the linear part (K excludes the joints' laws).
    directions : (n_j, N) ndarray
        Row j is b_j: delta_j = b_j . u.
    k0, k_c, k_t, g_c, g_t : (n_j,) ndarray
        Each joint's free-play stiffness, contact stiffnesses (N/m) and gap edges (m).
    dof_names : list of str
    is_joint : bool
        True for a single :class:`Joint` (one DOF, its x).
    source : Joint or Structure
    friction_force : (n_j,) ndarray, optional
        Coulomb force mu_s P of each joint, N, regularised as mu_s P tanh(v / v_eps).
    friction_speed : float
        The regularisation speed v_eps, m/s.
    """

    mass: FloatArray
    damping: FloatArray
    stiffness: FloatArray
    directions: FloatArray
    k0: FloatArray
    k_c: FloatArray
    k_t: FloatArray
    g_c: FloatArray
    g_t: FloatArray
    dof_names: list[str]
    is_joint: bool
    source: Any
    friction_force: FloatArray | None = None
    friction_speed: float = 0.0

    @property
    def n_dof(self) -> int:
        """N, the number of degrees of freedom."""
        return int(self.mass.shape[0])

    @property
    def reference_stiffness(self) -> float:
        """A typical stiffness (N/m) to make residuals dimensionless: the largest closed one."""
        k_closed = np.diag(self.stiffness) + (
            (self.k0 + np.maximum(self.k_c, self.k_t)) @ self.directions**2
        )
        return float(max(np.max(np.abs(k_closed)), 1e-300))

    def closed_stiffness(self) -> FloatArray:
        """K plus every joint in compression contact (its tangent k0 + k_c), N/m."""
        b = self.directions
        return np.asarray(self.stiffness + (b.T * (self.k0 + self.k_c)) @ b, dtype=np.float64)

    def open_stiffness(self) -> FloatArray:
        """K plus every joint in free-play (its tangent k0), N/m."""
        b = self.directions
        return np.asarray(self.stiffness + (b.T * self.k0) @ b, dtype=np.float64)

    def joint_forces(self, delta: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Return f_j(delta) (N) and df_j/d delta (N/m) for samples ``delta`` (N_t, n_j).

        MODEL.md sec. 0: :func:`clearjoint.laws.clearance.forces_and_tangents`.
        """
        return clearance.forces_and_tangents(
            np.ascontiguousarray(delta), self.k0, self.k_c, self.k_t, self.g_c, self.g_t
        )

    def friction_forces(self, speed: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Return mu_s P tanh(v / v_eps) (N) and its derivative in v (N s/m), samples (N_t, n_j)."""
        assert self.friction_force is not None
        ratio = np.tanh(speed / self.friction_speed)
        return (
            self.friction_force * ratio,
            (self.friction_force / self.friction_speed) * (1.0 - ratio * ratio),
        )


def _refuse_losses(
    friction: Friction | None, restitution: float, where: str, *, allow_friction: bool = False
) -> None:
    if friction is not None and friction.force > 0.0 and friction.region != "everywhere":
        raise HarmonicError(
            f"Coulomb friction over the free-play stroke only ({where}) is not carried by "
            "clearjoint.harmonic; use clearjoint.periodic, or region='everywhere'"
        )
    if friction is not None and friction.force > 0.0 and not allow_friction:
        raise HarmonicError(
            f"Coulomb friction ({where}) is not carried by clearjoint.harmonic; "
            "use clearjoint.periodic (exact orbits with stick-slip) or set friction=None"
        )
    if restitution != 1.0:
        raise HarmonicError(
            f"restitution {restitution!r} ({where}) is an impact event that harmonic balance "
            "cannot carry; use clearjoint.periodic.frequency_response for exact orbits with "
            "impacts, or set restitution=1"
        )


def _refuse_system_losses(system: VibrationSystem) -> None:
    """Refuse a joint's friction over the free-play stroke only, or impacts (``system.losses``).

    Friction over the whole path (region "everywhere") is carried, regularised; a
    structure's member holds it only when it is rigid (:meth:`ClearanceJoint.in_series`).
    """
    for j, loss in enumerate(system.losses):
        where = _joint_name(system, j)
        rubs = loss.friction is not None and loss.friction.force > 0.0
        if rubs and loss.friction is not None and loss.friction.region != "everywhere":
            raise HarmonicError(
                f"Coulomb friction over the free-play stroke only ({where}) is "
                "not carried by clearjoint.harmonic; set region='everywhere' (friction over the "
                "whole path, carried regularised) or friction=None, or study that joint alone "
                "with clearjoint.periodic (exact stick-slip)"
            )
        if loss.restitution != 1.0:
            raise HarmonicError(
                f"restitution {loss.restitution!r} ({where}) is an impact event "
                "that harmonic balance cannot carry; use clearjoint.structure.frequency_response "
                "(exact shooting, impacts carried) or time_response, or set restitution=1"
            )


def _joint_name(system: VibrationSystem, j: int) -> str:
    """How a message names joint ``j``: by its member for a structure, else by index."""
    members = getattr(system.source, "joint_members", None)
    return f"joint of member {members[j]}" if members is not None else f"joint {j}"


def from_joint(
    joint: Joint, losses: Losses | None = None, friction_speed: float = 0.0
) -> LinearSystem:
    """The one-DOF system of a :class:`Joint` with viscous damping c_v = 2 zeta sqrt(m k_c):
    :func:`from_system` of ``VibrationSystem.from_joint(joint, losses)``, a Joint's.

    ``losses`` (default none) give zeta and the friction. Coulomb friction (region
    "everywhere") is regularised as mu_s P tanh(v / v_eps), v_eps = ``friction_speed``
    (m/s, > 0 when there is friction); restitution below 1 is refused. The pin's
    contact friction, which the exact solvers evaluate along the cycle without feedback
    on the motion (MODEL.md sec. 2), does not change the harmonic-balance orbit.
    """
    losses = checked_losses(losses)
    _refuse_losses(losses.friction, losses.restitution, "on the joint", allow_friction=True)
    if losses.friction is not None and losses.friction.force > 0.0:
        friction_speed = _checks.positive("friction_regularization", friction_speed, unit="m/s")
    made = from_system(VibrationSystem.from_joint(joint, losses), friction_speed)
    return replace(made, is_joint=True, source=joint)


def from_structure(structure: Any, friction_speed: float = 0.0) -> LinearSystem:
    """The system of a :class:`~clearjoint.structure.Structure`: :func:`from_system` of its
    ``to_system()``."""
    return from_system(structure.to_system(), friction_speed)


def from_system(system: VibrationSystem, friction_speed: float = 0.0) -> LinearSystem:
    """The harmonic-balance view of a :class:`~clearjoint.system.VibrationSystem` (dense).

    MODEL.md 5.2. Coulomb friction of a joint over its whole path
    (``system.friction_force()``) is carried as mu_s P tanh(v_j / v_eps) on its relative
    speed v_j = b_j . u', v_eps = ``friction_speed`` (m/s, > 0 when some joint has
    friction); joints without friction get a friction force of 0. Friction over the
    free-play stroke only and restitution below 1 (``system.losses``) are refused.
    """
    _refuse_system_losses(system)
    rub = system.friction_force()
    forces = None
    if np.any(rub > 0.0):
        if not friction_speed > 0.0:  # a caller that gave no regularisation speed
            where = _joint_name(system, int(np.argmax(rub > 0.0)))
            raise HarmonicError(
                f"Coulomb friction in the {where} needs a regularisation "
                f"speed v_eps > 0 (got {friction_speed!r} m/s); pass friction_regularization "
                "or build through frequency_response / nonlinear_modes, which set it"
            )
        forces = rub
        friction_speed = _checks.positive("friction_regularization", friction_speed, unit="m/s")
    k0, k_c, k_t, g_c, g_t = system.law_arrays()
    return LinearSystem(
        mass=_dense(system.mass),
        damping=_dense(system.damping),
        stiffness=_dense(system.stiffness),
        directions=np.asarray(system.directions, dtype=np.float64),
        k0=k0,
        k_c=k_c,
        k_t=k_t,
        g_c=g_c,
        g_t=g_t,
        dof_names=list(system.dof_names),
        is_joint=False,
        source=system.source if system.source is not None else system,
        friction_force=forces,
        friction_speed=float(friction_speed),
    )


def _dense(matrix: Any) -> FloatArray:
    """``matrix`` as a dense float64 array (sparse ones expanded)."""
    dense = matrix.toarray() if scipy.sparse.issparse(matrix) else matrix
    return np.asarray(dense, dtype=np.float64)


def build(system: Any, losses: Losses | None, friction_speed: float = 0.0) -> LinearSystem:
    """A :class:`LinearSystem` from a Joint (with its ``losses``), a Structure or a
    VibrationSystem (which carry their own: ``losses`` must then be None).

    A Structure goes through ``to_system()``; a system built from a Joint
    (``VibrationSystem.from_joint``) stays a Joint's.
    """
    if isinstance(system, Joint):
        return from_joint(system, losses, friction_speed)
    from clearjoint.structure.model import Structure

    if isinstance(system, Structure | VibrationSystem):
        if losses is not None:
            raise ParameterError(
                "losses apply to a Joint; a "
                f"{type(system).__name__} carries its own damping (Member.damping, rayleigh, "
                "or its C) and joint losses"
            )
        return from_system(as_system(system), friction_speed)
    raise ParameterTypeError(
        "system must be a clearjoint.Joint, a clearjoint.structure.Structure or a "
        f"clearjoint.system.VibrationSystem, got {system!r}"
    )


def force_vector(system: LinearSystem, force: ArrayLike, name: str = "force") -> FloatArray:
    """The force amplitudes per DOF (N): a number for a Joint (or any one-DOF system), an (N,)
    array for a Structure."""
    if system.is_joint:
        return np.array([_checks.positive(name, force, unit="N")])
    f = force_amplitudes(force, system.dof_names, name)
    if not np.any(f != 0.0):
        raise ParameterError(f"{name} must not be all zero (N)")
    return f


def scale_length(system: LinearSystem) -> float:
    """A typical length (m): the largest clearance, or 1 um if there is none."""
    gaps = system.g_c + system.g_t
    return float(max(np.max(gaps, initial=0.0), 1e-6)) if gaps.size else 1e-6


def friction_speed(system: Any, omega: float, given: float | None) -> float:
    """The regularisation speed v_eps (m/s): ``given``, or 1e-3 * omega * c.

    c is a Joint's clearance, or for a Structure the largest clearance of its joints
    with friction (1 um at least); 0 for a Structure without friction.
    """
    if given is not None:
        return _checks.positive("friction_regularization", given, unit="m/s")
    if isinstance(system, Joint):
        return 1e-3 * omega * max(system.clearance, 1e-6)
    if isinstance(system, VibrationSystem):
        pairs = list(zip(system.laws, system.losses, strict=True))
        gaps = [
            float(law.clearance)
            for law, loss in pairs
            if loss.friction is not None and loss.friction.force > 0.0
        ]
    else:
        laws = getattr(system, "joint_laws", ())
        gaps = [
            float(law.clearance)
            for law in laws
            if law.friction is not None and law.friction.force > 0.0
        ]
    if gaps:
        return 1e-3 * omega * max(max(gaps), 1e-6)
    return 0.0


#: The largest array a harmonic-balance solve may allocate, bytes (2 GiB).
MEMORY_BOUND = 2**31


def check_size(n_dof: int, harmonics: int, samples: Callable[[int], int]) -> None:
    """Refuse an H whose largest array would exceed :data:`MEMORY_BOUND`.

    The two largest arrays are the dense Jacobian, (N (2H + 1) + 2)^2 floats, and the
    AFT basis, N_t (2H + 1) floats (8 bytes each); ``samples(H)`` is N_t for that H
    (the user's, or the default that grows with H).

    Raises
    ------
    HarmonicError
        Naming the size, the bound and the largest H that fits.
    """

    def largest(h: int) -> float:
        return 8.0 * max((n_dof * (2 * h + 1) + 2) ** 2, samples(h) * (2 * h + 1))

    need = largest(harmonics)
    if need <= MEMORY_BOUND:
        return
    fits, above = 0, harmonics  # largest(fits) fits (0: nothing does), largest(above) not
    while above - fits > 1:
        middle = (fits + above) // 2
        fits, above = (middle, above) if largest(middle) <= MEMORY_BOUND else (fits, middle)
    raise HarmonicError(
        f"harmonics {harmonics} with {n_dof} DOF(s) and {samples(harmonics)} samples needs an "
        "array of "
        f"{need / 2**30:.3g} GiB, above the {MEMORY_BOUND / 2**30:.0f} GiB bound: use fewer "
        f"harmonics (H = 7 to 31 is usual for joints; H <= {fits} fits here)"
    )
