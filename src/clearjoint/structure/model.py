"""A structure of lumped masses, axial members and clearance joints (MODEL.md 5.2).

    M u'' + C u' + K u + sum_j b_j f_j(b_j^T u) = F(t)

u holds the displacements of the free nodes (``dim`` per node). Each member joins two
nodes along their line; delta = b^T u is its shortening (positive in compression, as x
is for :class:`~clearjoint.Joint`). A member without a joint is a linear spring in K;
a member with a :class:`~clearjoint.ClearanceJoint` is one massless piecewise-linear
law of delta (the joint in series with the member's spring,
:meth:`ClearanceJoint.in_series`). In one contact pattern (each joint open, in
compression or in tension) the system is linear: K_s = K + sum_j K_j,s b_j b_j^T and a
constant force r_s.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.errors import ClearjointError, ParameterError, ParameterTypeError
from clearjoint.joint import ClearanceJoint, positive_or_inf
from clearjoint.laws import clearance
from clearjoint.system import Matrix, VibrationSystem, as_system, pattern_states

FloatArray = NDArray[np.float64]

#: Joint states in a contact pattern: the law's contact states.
OPEN, COMPRESSION, TENSION = clearance.OPEN, clearance.COMPRESSION, clearance.TENSION

#: Above this many DOFs the matrices are returned sparse.
SPARSE_ABOVE = 200


class StructureError(ClearjointError, ValueError):
    """A structure that cannot be built or solved as given (the message names the item)."""


@dataclass(frozen=True)
class Member:
    """An axial member between two nodes, optionally with a clearance joint in series.

    Parameters
    ----------
    start, end : int
        Node indices (0-based) of the member's ends.
    stiffness : float, optional
        Axial stiffness k_m in N/m (> 0; ``math.inf`` for a rigid link, which needs a
        joint). Give either this or ``youngs_modulus`` and ``area``.
    youngs_modulus, area : float, optional
        E in Pa and A in m^2: k_m = E A / L.
    length : float, optional
        L in m for E A / L; default: the distance between the nodes.
    joint : ClearanceJoint, optional
        A clearance joint in series with the member's spring.
    damping : float
        A viscous dashpot across the member (joint included), N s/m, >= 0.
    """

    start: int
    end: int
    stiffness: float | None = None
    youngs_modulus: float | None = None
    area: float | None = None
    length: float | None = None
    joint: ClearanceJoint | None = None
    damping: float = 0.0

    def __post_init__(self) -> None:
        for name in ("start", "end"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | np.integer):
                raise ParameterTypeError(f"member {name} must be a node index, got {value!r}")
            object.__setattr__(self, name, int(value))
        if self.stiffness is not None:
            if self.youngs_modulus is not None or self.area is not None:
                raise ParameterError(
                    "give a member either stiffness or youngs_modulus and area, not both"
                )
            object.__setattr__(
                self, "stiffness", positive_or_inf("member stiffness", self.stiffness, unit="N/m")
            )
        elif self.youngs_modulus is None or self.area is None:
            raise ParameterError(
                f"member {self.start}-{self.end} needs a stiffness (N/m) or youngs_modulus "
                "(Pa) and area (m^2)"
            )
        else:
            e = _checks.positive("youngs_modulus", self.youngs_modulus, unit="Pa")
            a = _checks.positive("area", self.area, unit="m^2")
            object.__setattr__(self, "youngs_modulus", e)
            object.__setattr__(self, "area", a)
        if self.length is not None:
            object.__setattr__(
                self, "length", _checks.positive("member length", self.length, unit="m")
            )
        if self.joint is not None and not isinstance(self.joint, ClearanceJoint):
            raise ParameterTypeError(
                f"member joint must be a clearjoint.ClearanceJoint or None, got {self.joint!r}"
            )
        object.__setattr__(
            self, "damping", _checks.non_negative("member damping", self.damping, unit="N s/m")
        )


def default_dof_names(structure: Structure | None, n_dof: int) -> tuple[str, ...]:
    """Return the structure's DOF names, or u1 ... un when there is none or it names none.

    The default ``dof_names`` of the structure's results (:class:`Modes`,
    :class:`~clearjoint.structure.motion.StructureMotion`).
    """
    names = () if structure is None else tuple(structure.dof_names)
    return names or tuple(f"u{i + 1}" for i in range(n_dof))


@dataclass(frozen=True)
class Modes:
    """Natural frequencies and mode shapes of one linear contact pattern.

    Attributes
    ----------
    omega : (n,) ndarray
        Natural circular frequencies, rad/s, ascending (0 for a mechanism of an open pattern).
    shapes : (N, n) ndarray
        Mass-normalised mode shapes (u^T M u = 1), one per column, over the free DOFs.
    pattern : str
        "closed" (every joint in compression contact) or "open" (every joint in free-play).
    structure : Structure or None
        The structure drawn by :meth:`plot`; None for a system given as matrices.
    dof_names : tuple of str
        A name per DOF (default: the structure's).
    """

    omega: FloatArray
    shapes: FloatArray
    pattern: str
    structure: Structure | None = field(repr=False)
    dof_names: tuple[str, ...] = field(default=(), repr=False)

    def __post_init__(self) -> None:
        if not self.dof_names:
            names = default_dof_names(self.structure, self.shapes.shape[0])
            object.__setattr__(self, "dof_names", names)

    @property
    def frequency_hz(self) -> FloatArray:
        """Natural frequencies in Hz."""
        return self.omega / (2.0 * math.pi)

    def __repr__(self) -> str:
        shown = ", ".join(f"{f:.4g}" for f in self.frequency_hz[:4])
        more = ", ..." if self.omega.size > 4 else ""
        return f"Modes({self.pattern}, {self.omega.size} modes, f = [{shown}{more}] Hz)"

    def plot(self, ax: Any = None, *, modes: int = 3, scale: float | None = None) -> Any:
        """Draw the undeformed structure and its first ``modes`` shapes; return the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        n = min(modes, self.omega.size)
        s = self.structure
        if s is None:  # a system given as matrices: the shapes against DOF index
            for k in range(n):
                label = f"mode {k + 1}: {self.frequency_hz[k]:.4g} Hz"
                ax.plot(self.shapes[:, k], marker="o", color=f"C{k}", label=label)
            ax.set_xlabel("DOF index")
            ax.set_ylabel("mode shape (1/sqrt(kg))")
            ax.set_title(f"{self.pattern} pattern")
            ax.legend(fontsize="small")
            return ax
        for k in range(n):
            shape = s.node_displacements(self.shapes[:, k])
            size = float(np.max(np.abs(shape))) or 1.0
            factor = (scale if scale is not None else 0.15 * s.size) / size
            label = f"mode {k + 1}: {self.frequency_hz[k]:.4g} Hz"
            s.draw(ax, displacement=factor * shape, color=f"C{k}", label=label)
        s.draw(ax, color="0.6", linestyle=":", label="undeformed")
        ax.set_title(f"{self.pattern} pattern")
        ax.legend(fontsize="small")
        return ax

    def to_xarray(self) -> Any:
        """The modes as an xarray Dataset (omega in rad/s, shapes per DOF)."""
        import xarray as xr

        return xr.Dataset(
            {
                "omega": ("mode", self.omega, {"units": "rad/s"}),
                "frequency": ("mode", self.frequency_hz, {"units": "Hz"}),
                "shape": (("dof", "mode"), self.shapes, {"units": "1/sqrt(kg)"}),
            },
            coords={"mode": np.arange(1, self.omega.size + 1), "dof": list(self.dof_names)},
            attrs={"pattern": self.pattern},
        )

    def to_pandas(self) -> Any:
        """Return the modes as a ``pandas.DataFrame``, one row per mode.

        Returns
        -------
        pandas.DataFrame
            Index ``mode`` (1, 2, ...); columns ``omega_rad_per_s``, ``frequency_hz``,
            then the mass-normalised shape on each DOF, ``shape[<dof name>]`` in
            1/sqrt(kg).
        """
        import pandas as pd

        columns: dict[str, Any] = {"omega_rad_per_s": self.omega, "frequency_hz": self.frequency_hz}
        names = self.dof_names
        columns.update({f"shape[{name}]": self.shapes[k] for k, name in enumerate(names)})
        return pd.DataFrame(columns, index=pd.Index(np.arange(1, self.omega.size + 1), name="mode"))


@dataclass(frozen=True, eq=False)
class Structure:
    """Lumped masses on nodes, axial members with optional clearance joints, supports.

    Parameters
    ----------
    nodes : (n_nodes, dim) array_like
        Node coordinates in m; dim = 1, 2 or 3 (a 1-D sequence is taken as dim = 1).
    masses : (n_nodes,) array_like
        Lumped mass of each node in kg (> 0 on every free node; ignored on supports).
    members : sequence of Member
    supports : sequence of int
        Nodes fixed in every direction.
    rayleigh : (alpha, beta)
        Rayleigh damping C += alpha M + beta K_closed (1/s, s), with K_closed the
        stiffness with every joint in compression contact. Default none. Each may be a
        pint Quantity or unit text ("0.5/s" or "0.5rad/s", the same rate; "2e-6s").

    Raises
    ------
    StructureError
        Zero-length member, unknown node, a joint between two supports, restitution on
        a joint in series with a member, a rigid member without a joint, a massless
        free node, or a structure free to move as a rigid body or mechanism.
    """

    nodes: FloatArray
    masses: FloatArray
    members: tuple[Member, ...]
    supports: tuple[int, ...] = ()
    rayleigh: tuple[float, float] = (0.0, 0.0)
    _laws: tuple[ClearanceJoint, ...] = field(init=False, repr=False, compare=False)
    _b: FloatArray = field(init=False, repr=False, compare=False)
    _k_member: FloatArray = field(init=False, repr=False, compare=False)

    def __eq__(self, other: object) -> bool:
        """Equal when nodes, masses, members, supports and damping are (arrays by value)."""
        if not isinstance(other, Structure):
            return NotImplemented
        return (
            np.array_equal(self.nodes, other.nodes)
            and np.array_equal(self.masses, other.masses)
            and self.members == other.members
            and self.supports == other.supports
            and self.rayleigh == other.rayleigh
        )

    __hash__ = None  # type: ignore[assignment]  # mutable-by-content arrays: not hashable

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        nodes = np.asarray(self.nodes, dtype=np.float64)
        if nodes.ndim == 1:
            nodes = nodes[:, None]
        if nodes.ndim != 2 or nodes.shape[1] not in (1, 2, 3) or nodes.shape[0] < 2:
            raise StructureError(
                f"nodes must be an (n_nodes, dim) array with dim 1, 2 or 3 and at least 2 "
                f"nodes, got shape {nodes.shape}"
            )
        if not np.all(np.isfinite(nodes)):
            raise StructureError("node coordinates must be finite (m)")
        set_(self, "nodes", nodes)
        n_nodes = nodes.shape[0]
        masses = np.asarray(self.masses, dtype=np.float64)
        if masses.shape != (n_nodes,):
            raise StructureError(
                f"masses must have one value per node ({n_nodes}), got shape {masses.shape}"
            )
        set_(self, "masses", masses)
        supports = tuple(self._node("support", s, n_nodes) for s in self.supports)
        twice = sorted({s for s in supports if supports.count(s) > 1})
        if twice:  # harmless to the matrices, but a typo for another node more often than not
            raise StructureError(f"support {twice[0]} is listed twice; list each support once")
        set_(self, "supports", supports)
        for i in range(n_nodes):
            if i not in supports and not (math.isfinite(masses[i]) and masses[i] > 0.0):
                raise StructureError(
                    f"node {i} is free but has mass {float(masses[i])!r} kg; give it a mass > 0 "
                    "or make it a support"
                )
        if not isinstance(self.rayleigh, tuple | list) or len(self.rayleigh) != 2:
            raise StructureError(
                f"rayleigh must be (alpha, beta) in (1/s, s), got {self.rayleigh!r}"
            )
        # alpha multiplies M: a rate (1/s; "0.5rad/s" is 0.5 /s, Hz is refused); beta is a time
        alpha = _checks.non_negative("rayleigh alpha", self.rayleigh[0], unit="1/s")
        beta = _checks.non_negative("rayleigh beta", self.rayleigh[1], unit="s")
        set_(self, "rayleigh", (alpha, beta))
        members = tuple(self.members)
        if not members:
            raise StructureError("a structure needs at least one member")
        set_(self, "members", members)
        laws: list[ClearanceJoint] = []
        b_rows: list[FloatArray] = []
        k_member = np.zeros(len(members))
        for index, member in enumerate(members):
            if not isinstance(member, Member):
                raise StructureError(f"member {index} must be a structure.Member, got {member!r}")
            b, k = self._member_geometry(index, member, supports)
            b_rows.append(b)
            k_member[index] = k
            if member.joint is not None:
                try:
                    laws.append(member.joint.in_series(k))
                except ParameterError as exc:
                    raise StructureError(f"member {index}: {exc}") from None
        set_(self, "_laws", tuple(laws))
        set_(self, "_b", np.array(b_rows).reshape(len(members), self.n_dof))
        set_(self, "_k_member", k_member)
        self._check_supported()

    # ---- construction helpers -------------------------------------------------------------

    @staticmethod
    def _node(what: str, value: Any, n_nodes: int) -> int:
        if isinstance(value, bool) or not isinstance(value, int | np.integer):
            raise StructureError(f"{what} must be a node index, got {value!r}")
        if not 0 <= value < n_nodes:
            raise StructureError(
                f"{what} names node {value}, which does not exist (nodes are 0 to {n_nodes - 1})"
            )
        return int(value)

    def _member_geometry(
        self, index: int, member: Member, supports: tuple[int, ...]
    ) -> tuple[FloatArray, float]:
        n_nodes = self.nodes.shape[0]
        start = self._node(f"member {index} start", member.start, n_nodes)
        end = self._node(f"member {index} end", member.end, n_nodes)
        axis = self.nodes[end] - self.nodes[start]
        distance = float(np.linalg.norm(axis))
        if distance == 0.0 or distance < 1e-12 * max(self.size, 1e-300):
            raise StructureError(
                f"member {index} (nodes {start}-{end}) has zero length; move its nodes apart"
            )
        if start in supports and end in supports:
            what = "a joint" if member.joint is not None else "a member"
            raise StructureError(
                f"member {index} joins two supports (nodes {start}, {end}), so {what} there "
                "can never move; remove it or free one of its nodes"
            )
        if member.stiffness is not None:
            k = float(member.stiffness)
        else:
            length = member.length if member.length is not None else distance
            k = float(member.youngs_modulus) * float(member.area) / length  # type: ignore[arg-type]
        if math.isinf(k) and member.joint is None:
            raise StructureError(
                f"member {index} (nodes {start}-{end}) is rigid and has no joint; "
                "give it a finite stiffness or a ClearanceJoint"
            )
        unit = axis / distance
        b = np.zeros(self.n_dof)
        # shortening: delta = e . (u_start - u_end)
        for node, sign in ((start, 1.0), (end, -1.0)):
            dofs = self.node_dofs(node)
            if dofs is not None:
                b[dofs] += sign * unit
        return b, k

    def _check_supported(self) -> None:
        k, _ = self.pattern_stiffness(self._states("closed"))
        w2 = scipy.linalg.eigh(k, np.diag(self.mass_diagonal()), eigvals_only=True)
        top = max(float(w2[-1]), 1e-300)
        if w2[0] <= 1e-10 * top:
            _, vectors = scipy.linalg.eigh(k, np.diag(self.mass_diagonal()))
            moving = self.node_displacements(vectors[:, 0])
            nodes = np.flatnonzero(np.linalg.norm(moving, axis=1) > 1e-6 * np.abs(moving).max())
            raise StructureError(
                "the structure is singular: it can move as a rigid body or mechanism without "
                f"straining any member (nodes {', '.join(map(str, nodes[:6]))} move); "
                "add supports or members"
            )

    # ---- geometry and DOFs ------------------------------------------------------------------

    @property
    def dim(self) -> int:
        """Number of space dimensions (1, 2 or 3)."""
        return int(self.nodes.shape[1])

    @property
    def free_nodes(self) -> tuple[int, ...]:
        """Indices of the nodes that are not supports, in DOF order."""
        return tuple(i for i in range(self.nodes.shape[0]) if i not in self.supports)

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom N = dim x (free nodes)."""
        return self.dim * len(self.free_nodes)

    @property
    def size(self) -> float:
        """The largest extent of the structure, m."""
        return float(np.max(np.ptp(self.nodes, axis=0)))

    def node_dofs(self, node: int) -> NDArray[np.int64] | None:
        """The DOF indices of a node (None for a support)."""
        if node in self.supports:
            return None
        rank = self.free_nodes.index(node)
        return np.arange(rank * self.dim, (rank + 1) * self.dim)

    @property
    def dof_names(self) -> list[str]:
        """A name per DOF: "n3x" is node 3 along x."""
        axes = "xyz"[: self.dim]
        return [f"n{node}{a}" for node in self.free_nodes for a in axes]

    def node_displacements(self, u: ArrayLike) -> FloatArray:
        """Return (n_nodes, dim) nodal displacements from a DOF vector (0 at supports)."""
        out = np.zeros_like(self.nodes)
        values = np.asarray(u, dtype=np.float64).reshape(-1, self.dim)
        out[list(self.free_nodes)] = values
        return out

    @property
    def joint_members(self) -> tuple[int, ...]:
        """Indices of the members that carry a clearance joint, in joint order."""
        return tuple(i for i, m in enumerate(self.members) if m.joint is not None)

    @property
    def joint_laws(self) -> tuple[ClearanceJoint, ...]:
        """Each joint's law of its member's shortening (joint and member spring in series)."""
        return self._laws

    @property
    def joint_directions(self) -> FloatArray:
        """(n_joints, N): row j is b_j, so delta_j = b_j . u is joint j's member shortening."""
        return self._b[list(self.joint_members)]

    @property
    def member_directions(self) -> FloatArray:
        """(n_members, N): row i maps u to member i's shortening."""
        return self._b.copy()

    # ---- matrices ---------------------------------------------------------------------------

    def mass_diagonal(self) -> FloatArray:
        """The lumped masses per DOF, (N,) in kg."""
        return np.repeat(self.masses[list(self.free_nodes)], self.dim)

    def mass_matrix(self) -> FloatArray | scipy.sparse.csr_matrix:
        """Return the lumped mass matrix M, (N, N) in kg (sparse when N > 200)."""
        diagonal = self.mass_diagonal()
        if self.n_dof > SPARSE_ABOVE:
            return scipy.sparse.diags(diagonal).tocsr()
        return np.diag(diagonal)

    def pattern_stiffness(self, states: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Return (K_s, r_s) of a contact pattern: the restoring force is K_s u - r_s.

        ``states`` (n_joints,) holds OPEN (0), COMPRESSION (1) or TENSION (-1) per joint.
        Dense (N, N) and (N,).
        """
        states = np.asarray(states, dtype=np.int64)
        if states.shape != (len(self._laws),):
            raise StructureError(
                f"a pattern needs one state per joint ({len(self._laws)}), got {states.shape}"
            )
        b = self._b
        plain = [i for i, m in enumerate(self.members) if m.joint is None]
        k = (b[plain].T * self._k_member[plain]) @ b[plain]
        r = np.zeros(self.n_dof)
        for j, (member, law) in enumerate(zip(self.joint_members, self._laws, strict=True)):
            k_j, offset = _law_state(law, int(states[j]))
            k += k_j * np.outer(b[member], b[member])
            r += offset * b[member]
        return k, r

    def stiffness_matrix(
        self, pattern: Literal["closed", "open"] | ArrayLike = "closed"
    ) -> FloatArray | scipy.sparse.csr_matrix:
        """Return the stiffness K of a contact pattern, (N, N) in N/m (sparse when N > 200).

        ``pattern``: "closed" (every joint in compression contact), "open" (every joint
        in free-play) or an array of per-joint states (0 open, 1 compression, -1 tension).
        """
        k, _ = self.pattern_stiffness(self._states(pattern))
        return scipy.sparse.csr_matrix(k) if self.n_dof > SPARSE_ABOVE else k

    def _states(self, pattern: Literal["closed", "open"] | ArrayLike) -> NDArray[np.int64]:
        n = len(self._laws)
        if isinstance(pattern, str):
            if pattern == "closed":
                return np.full(n, COMPRESSION, dtype=np.int64)
            if pattern == "open":
                return np.full(n, OPEN, dtype=np.int64)
            raise StructureError(
                f"pattern must be 'closed', 'open' or per-joint states, got {pattern!r}"
            )
        return np.asarray(pattern, dtype=np.int64)

    def damping_matrix(self) -> FloatArray:
        """Return the viscous damping C, (N, N) in N s/m: member dashpots plus Rayleigh."""
        b = self._b
        c = (b.T * np.array([m.damping for m in self.members])) @ b
        alpha, beta = self.rayleigh
        if alpha:
            c += alpha * np.diag(self.mass_diagonal())
        if beta:
            k, _ = self.pattern_stiffness(self._states("closed"))
            c += beta * k
        return np.asarray(c, dtype=np.float64)

    def to_system(self) -> VibrationSystem:
        """Return the structure as the :class:`~clearjoint.system.VibrationSystem` solvers take.

        MODEL.md 5.2: M the lumped masses, C the member dashpots plus Rayleigh damping,
        K the members without a joint (each joint's law, in series with its member,
        carries its own k0), b_j the joint members' directions; each joint's friction
        and restitution become its losses. Dense (N, N) up to ``SPARSE_ABOVE`` DOFs,
        sparse above.
        """
        b = self._b
        plain = [i for i, m in enumerate(self.members) if m.joint is None]
        k = (b[plain].T * self._k_member[plain]) @ b[plain]
        c = self.damping_matrix()
        m = np.diag(self.mass_diagonal())
        if self.n_dof > SPARSE_ABOVE:
            k, c, m = (scipy.sparse.csr_matrix(a) for a in (k, c, m))
        return VibrationSystem(
            mass=m,
            damping=c,
            stiffness=k,
            directions=self.joint_directions.reshape(len(self._laws), self.n_dof),
            laws=self._laws,
            dof_names=tuple(self.dof_names),
            source=self,
        )

    def modes(
        self, pattern: Literal["closed", "open"] = "closed", count: int | None = None
    ) -> Modes:
        """Return the natural frequencies (rad/s) and mass-normalised shapes of a pattern.

        Solves K_s phi = omega^2 M phi (dense, or scipy's eigsh for the ``count``
        lowest modes when N > 200). Linear modes bound the nonlinear ones (MODEL.md 5.2).
        """
        if pattern not in ("closed", "open"):
            raise StructureError(f"pattern must be 'closed' or 'open', got {pattern!r}")
        k, _ = self.pattern_stiffness(self._states(pattern))
        omega, shapes = _pattern_modes(k, self.mass_diagonal(), count)
        return Modes(omega=omega, shapes=shapes, pattern=pattern, structure=self)

    # ---- drawing ----------------------------------------------------------------------------

    def draw(self, ax: Any = None, *, displacement: ArrayLike | None = None, **style: Any) -> Any:
        """Draw the members (joints as dots, supports as triangles); return the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        xyz = self.nodes + (0.0 if displacement is None else np.asarray(displacement))
        if self.dim == 1:
            xyz = np.column_stack((xyz[:, 0], np.zeros(len(xyz))))
        label = style.pop("label", None)
        for i, member in enumerate(self.members):
            p = xyz[[member.start, member.end], :2]
            ax.plot(p[:, 0], p[:, 1], label=label if i == 0 else None, **style)
            if member.joint is not None:
                mid = 0.5 * (p[0] + p[1])
                ax.plot(*mid, "o", ms=3, color=style.get("color", "k"))
        s = xyz[list(self.supports), :2]
        ax.plot(s[:, 0], s[:, 1], "^", color="k", ms=6)
        ax.set_aspect("equal", adjustable="datalim")
        return ax

    def __repr__(self) -> str:
        return (
            f"Structure({self.dim}D, {self.nodes.shape[0]} nodes, {len(self.members)} members, "
            f"{len(self._laws)} joints, {len(self.supports)} supports, {self.n_dof} DOF)"
        )


def _law_state(law: ClearanceJoint, state: int) -> tuple[float, float]:
    """(stiffness, offset) of a joint's law in one state: f = stiffness * delta - offset.

    MODEL.md sec. 0: :func:`clearjoint.laws.clearance.state_law`, for a valid state.
    """
    if state not in (OPEN, COMPRESSION, TENSION):
        raise StructureError(f"a joint state must be 0 (open), 1 or -1, got {state!r}")
    k_s, offset = prefer(clearance.state_law)(
        state,
        law.gap_stiffness,
        law.compression_stiffness,
        law.tension_stiffness,
        law.compression_gap,
        law.tension_gap,
    )
    return float(k_s), float(offset)


def edge_positions(laws: Sequence[ClearanceJoint]) -> tuple[FloatArray, FloatArray]:
    """Return (g_c, g_t) of each law: contact at delta >= g_c and delta <= -g_t."""
    return (
        np.array([law.compression_gap for law in laws]),
        np.array([law.tension_gap for law in laws]),
    )


def require_masses(mass: FloatArray, what: str, names: tuple[str, ...] = ()) -> None:
    """Refuse, in one line naming it, a DOF without a positive mass (``what`` needs them all)."""
    if np.all(mass > 0.0):
        return
    k = int(np.flatnonzero(~(mass > 0.0))[0])
    name = f" ({names[k]})" if names else ""
    raise StructureError(
        f"DOF {k}{name} has a mass of {float(mass[k])!r} kg: {what} needs a mass on every "
        "DOF; give it one, or reduce the model onto its massive DOFs "
        "(clearjoint.structure.reduce)"
    )


def _pattern_modes(k: Matrix, m: FloatArray, count: int | None) -> tuple[FloatArray, FloatArray]:
    """Return omega (rad/s) and mass-normalised shapes of K phi = omega^2 diag(m) phi.

    Dense, or scipy's eigsh for the ``count`` lowest modes when N > ``SPARSE_ABOVE``
    (MODEL.md 5.2).
    """
    n = m.size
    if count is not None and (not isinstance(count, int) or count < 1):
        raise StructureError(f"count must be a positive integer, got {count!r}")
    require_masses(m, "modes")
    if n > SPARSE_ABOVE and count is not None and count < n - 1:
        # shift-invert just below 0: an open pattern with k0 = 0 has a singular K, so
        # K - 0 M cannot be factorised; K + s M (s > 0, far below the spectrum) can
        shift = 1e-9 * float(np.max(np.asarray(k.diagonal()) / m))
        w2, shapes = scipy.sparse.linalg.eigsh(
            scipy.sparse.csc_matrix(k), k=count, M=scipy.sparse.diags(m), sigma=-shift
        )
        order = np.argsort(w2)
        w2, shapes = w2[order], shapes[:, order]
    else:
        dense = k.toarray() if scipy.sparse.issparse(k) else k
        w2, shapes = scipy.linalg.eigh(dense, np.diag(m))
        if count is not None:
            w2, shapes = w2[:count], shapes[:, :count]
    return np.sqrt(np.clip(w2, 0.0, None)), shapes


def system_modes(
    system: VibrationSystem | Structure,
    pattern: str | ArrayLike = "closed",
    count: int | None = None,
) -> Modes:
    """Return the natural frequencies and mass-normalised shapes of a system's contact pattern.

    MODEL.md 5.2: K_s phi = omega^2 M phi with K_s = K + sum_j K_j,s b_j b_j^T.

    Parameters
    ----------
    system : VibrationSystem or Structure
        A Structure goes through ``as_system``; M must be lumped (diagonal).
    pattern : "closed", "open" or (n_j,) per-joint states
        0 open, 1 compression, -1 tension.
    count : int, optional
        Only the ``count`` lowest modes (eigsh above ``SPARSE_ABOVE`` DOFs).

    Raises
    ------
    ParameterError
        A consistent (non-diagonal) mass matrix; a pattern or count not understood.
    """
    sys_ = as_system(system)
    states = pattern if isinstance(pattern, str) else np.asarray(pattern, dtype=np.int64)
    k, _ = sys_.pattern_stiffness(pattern_states(sys_, states))
    omega, shapes = _pattern_modes(k, sys_.mass_diagonal(), count)
    source = sys_.source if isinstance(sys_.source, Structure) else None
    name = pattern if isinstance(pattern, str) else "custom"
    return Modes(
        omega=omega, shapes=shapes, pattern=name, structure=source, dof_names=sys_.dof_names
    )
