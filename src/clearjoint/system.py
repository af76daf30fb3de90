"""The vibration system every solver takes: matrices, joint directions, laws and losses.

MODEL.md 5.2:

    M u'' + C u' + K u + sum_j b_j f_j(b_j . u) = F sin(w t)

u holds the N displacements (DOFs); M, C and K are the linear part (K without the
joints' laws: each law f_j carries its own free-play stiffness k0); row j of
``directions`` is b_j, so delta_j = b_j . u is joint j's relative displacement,
positive in compression; f_j is joint j's piecewise-linear law of MODEL.md section 0
(a :class:`~clearjoint.ClearanceJoint`, elastic only) and ``losses[j]`` its
dissipation (Coulomb friction, restitution, the pin for contact friction). In one
contact pattern s (each joint open, in compression or in tension) the restoring
force is K_s u - r_s with

    K_s = K + sum_j K_j,s b_j b_j^T,    r_s = sum_j r_j,s b_j

(K_j,s, r_j,s the law's stiffness and offset in its state).

A :class:`~clearjoint.Joint` is the one-DOF case (M = m, C = c_v from the damping
ratio, K = 0, b = 1, the whole restoring force in the law): :meth:`VibrationSystem.
from_joint`. A :class:`~clearjoint.structure.Structure` gives its own with
``Structure.to_system()``. :func:`as_system` takes either, or a system, so a solver
has one type to work on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, NamedTuple, TypeAlias

import numpy as np
import scipy.sparse
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.errors import ClearjointError, ParameterError, ParameterTypeError
from clearjoint.joint import ClearanceJoint, Joint, Losses, checked_losses
from clearjoint.laws.clearance import COMPRESSION, OPEN, TENSION, state_tables
from clearjoint.laws.clearance import parameters as law_parameters

FloatArray = NDArray[np.float64]
Matrix: TypeAlias = Any  # (N, N) float64 ndarray or scipy.sparse.csr_matrix

#: Above this many DOFs a structure's matrices are kept sparse.
SPARSE_ABOVE = 200


def force_amplitudes(force: ArrayLike, dof_names: Sequence[str], name: str = "force") -> FloatArray:
    """The force amplitudes (N) as an (N,) array: one finite value per DOF of ``dof_names``
    (for one DOF, a number too).

    Raises
    ------
    ParameterTypeError
        ``force`` is not numbers.
    ParameterError
        Not one value per DOF, or a NaN or infinite one.
    """
    n = len(dof_names)
    if n == 1 and np.ndim(force) == 0:
        return np.array([_checks.real_scalar(name, force, unit="N")])
    try:
        f = np.asarray(force, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterTypeError(
            f"{name} must be {n} force amplitudes (N), one per DOF, got {force!r}"
        ) from None
    if f.shape != (n,):
        raise ParameterError(
            f"{name} must hold one amplitude per DOF, shape ({n},) in N, got shape {f.shape}; "
            f"the DOFs are {', '.join(dof_names[:6])}" + (", ..." if n > 6 else "")
        )
    if not np.all(np.isfinite(f)):
        raise ParameterError(f"{name} has a NaN or infinite entry")
    return f


class VibrationSystemError(ClearjointError, ValueError):
    """A vibration system that cannot be built as given (the message names the item)."""


class LawArrays(NamedTuple):
    """Each joint's law as arrays (n_j,): k0, k_c, k_t in N/m, g_c, g_t in m."""

    k0: FloatArray
    k_c: FloatArray
    k_t: FloatArray
    g_c: FloatArray
    g_t: FloatArray


def _matrix(name: str, value: Any, n: int | None) -> Matrix:
    """``value`` as a float64 (N, N) matrix, sparse (CSR) kept sparse; checked finite, square."""
    if scipy.sparse.issparse(value):
        m = scipy.sparse.csr_matrix(value, dtype=np.float64)
        data = m.data
    else:
        try:
            m = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise ParameterTypeError(f"{name} must be a matrix of numbers, got {value!r}") from None
        data = m
    shape = m.shape
    if len(shape) != 2 or shape[0] != shape[1]:
        raise VibrationSystemError(f"{name} must be a square (N, N) matrix, got shape {shape}")
    if n is not None and shape[0] != n:
        raise VibrationSystemError(
            f"{name} is {shape[0]} x {shape[0]}, the mass matrix is {n} x {n}"
        )
    if not np.all(np.isfinite(data)):
        raise VibrationSystemError(f"{name} has a NaN or infinite entry")
    return m


