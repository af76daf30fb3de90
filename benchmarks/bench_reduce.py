"""Craig-Bampton reduction of large sparse models onto two joints (issue 26).

Run on demand: ``python benchmarks/bench_reduce.py [N ...]`` (default N = 20000 100000
DOFs). Each model is a 3-D spring lattice (a square mast section of 4 x 4 nodes with
springs along the three axes and the face diagonals, lumped masses, clamped at its
foot) with two clearance joints along z between facing nodes at mid-height. It is
reduced onto the two joints with 50 fixed-interface modes; the time of ``from_matrices``
(with its checks), of ``reduce`` and of ``check(5)`` (the full model's five closed and
open modes by sparse shift-invert) are printed, with the check's worst relative error.
Target: the 20,000-DOF reduction in under 60 s on 2 cores.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import scipy.sparse

from clearjoint import ClearanceJoint
from clearjoint.structure import from_matrices, reduce

SECTION = 4  # nodes per side of the square section
SPACING, K_AXIS, K_DIAGONAL, NODE_MASS = 0.1, 2e7, 5e6, 0.05  # m, N/m, N/m, kg


def lattice(n_dof: int) -> tuple[scipy.sparse.csr_matrix, scipy.sparse.csr_matrix, int]:
    """M, K (sparse) of a clamped square lattice mast of about ``n_dof`` DOFs, and its layers."""
    layers = max(4, round(n_dof / (3 * SECTION * SECTION)) + 1)
    ix, iy, iz = np.meshgrid(
        np.arange(SECTION), np.arange(SECTION), np.arange(layers), indexing="ij"
    )
    # node numbers layer by layer (z slowest), so a layer's DOFs are contiguous
    node = np.arange(ix.size).reshape(layers, SECTION, SECTION).transpose(1, 2, 0)
    xyz = np.zeros((ix.size, 3))
    xyz[node.ravel()] = np.stack((ix, iy, iz), axis=-1).reshape(-1, 3) * SPACING
    pairs = []
    for step in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 0), (-1, 0, 1)):
        a = node[
            max(0, -step[0]) : SECTION - max(0, step[0]),
            max(0, -step[1]) : SECTION - max(0, step[1]),
            : layers - step[2],
        ]
        b = node[
            max(0, step[0]) : SECTION + min(0, step[0]),
            max(0, step[1]) : SECTION + min(0, step[1]),
            step[2] :,
        ]
        stiff = K_AXIS if sum(map(abs, step)) == 1 else K_DIAGONAL
        pairs.append((a.ravel(), b.ravel(), stiff))
    rows, cols, vals = [], [], []
    for a, b, stiff in pairs:
        e = xyz[b] - xyz[a]
        e /= np.linalg.norm(e, axis=1)[:, None]
        block = stiff * e[:, :, None] * e[:, None, :]  # (n, 3, 3)
        for p, q, sign in ((a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)):
            r = 3 * p[:, None, None] + np.arange(3)[None, :, None]
            c = 3 * q[:, None, None] + np.arange(3)[None, None, :]
            rows.append(np.broadcast_to(r, block.shape).ravel())
            cols.append(np.broadcast_to(c, block.shape).ravel())
            vals.append(sign * block.ravel())
    n_all = 3 * node.size
    k = scipy.sparse.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n_all, n_all)
    ).tocsr()
    free = np.flatnonzero(np.repeat(xyz[:, 2] > 0.0, 3))  # the foot layer clamped
    k = k[free][:, free].tocsr()
    m = scipy.sparse.identity(free.size, format="csr") * NODE_MASS
    return m, k, layers


def main(sizes: list[int]) -> None:
    law = ClearanceJoint(0.1e-3, 1e7, gap_stiffness=1e4)
    for n_dof in sizes:
        m, k, layers = lattice(n_dof)
        n = m.shape[0]
        middle = layers // 2
        per_layer = 3 * SECTION * SECTION

        def dofs(corner: int, layer: int, per_layer: int = per_layer) -> list[int]:
            """x, y, z DOFs of a node of the section's first row in a layer (>= 1)."""
            first = per_layer * (layer - 1) + 3 * corner  # layer 0 is clamped
            return [first, first + 1, first + 2]

        joints = [
            (dofs(0, middle), dofs(0, middle + 1), [0.0, 0.0, 1.0], law),
            (dofs(SECTION - 1, middle), dofs(SECTION - 1, middle + 1), [0.0, 0.0, 1.0], law),
        ]
        t0 = time.perf_counter()
        system = from_matrices(m, k, joints=joints)
        t1 = time.perf_counter()
        reduced = reduce(system, modes=50)
        t2 = time.perf_counter()
        check = reduced.check(5)
        t3 = time.perf_counter()
        print(
            f"{n:7d} DOF ({k.nnz} nonzeros): from_matrices {t1 - t0:6.2f} s, reduce onto 2 joints "
            f"with 50 modes {t2 - t1:6.2f} s, check(5) {t3 - t2:6.2f} s; {reduced!r}; "
            f"worst check error {check.worst:.2g}"
        )
    print("(wall-clock times on a shared machine: other sessions load it)")


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [20_000, 100_000])
