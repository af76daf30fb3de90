"""A model TOML: the structure study's ``[model]`` section names matrix files and joints.

:func:`clearjoint.structure.read_model` (in :mod:`clearjoint.structure.study`, the
study reader) returns the system of such a file; :func:`model_system` builds it from
the section's values.

Example (the matrices of a mast written by its finite-element program)::

    [model]
    mass = "mast_M.mtx"            # paths relative to this file
    stiffness = "mast_K.mtx"
    damping = "mast_C.mtx"         # optional; or rayleigh_alpha / rayleigh_beta
    dof_names = "mast_dofs.txt"    # optional: one name a line (an Abaqus file names its own)
    joints = [["n41z", "n42z"], ["n44z", "n45z"]]   # pairs of DOFs; "ground" for none
    reduce_modes = 40              # optional Craig-Bampton onto the joints (and keep)
    keep = ["n80x"]                # extra boundary DOFs (the forced DOF is kept anyway)

    [joint]                        # the law of every joint, as in any structure study
    clearance = "50um"
    compression_stiffness = "5e7N/m"

    [excitation]                   # force_dof names a DOF of the full model
    frequency = "12Hz"
    force_dof = "n80x"
    force_amplitude = "5N"

A joint along a direction between two nodes is an inline table:
``{a = ["n41x", "n41y", "n41z"], b = ["n42x", "n42y", "n42z"], direction = [0, 0, 1]}``.
Matrix files are read by :func:`~clearjoint.structure.fe.readers.read_matrix` (format
sniffed; ``format``, ``mass_key``, ``stiffness_key``, ``damping_key`` when needed).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from clearjoint.joint import ClearanceJoint
from clearjoint.structure.fe.matrices import FEModelError, from_matrices
from clearjoint.structure.fe.readers import read_matrix
from clearjoint.structure.fe.reduction import reduce
from clearjoint.system import VibrationSystem

#: The [model] keys and the kind of each value (io_toml's kinds).
MODEL_KEYS: dict[str, str] = {
    "mass": "text",
    "stiffness": "text",
    "damping": "text",
    "format": "text",
    "mass_key": "text",
    "stiffness_key": "text",
    "damping_key": "text",
    "dof_names": "text",
    "joints": "joint list",
    "rayleigh_alpha": "rate",
    "rayleigh_beta": "time",
    "reduce_modes": "count",
    "reduce_cutoff": "frequency",
    "keep": "text list",
}


def _joint_spec(index: int, raw: Any, law: ClearanceJoint) -> tuple[Any, ...]:
    name = f"[model] joints[{index}]"
    if isinstance(raw, list) and len(raw) == 2 and all(isinstance(s, str) for s in raw):
        b = None if raw[1].lower() == "ground" else raw[1]
        return (raw[0], b, law)
    if isinstance(raw, dict) and set(raw) <= {"a", "b", "direction"} and "a" in raw:
        b = raw.get("b", "ground")
        return (raw["a"], None if b == "ground" else b, raw.get("direction"), law)
    raise FEModelError(
        f'{name} must be a pair of DOF names ["n41z", "n42z"] ("ground" for none) or '
        "{a = [...], b = [...], direction = [x, y, z]}, got " + repr(raw)
    )


def model_system(
    model: dict[str, Any],
    joint: ClearanceJoint | None,
    folder: Path,
    *,
    keep: tuple[str, ...] = (),
) -> VibrationSystem:
    """Build the [model] of a study: read its matrices, add its joints, reduce if asked.

    ``model`` holds the section's values in SI (the study reader's); ``keep`` the DOFs
    the study forces or watches, kept on a reduction's boundary.

    Raises
    ------
    FEModelError
        A missing key, an unreadable file, a bad joint or DOF (one line naming it).
    """
    for key in ("mass", "stiffness", "joints"):
        if key not in model:
            raise FEModelError(f"[model] {key} is required")
    if joint is None:
        raise FEModelError(
            'a [model] needs a [joint] section (its joints\' law, e.g. clearance = "50um", '
            'compression_stiffness = "5e7N/m")'
        )
    fmt = model.get("format")
    matrices: dict[str, Any] = {}
    names: tuple[str, ...] | None = None
    for kind in ("mass", "stiffness", "damping"):
        if kind in model:
            matrix, found = read_matrix(
                folder / model[kind], kind, key=model.get(f"{kind}_key"), format=fmt
            )
            matrices[kind] = matrix
            names = names or found
    if "dof_names" in model:
        path = folder / model["dof_names"]
        if not path.is_file():
            raise FEModelError(f"[model] dof_names: no such file {path}")
        names = tuple(s.strip() for s in path.read_text().splitlines() if s.strip())
    specs = [_joint_spec(i, raw, joint) for i, raw in enumerate(model["joints"])]
    rayleigh = None
    if "rayleigh_alpha" in model or "rayleigh_beta" in model:
        rayleigh = (model.get("rayleigh_alpha", 0.0), model.get("rayleigh_beta", 0.0))
    system = from_matrices(
        matrices["mass"],
        matrices["stiffness"],
        damping=matrices.get("damping"),
        rayleigh=rayleigh,
        joints=specs,
        dof_names=names,
    )
    if "reduce_modes" in model or "reduce_cutoff" in model:
        return reduce(
            system,
            modes=model.get("reduce_modes"),
            cutoff_hz=model.get("reduce_cutoff"),
            keep=(*model.get("keep", ()), *keep),
        )
    return system


__all__ = ["MODEL_KEYS", "model_system"]
