"""A 3-D deployable mast built in OpenSees, written as Matrix Market files for clearjoint.

Run from the repository: ``python examples/opensees_mast.py`` (needs the extra
``opensees``: ``pip install 'clearjoint[opensees]'``). It

1. builds a 20-bay triangular mast (side 0.4 m, bays 0.5 m; longerons, battens and
   diagonals as 3-D elastic frame elements, carbon-fibre tubes; lumped masses) clamped
   at its foot, with a hinge in each of the three longerons at mid-height: two
   coincident nodes tied by ``equalDOF`` in every direction but the longeron's axis;
2. pulls its M, C, K with :func:`clearjoint.structure.from_opensees`, clearance joints
   along z between the hinge nodes, and checks the linear modes with every joint closed
   against OpenSees's own ``eigen`` of the same mast with the hinges closed by
   ``zeroLength`` springs (k0 + k_c);
3. writes ``examples/opensees_mast/M.mtx``, ``K.mtx`` (Matrix Market), ``dofs.txt`` (the
   DOF names) and ``nodes.csv`` (node coordinates, for drawing), which
   ``examples/opensees_mast.toml`` reads: ``clearjoint structure
   examples/opensees_mast.toml modes --out modes.nc`` (docs/fe_models.md).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import scipy.io
import scipy.sparse

from clearjoint import ClearanceJoint
from clearjoint.structure import from_opensees
from clearjoint.structure.model import system_modes

OUT = Path(__file__).resolve().parent / "opensees_mast"
BAYS, SIDE, BAY = 20, 0.4, 0.5  # -, m, m
HINGE_LEVEL = BAYS // 2
E, G = 1.0e11, 4.0e10  # Pa: a carbon-fibre tube
TUBE = {"A": 1.2e-4, "J": 2.0e-8, "Iy": 1.0e-8, "Iz": 1.0e-8}  # m^2, m^4
NODE_MASS, NODE_INERTIA = 0.25, 1.0e-4  # kg, kg m^2
#: The hinges' law: the same as examples/opensees_mast.toml's [joint].
HINGE = ClearanceJoint(50e-6, 2e7, gap_stiffness=2e5)


def build(closed_hinges: float | None = None) -> list[tuple[str, str]]:
    """Define the mast in OpenSees; return the hinge DOF pairs (lower node, upper node).

    With ``closed_hinges`` (N/m) the hinges are closed by zeroLength springs of that
    stiffness along z (OpenSees's own reference); without, they are left to clearjoint.
    """
    import openseespy.opensees as ops

    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    corners = [
        (SIDE * math.cos(a), SIDE * math.sin(a))
        for a in (math.pi / 2 + 2 * math.pi * k / 3 for k in range(3))
    ]
    scale = SIDE / math.dist(corners[0], corners[1])
    corners = [(x * scale, y * scale) for x, y in corners]

    def tag(level: int, corner: int) -> int:
        return 100 * level + corner + 1

    for level in range(BAYS + 1):
        for c, (x, y) in enumerate(corners):
            ops.node(tag(level, c), x, y, level * BAY)
            if level == 0:
                ops.fix(tag(level, c), 1, 1, 1, 1, 1, 1)
            else:
                ops.mass(tag(level, c), *[NODE_MASS] * 3, *[NODE_INERTIA] * 3)
    hinges = []
    for c, (x, y) in enumerate(corners):  # the upper half of each hinge: its own node
        upper = 10_000 + c + 1
        ops.node(upper, x, y, HINGE_LEVEL * BAY)
        ops.mass(upper, *[NODE_MASS] * 3, *[NODE_INERTIA] * 3)
        ops.equalDOF(tag(HINGE_LEVEL, c), upper, 1, 2, 4, 5, 6)
        hinges.append((f"n{tag(HINGE_LEVEL, c)}d3", f"n{upper}d3"))
    ops.geomTransf("Linear", 1, 1.0, 0.0, 0.0)  # vertical members
    ops.geomTransf("Linear", 2, 0.0, 0.0, 1.0)  # battens and diagonals
    section = (TUBE["A"], E, G, TUBE["J"], TUBE["Iy"], TUBE["Iz"])
    element = 0

    def frame(a: int, b: int, transf: int) -> None:
        nonlocal element
        element += 1
        ops.element("elasticBeamColumn", element, a, b, *section, transf)

    for level in range(BAYS):
        for c in range(3):
            # a longeron leaving the hinge level starts at the hinge's upper node
            start = 10_000 + c + 1 if level == HINGE_LEVEL else tag(level, c)
            frame(start, tag(level + 1, c), 1)
            # a face diagonal from this corner at this level to the next corner above
            frame(tag(level, c), tag(level + 1, (c + 1) % 3), 2)
    for level in range(1, BAYS + 1):
        for c in range(3):
            frame(tag(level, c), tag(level, (c + 1) % 3), 2)
    if closed_hinges is not None:
        ops.uniaxialMaterial("Elastic", 1, closed_hinges)
        for c in range(3):
            lower, upper = tag(HINGE_LEVEL, c), 10_000 + c + 1
            ops.element("zeroLength", 90_000 + c, lower, upper, "-mat", 1, "-dir", 3)
    return hinges


def main() -> None:
    import openseespy.opensees as ops

    closed = HINGE.gap_stiffness + HINGE.compression_stiffness
    build(closed)
    reference = np.sqrt(ops.eigen("-fullGenLapack", 6))
    hinges = build()
    system = from_opensees(joints=[(a, b, HINGE) for a, b in hinges])
    coordinates = {}
    for tag in ops.getNodeTags():
        coordinates[int(tag)] = ops.nodeCoord(tag)
    ops.wipe()
    mine = system_modes(system).omega[:6]
    worst = float(np.max(np.abs(mine / reference - 1.0)))
    print(f"{system!r}: closed modes {np.round(mine / (2 * math.pi), 3)} Hz")
    print(f"OpenSees eigen with zeroLength hinges: worst relative difference {worst:.1e}")
    assert worst < 1e-6, worst
    OUT.mkdir(exist_ok=True)
    for name, matrix in (("M", system.mass), ("K", system.stiffness)):
        scipy.io.mmwrite(
            str(OUT / f"{name}.mtx"),
            scipy.sparse.coo_matrix(matrix),
            comment=f"clearjoint examples/opensees_mast.py: {BAYS}-bay mast, {name}",
            symmetry="symmetric",
            precision=12,
        )
    (OUT / "dofs.txt").write_text("\n".join(system.dof_names) + "\n")
    rows = [f"{t},{x:.6g},{y:.6g},{z:.6g}" for t, (x, y, z) in sorted(coordinates.items())]
    (OUT / "nodes.csv").write_text("node,x_m,y_m,z_m\n" + "\n".join(rows) + "\n")
    print(f"wrote {OUT}/M.mtx, K.mtx, dofs.txt, nodes.csv")


if __name__ == "__main__":
    main()
