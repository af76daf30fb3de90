"""Builders of common structures: a chain of masses, a deployable mast, a general truss.

MODEL.md 5.2. Each returns a validated :class:`~clearjoint.structure.Structure`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from clearjoint.joint import ClearanceJoint
from clearjoint.structure.model import Member, Structure, StructureError


def _per_link(name: str, values: Sequence[Any] | None, n: int, default: Any) -> list[Any]:
    if values is None:
        return [default] * n
    values = list(values)
    if len(values) != n:
        raise StructureError(f"{name} must have one entry per link ({n}), got {len(values)}")
    return values


def chain(
    masses: ArrayLike,
    stiffnesses: ArrayLike,
    joints: Sequence[ClearanceJoint | None] | None = None,
    dampers: ArrayLike | None = None,
) -> Structure:
    """Return a 1-D chain: ground, link 0, mass 0, link 1, mass 1, ...

    Link i is a spring ``stiffnesses[i]`` (``math.inf`` for a rigid link) in series with
    ``joints[i]`` (a ClearanceJoint or None), with a dashpot ``dampers[i]`` (N s/m) across
    it. Displacements are positive toward the ground, as x is for
    :class:`~clearjoint.Joint`, so link i is compressed by u_i - u_(i-1) (u_(-1) = 0), and a
    one-link chain with a rigid link is exactly ``Joint``. Node 0 is the ground (at x = 0),
    mass i is node i + 1 (at x = -(i + 1) m); DOF i is mass i.

    Parameters
    ----------
    masses : (n,) array_like
        kg, > 0.
    stiffnesses : (n,) array_like
        N/m, > 0 or inf.
    joints : sequence of n ClearanceJoint or None, optional
    dampers : (n,) array_like, optional
        N s/m, >= 0.
    """
    m = np.atleast_1d(np.asarray(masses, dtype=np.float64))
    k = np.atleast_1d(np.asarray(stiffnesses, dtype=np.float64))
    n = m.size
    if m.ndim != 1 or n < 1:
        raise StructureError("masses must be a 1-D sequence of at least one mass (kg)")
    if k.shape != (n,):
        raise StructureError(f"stiffnesses must have one entry per link ({n}), got {k.size}")
    joint_list = _per_link("joints", joints, n, None)
    damper_list = _per_link("dampers", None if dampers is None else list(np.ravel(dampers)), n, 0.0)
    for i, mass in enumerate(m):
        if not (math.isfinite(mass) and mass > 0.0):
            raise StructureError(f"masses[{i}] must be > 0 kg, got {mass!r}")
    members = tuple(
        Member(i, i + 1, stiffness=float(k[i]), joint=joint_list[i], damping=float(damper_list[i]))
        for i in range(n)
    )
    nodes = -np.arange(n + 1, dtype=np.float64)[:, None]
    return Structure(nodes, np.concatenate(([0.0], m)), members, supports=(0,))


def truss(
    nodes: ArrayLike,
    members: Sequence[Member | Mapping[str, Any] | tuple[int, int]],
    supports: Sequence[int],
    *,
    masses: ArrayLike | float = 1.0,
    stiffness: float | None = None,
    joint: ClearanceJoint | None = None,
    damping: float = 0.0,
    rayleigh: tuple[float, float] = (0.0, 0.0),
) -> Structure:
    """Return a general pin-jointed truss of axial members (1-D, 2-D or 3-D).

    Parameters
    ----------
    nodes : (n_nodes, dim) array_like
        Coordinates, m.
    members : sequence
        Each a :class:`Member`, a mapping of Member's fields, or a pair (start, end) that
        takes ``stiffness``, ``joint`` and ``damping`` below.
    supports : sequence of int
        Fixed nodes.
    masses : float or (n_nodes,) array_like
        Lumped nodal masses, kg.
    stiffness, joint, damping
        Defaults for members given as pairs.
    rayleigh : (alpha, beta)
        Rayleigh damping on M and the closed-pattern K.
    """
    xyz = np.asarray(nodes, dtype=np.float64)
    n_nodes = xyz.shape[0] if xyz.ndim else 0
    mass = np.broadcast_to(np.asarray(masses, dtype=np.float64), (n_nodes,)).copy()
    built: list[Member] = []
    for i, item in enumerate(members):
        if isinstance(item, Member):
            built.append(item)
        elif isinstance(item, Mapping):
            built.append(Member(**item))
        elif isinstance(item, tuple | list) and len(item) == 2:
            if stiffness is None:
                raise StructureError(
                    f"member {i} is a pair of nodes but no default stiffness was given; "
                    "pass stiffness= or give the member as a Member"
                )
            built.append(
                Member(item[0], item[1], stiffness=stiffness, joint=joint, damping=damping)
            )
        else:
            raise StructureError(
                f"member {i} must be a Member, a mapping or a node pair, got {item!r}"
            )
    return Structure(xyz, mass, tuple(built), supports=tuple(supports), rayleigh=rayleigh)


def mast(
    bays: int,
    *,
    width: float = 0.5,
    bay_height: float = 0.5,
    longeron_rigidity: float = 2.0e7,
    batten_rigidity: float = 2.0e7,
    diagonal_rigidity: float = 2.0e7,
    node_mass: float = 0.5,
    tip_mass: float = 0.0,
    joints: ClearanceJoint | Sequence[ClearanceJoint] | None = None,
    member_damping: float = 0.0,
    rayleigh: tuple[float, float] = (0.0, 0.0),
) -> Structure:
    """Return a planar deployable mast: ``bays`` square bays stacked on a clamped base.

    Geometry (2-D, y up, base nodes 0 and 1 supported)::

        2b ---- 2b+1     level b: nodes 2b (left, x = 0) and 2b+1 (right, x = width)
         |  \\    |       longerons: 2(b-1) -> 2b and 2(b-1)+1 -> 2b+1, each with a
         j   \\   j       hinge joint j in series (2 per bay, 2 x bays in all)
         |    \\  |       batten: 2b -> 2b+1 (rigid-jointed, no clearance)
        2b-2 -- 2b-1     diagonal: 2(b-1) -> 2b+1

    Each member's axial stiffness is its rigidity EA (N) over its length. The hinge
    joints sit in the longerons, which carry the mast's bending as axial push and
    pull, so the lateral modes soften with the joints' clearance.

    Parameters
    ----------
    bays : int
        Number of bays, >= 1.
    width, bay_height : float
        m.
    longeron_rigidity, batten_rigidity, diagonal_rigidity : float
        EA of each member family, N.
    node_mass : float
        Lumped mass of every free node, kg (members' own mass included by the user).
    tip_mass : float
        Added to each of the two top nodes, kg.
    joints : ClearanceJoint or sequence of 2 x bays, optional
        The same joint in every longeron, or one per longeron in order (bay 1 left,
        bay 1 right, bay 2 left, ...). Default: no joints (a linear mast).
    member_damping : float
        Dashpot across every member, N s/m.
    rayleigh : (alpha, beta)
        Rayleigh damping.
    """
    if isinstance(bays, bool) or not isinstance(bays, int) or bays < 1:
        raise StructureError(f"bays must be a whole number >= 1, got {bays!r}")
    if joints is None or isinstance(joints, ClearanceJoint):
        hinge: list[ClearanceJoint | None] = [joints] * (2 * bays)
    else:
        hinge = _per_link("joints (one per longeron, 2 x bays)", joints, 2 * bays, None)
    nodes = np.array(
        [[side * width, level * bay_height] for level in range(bays + 1) for side in (0, 1)],
        dtype=np.float64,
    )
    if width <= 0.0 or bay_height <= 0.0:
        raise StructureError("width and bay_height must be > 0 m")
    diagonal = math.hypot(width, bay_height)
    members: list[Member] = []
    for level in range(1, bays + 1):
        lo, hi = 2 * (level - 1), 2 * level
        members.append(
            Member(
                lo,
                hi,
                stiffness=longeron_rigidity / bay_height,
                joint=hinge[2 * (level - 1)],
                damping=member_damping,
            )
        )
        members.append(
            Member(
                lo + 1,
                hi + 1,
                stiffness=longeron_rigidity / bay_height,
                joint=hinge[2 * (level - 1) + 1],
                damping=member_damping,
            )
        )
        members.append(
            Member(hi, hi + 1, stiffness=batten_rigidity / width, damping=member_damping)
        )
        members.append(
            Member(lo, hi + 1, stiffness=diagonal_rigidity / diagonal, damping=member_damping)
        )
    masses = np.full(nodes.shape[0], float(node_mass))
    masses[-2:] += tip_mass
    return Structure(nodes, masses, tuple(members), supports=(0, 1), rayleigh=rayleigh)