@dataclass(frozen=True, eq=False)
class VibrationSystem:
    """M, C, K, the joints' directions, laws and losses: the system every solver takes.

    MODEL.md 5.2 (module docstring).

    Parameters
    ----------
    mass, damping, stiffness : (N, N) ndarray or scipy.sparse matrix
        M in kg, C in N s/m, K in N/m of the linear part (K excludes the joints' laws,
        whose free-play stiffness k0 the laws carry). Sparse inputs stay sparse (CSR).
    directions : (n_j, N) array_like
        Row j is b_j: joint j's relative displacement is delta_j = b_j . u.
    laws : sequence of ClearanceJoint
        Joint j's elastic law f_j(delta) (its friction and restitution, if any, are
        moved into ``losses``).
    losses : sequence of Losses, optional
        Joint j's dissipation: ``friction``, ``restitution``, ``pin`` and
        ``contact_friction_coefficient`` (its ``damping_ratio`` must be 0: viscous
        damping is in C). Default: none.
    dof_names : sequence of str, optional
        One name per DOF. Default "u1", "u2", ...
    source : object, optional
        What the system was made from (a Joint or a Structure), for drawing and names.

    Raises
    ------
    ParameterError
        A matrix not square, of another size, or not finite; directions of the wrong
        shape; a law or loss of the wrong type or count; a damping ratio in a joint's
        losses; DOF names not one per DOF or repeated.
    """

    mass: Matrix
    damping: Matrix
    stiffness: Matrix
    directions: FloatArray
    laws: tuple[ClearanceJoint, ...]
    losses: tuple[Losses, ...] = ()
    dof_names: tuple[str, ...] = ()
    source: Any = field(default=None, repr=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        mass = _matrix("mass", self.mass, None)
        n = int(mass.shape[0])
        if n == 0:
            raise VibrationSystemError("a vibration system needs at least one DOF")
        set_(self, "mass", mass)
        set_(self, "damping", _matrix("damping", self.damping, n))
        set_(self, "stiffness", _matrix("stiffness", self.stiffness, n))
        laws = tuple(self.laws)
        for j, law in enumerate(laws):
            if not isinstance(law, ClearanceJoint):
                raise ParameterTypeError(
                    f"laws[{j}] must be a clearjoint.ClearanceJoint, got {law!r}"
                )
        losses = tuple(self.losses) or tuple(Losses() for _ in laws)
        if len(losses) != len(laws):
            raise VibrationSystemError(
                f"{len(losses)} losses given for {len(laws)} joints: give one each"
            )
        elastic, carried = [], []
        for j, (law, loss) in enumerate(zip(laws, losses, strict=True)):
            if not isinstance(loss, Losses):
                raise ParameterTypeError(f"losses[{j}] must be a clearjoint.Losses, got {loss!r}")
            if loss.damping_ratio != 0.0:
                raise ParameterError(
                    f"losses[{j}] has damping_ratio {loss.damping_ratio!r}: a joint's viscous "
                    "damping belongs in the damping matrix C; set it to 0"
                )
            if law.friction is not None or law.restitution != 1.0:
                if loss.friction is not None or loss.restitution != 1.0:
                    raise ParameterError(
                        f"joint {j} has friction or restitution both in its law and in "
                        "losses; give them in losses only"
                    )
                loss = replace(loss, friction=law.friction, restitution=law.restitution)
                law = replace(law, friction=None, restitution=1.0)
            elastic.append(law)
            carried.append(loss)
        set_(self, "laws", tuple(elastic))
        set_(self, "losses", tuple(carried))
        b = np.asarray(self.directions, dtype=np.float64)
        if b.size == 0:
            b = b.reshape(len(laws), n)
        if b.shape != (len(laws), n):
            raise VibrationSystemError(
                f"directions must be (n_joints, N) = ({len(laws)}, {n}), got {b.shape}"
            )
        if not np.all(np.isfinite(b)):
            raise VibrationSystemError("directions has a NaN or infinite entry")
        set_(self, "directions", b)
        names = tuple(self.dof_names) or tuple(f"u{i + 1}" for i in range(n))
        if len(names) != n or len(set(names)) != n:
            raise VibrationSystemError(f"dof_names must be {n} distinct names, got {len(names)}")
        set_(self, "dof_names", tuple(str(s) for s in names))

    # ---- construction ---------------------------------------------------------------------

    @classmethod
    def from_joint(cls, joint: Joint, losses: Losses | None = None) -> VibrationSystem:
        """The one-DOF system of a :class:`Joint`: M = m, C = 2 zeta sqrt(m k_c), K = 0, b = 1.

        MODEL.md eq 7 for c_v. ``losses`` (default none) gives the damping ratio, which
        becomes C, and the joint's friction, restitution and pin.
        """
        if not isinstance(joint, Joint):
            raise ParameterTypeError(f"joint must be a clearjoint.Joint, got {joint!r}")
        losses = checked_losses(losses)
        c_v = 2.0 * losses.damping_ratio * math.sqrt(joint.mass * joint.compression_stiffness)
        one = np.ones((1, 1))
        return cls(
            mass=joint.mass * one,
            damping=c_v * one,
            stiffness=np.zeros((1, 1)),
            directions=one.copy(),
            laws=(joint.element,),
            losses=(replace(losses, damping_ratio=0.0),),
            dof_names=("x",),
            source=joint,
        )

    def to_joint(self) -> tuple[Joint, Losses]:
        """This system of one DOF and one joint as a :class:`Joint` and its :class:`Losses`.

        The inverse of :meth:`from_joint` (MODEL.md eq 7): m = M; the joint's law, with
        the linear stiffness K (a spring in parallel, acting everywhere) added to its
        free-play stiffness k0; ``damping_ratio`` = C / (2 sqrt(m k_c)) beside the joint's
        own losses. This is how the single-joint solvers (``clearjoint.simulate``,
        ``clearjoint.periodic``, ``clearjoint.dissipation``) take a system.

        Raises
        ------
        VibrationSystemError
            More than one DOF or joint, or a joint direction other than +1.
        """
        if self.n_dof != 1 or self.n_joints != 1:
            raise VibrationSystemError(
                f"a single-joint solver takes a system of one DOF and one joint, got "
                f"{self.n_dof} DOFs and {self.n_joints} joints; use clearjoint.structure's "
                "solvers or clearjoint.harmonic for this system"
            )
        b = float(self.directions[0, 0])
        if b != 1.0:
            flip = (
                "; flip the law's sides instead (swap k_c and k_t, negate gap_offset)"
                if b == -1.0
                else "; write the system in the joint's own displacement delta = b u"
            )
            raise VibrationSystemError(
                "a single-joint solver needs the joint's direction b = +1 (x positive in "
                f"compression), got {b!r}" + flip
            )
        law = self.laws[0]
        mass = float(self.mass[0, 0])
        if law.gap_stiffness + float(self.stiffness[0, 0]) < 0.0:
            raise VibrationSystemError(
                f"the linear stiffness K = {float(self.stiffness[0, 0])!r} N/m plus the law's "
                f"k0 = {law.gap_stiffness!r} N/m is negative: a single joint's stiffness inside "
                "the gap must be >= 0"
            )
        joint = Joint(
            mass,
            law.clearance,
            law.compression_stiffness,
            law.tension_stiffness,
            law.gap_stiffness + float(self.stiffness[0, 0]),
            law.gap_offset,
        )
        zeta = float(self.damping[0, 0]) / (2.0 * math.sqrt(mass * law.compression_stiffness))
        return joint, replace(self.losses[0], damping_ratio=zeta)

    # ---- sizes and views --------------------------------------------------------------------

    @property
    def n_dof(self) -> int:
        """N, the number of degrees of freedom."""
        return int(self.mass.shape[0])

    @property
    def n_joints(self) -> int:
        """n_j, the number of clearance joints."""
        return len(self.laws)

    @property
    def is_sparse(self) -> bool:
        """Whether M, C, K are held as sparse matrices."""
        return bool(scipy.sparse.issparse(self.stiffness))

    @property
    def is_joint(self) -> bool:
        """True for the one-DOF system of a single :class:`Joint`."""
        return isinstance(self.source, Joint)

    def law_arrays(self) -> LawArrays:
        """Each joint's k0, k_c, k_t (N/m) and gap edges g_c, g_t (m), as (n_j,) arrays."""
        return LawArrays(*law_parameters(self.laws))

    def restitution(self) -> FloatArray:
        """Each joint's coefficient of restitution e, (n_j,)."""
        return np.array([loss.restitution for loss in self.losses], dtype=np.float64)

    def friction_force(self) -> FloatArray:
        """Each joint's Coulomb force mu_s P, N (0 for a joint without friction), (n_j,)."""
        return np.array(
            [0.0 if loss.friction is None else loss.friction.force for loss in self.losses]
        )

    def mass_diagonal(self) -> FloatArray:
        """The lumped masses per DOF, (N,) in kg.

        Raises
        ------
        ParameterError
            M is not diagonal (a consistent mass matrix): the solver asked for needs a
            lumped mass.
        """
        m = self.mass
        diagonal = np.asarray(m.diagonal(), dtype=np.float64)
        off = (
            (m - scipy.sparse.diags(diagonal))
            if scipy.sparse.issparse(m)
            else m - np.diag(diagonal)
        )
        if off.count_nonzero() if scipy.sparse.issparse(off) else np.count_nonzero(off):
            raise VibrationSystemError(
                "this solver needs a lumped (diagonal) mass matrix; this system's M has "
                "off-diagonal terms"
            )
        return diagonal

    # ---- stiffness of contact patterns -----------------------------------------------------

    def pattern_stiffness(self, states: ArrayLike) -> tuple[Matrix, FloatArray]:
        """Return (K_s, r_s) of a contact pattern: the restoring force is K_s u - r_s.

        ``states`` (n_j,) holds OPEN (0), COMPRESSION (1) or TENSION (-1) per joint
        (MODEL.md 5.2). K_s is sparse when K is.
        """
        s = np.asarray(states, dtype=np.int64)
        if s.shape != (self.n_joints,):
            raise VibrationSystemError(
                f"a pattern needs one state per joint ({self.n_joints}), got shape {s.shape}"
            )
        k_table, r_table = prefer(state_tables)(*self.law_arrays())
        rows = np.arange(self.n_joints)
        k_j, r_j = k_table[rows, s + 1], r_table[rows, s + 1]
        b = self.directions
        r = b.T @ r_j if self.n_joints else np.zeros(self.n_dof)
        if self.is_sparse:
            bs = scipy.sparse.csr_matrix(b)
            k = self.stiffness + (bs.T @ scipy.sparse.diags(k_j) @ bs).tocsr()
            return scipy.sparse.csr_matrix(k), np.asarray(r, dtype=np.float64)
        k = self.stiffness + (b.T * k_j) @ b
        return np.asarray(k, dtype=np.float64), np.asarray(r, dtype=np.float64)

    def closed_stiffness(self) -> Matrix:
        """K with every joint in compression contact (tangent k0 + k_c), N/m."""
        return self.pattern_stiffness(np.full(self.n_joints, COMPRESSION))[0]

    def open_stiffness(self) -> Matrix:
        """K with every joint in free-play (tangent k0), N/m."""
        return self.pattern_stiffness(np.full(self.n_joints, OPEN))[0]

    def joint_forces(self, delta: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Return f_j(delta) (N) and df_j/d delta (N/m) for samples ``delta`` (..., n_j)."""
        d = np.asarray(delta, dtype=np.float64)
        if d.shape[-1:] != (self.n_joints,):
            raise VibrationSystemError(
                f"delta must end in one value per joint ({self.n_joints}), got shape {d.shape}"
            )
        force = np.empty_like(d)
        tangent = np.empty_like(d)
        for j, law in enumerate(self.laws):
            force[..., j] = law.force(d[..., j])
            tangent[..., j] = law.tangent_stiffness(d[..., j])
        return force, tangent

    def force_vector(self, force: ArrayLike, name: str = "force") -> FloatArray:
        """The force amplitudes per DOF, N: a number for a one-DOF system, else an (N,) array.

        Raises
        ------
        ParameterError
            Not one finite value per DOF; a number for a system of several DOFs.
        """
        return force_amplitudes(force, self.dof_names, name)

    def __repr__(self) -> str:
        kind = "sparse" if self.is_sparse else "dense"
        made = f", from {type(self.source).__name__}" if self.source is not None else ""
        return f"VibrationSystem({self.n_dof} DOF, {self.n_joints} joints, {kind}{made})"


def as_system(system: Any, losses: Losses | None = None) -> VibrationSystem:
    """Return ``system`` as a :class:`VibrationSystem`: a Joint with ``losses``, a Structure, ...

    A Structure (anything with a ``to_system()`` method) carries its own losses, so
    ``losses`` must then be None.

    Raises
    ------
    ParameterTypeError
        ``system`` is none of these.
    ParameterError
        ``losses`` given with a system that carries its own.
    """
    if isinstance(system, Joint):
        return VibrationSystem.from_joint(system, losses)
    if losses is not None:
        raise ParameterError(
            f"losses apply to a single Joint; a {type(system).__name__} carries its own "
            "(member dampers, Rayleigh damping, each joint's friction and restitution)"
        )
    if isinstance(system, VibrationSystem):
        return system
    to_system = getattr(system, "to_system", None)
    if callable(to_system):
        made = to_system()
        if isinstance(made, VibrationSystem):
            return made
    raise ParameterTypeError(
        "system must be a clearjoint.Joint, a clearjoint.structure.Structure or a "
        f"clearjoint.system.VibrationSystem, got {system!r}"
    )


def as_joint(system: Any, losses: Losses | None = None) -> tuple[Joint, Losses]:
    """Return a single-joint solver's input as a :class:`Joint` and its :class:`Losses`.

    A Joint comes with ``losses`` (None: no losses); a one-DOF
    :class:`VibrationSystem` carries its own (:meth:`VibrationSystem.to_joint`), so
    ``losses`` must then be None.

    Raises
    ------
    ParameterTypeError
        ``system`` is neither, or ``losses`` is not a Losses.
    ParameterError
        ``losses`` given with a system that carries its own.
    VibrationSystemError
        A system that is not one joint.
    """
    if isinstance(system, Joint):
        return system, checked_losses(losses)
    if isinstance(system, VibrationSystem):
        if losses is not None:
            raise ParameterError(
                "losses apply to a Joint; a VibrationSystem carries its own (its damping "
                "matrix C and its losses): give one or the other"
            )
        return system.to_joint()
    raise ParameterTypeError(
        "joint must be a clearjoint.Joint or a one-DOF clearjoint.system.VibrationSystem, "
        f"got {system!r}"
    )


def pattern_states(
    system: VibrationSystem, pattern: str | Sequence[int] | NDArray[np.int64]
) -> NDArray[np.int64]:
    """Per-joint states of a named pattern ("closed", "open") or of an explicit array."""
    if isinstance(pattern, str):
        if pattern == "closed":
            return np.full(system.n_joints, COMPRESSION, dtype=np.int64)
        if pattern == "open":
            return np.full(system.n_joints, OPEN, dtype=np.int64)
        raise VibrationSystemError(
            f"pattern must be 'closed', 'open' or per-joint states, got {pattern!r}"
        )
    states = np.asarray(pattern, dtype=np.int64)
    bad = ~np.isin(states, (OPEN, COMPRESSION, TENSION))
    if np.any(bad):
        raise VibrationSystemError(
            f"a joint state must be 0 (open), 1 (compression) or -1 (tension), got "
            f"{states[bad][0]!r}"
        )
    return states
