"""The matrices of the model defined in OpenSees (``openseespy``, the extra ``opensees``).

OpenSees forms its own M, C and K: with the ``GimmeMCK`` integrator the system matrix
it assembles is A = m M + c C + k K, so one step with (1, 0, 0), (0, 1, 0) and
(0, 0, 1) and ``printA`` gives each of them (a ``FullGeneral`` system, the ``Plain``
numberer, the ``Transformation`` constraint handler so that ``fix`` and ``equalDOF``
both hold). ``nodeDOFs`` maps each node's DOFs to the equations (a DOF tied to another
node's by ``equalDOF`` is that node's equation, named after it); the DOF of node 12's
third direction is named ``"n12d3"``. The analysis is wiped before and after; the
model (nodes, elements, masses, constraints) is left as it was. OpenSees's rayleigh
damping, if any, comes in C.
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np
import scipy.sparse

from clearjoint.structure.fe.matrices import FEModelError, from_matrices
from clearjoint.system import SPARSE_ABOVE, VibrationSystem


def _opensees() -> Any:
    try:
        import openseespy.opensees as ops
    except ImportError as exc:
        raise FEModelError(
            f"from_opensees needs openseespy: pip install 'clearjoint[opensees]' (and on "
            f"Linux Debian's libblas3 liblapack3); the import said: {exc}"
        ) from None
    return ops


@contextlib.contextmanager
def _captured_stderr() -> Iterator[list[str]]:
    """Hold OpenSees's C++ messages (file descriptor 2) back; the list gets their text.

    Forming C = 0 or a singular M makes OpenSees's solve fail and say so, although the
    matrix asked for is formed: those lines are noise to the user, kept for an error.
    """
    said: list[str] = []
    with tempfile.TemporaryFile(mode="w+b") as sink:
        saved = os.dup(2)
        os.dup2(sink.fileno(), 2)
        try:
            yield said
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            said.append(sink.read().decode(errors="replace"))


def opensees_matrices() -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str], np.ndarray]:
    """M, C, K (dense, equation order), DOF names and node coordinates of the OpenSees model.

    Raises
    ------
    FEModelError
        openseespy missing, no model defined, or OpenSees failing to form a matrix.
    """
    ops = _opensees()
    tags = list(ops.getNodeTags())
    if not tags:
        raise FEModelError("no OpenSees model is defined: define nodes and elements first")
    ops.wipeAnalysis()
    ops.numberer("Plain")
    ops.constraints("Transformation")
    ops.system("FullGeneral")
    ops.algorithm("Linear")
    ops.test("NormUnbalance", 1e300, 1)  # one step: no convergence test to fail
    matrices = []
    try:
        with _captured_stderr() as said:
            try:
                for factors in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)):
                    ops.integrator("GimmeMCK", *factors)
                    ops.analysis("Transient")
                    ops.analyze(1, 0.0)  # forms A; a singular A fails to solve, but is formed
                    matrices.append(np.asarray(ops.printA("-ret"), dtype=np.float64))
            except Exception as exc:  # OpenSeesError: its text went to the held stderr
                failure: Exception | None = exc
            else:
                failure = None
        if failure is not None:
            last = [s for s in "".join(said).splitlines() if s.strip()][-1:] or [str(failure)]
            raise FEModelError(f"OpenSees could not form the model's matrices: {last[0]}")
        n = math.isqrt(matrices[2].size)
        names: list[str | None] = [None] * n
        xyz = np.zeros((n, 3))
        # a node tied by equalDOF lists its own free DOFs' equations first, then its
        # retained node's: only those first ones are its own
        tied = {int(c): set(ops.getConstrainedDOFs(int(c))) for c in ops.getConstrainedNodes()}
        for tag in tags:
            coord = np.asarray(ops.nodeCoord(tag), dtype=np.float64)
            equations = list(ops.nodeDOFs(tag))
            own = [d for d in range(1, len(equations) + 1) if d not in tied.get(tag, set())]
            for d, eq in zip(own, equations, strict=False):
                if 0 <= eq < n:
                    names[eq] = f"n{tag}d{d}"
                    xyz[eq, : coord.size] = coord
    finally:
        ops.wipeAnalysis()
    if any(name is None for name in names) or any(a.size != n * n for a in matrices):
        raise FEModelError(
            "OpenSees's equations do not map one to one onto node DOFs (a constraint handler "
            "that adds equations?); use fix and equalDOF constraints only"
        )
    m, c, k = (a.reshape(n, n) for a in matrices)
    return m, c, k, [str(s) for s in names], xyz


def from_opensees(
    *,
    joints: Sequence[Any] = (),
    rayleigh: tuple[Any, Any] | None = None,
) -> VibrationSystem:
    """Return the vibration system of the model currently defined in OpenSees.

    M, C, K pulled from OpenSees (module docstring), then
    :func:`~clearjoint.structure.from_matrices` with the ``joints`` (DOF names such as
    ``"n12d3"``, node 12 along its third DOF, or indices) and ``rayleigh`` added.
    Sparse above ``SPARSE_ABOVE`` DOFs. The node coordinates are kept in the system's
    ``source.coordinates``.

    Raises
    ------
    FEModelError
        openseespy not installed, no model, a joint on a DOF OpenSees does not have.
    """
    m, c, k, names, xyz = opensees_matrices()
    c = 0.5 * (c + c.T)
    if len(names) > SPARSE_ABOVE:
        m, c, k = (scipy.sparse.csr_matrix(a) for a in (m, c, k))
    return from_matrices(
        m,
        k,
        damping=c,
        rayleigh=rayleigh,
        joints=joints,
        dof_names=names,
        coordinates=xyz,
    )
