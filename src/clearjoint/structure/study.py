"""A structure study in one TOML file, with units: build, then modes / respond / decay.

A thin reader on :mod:`clearjoint.io_toml`, with its rules: a dimensional value carries its
unit (``"50um"``, ``"5e7N/m"``, ``"15Hz"``); a bare number only where the key names its SI
unit (``clearance_m = 5e-5``, ``masses_kg = [2, 1.5]``, ``dampers_n_s_per_m = [50, 30]``),
the quantity is dimensionless, or it is zero. An unknown section or key is an error.
Example (a 10-bay mast)::

    [structure]
    kind = "mast"            # "mast", "chain" or "truss"
    bays = 10
    width = "0.5m"
    bay_height = "0.5m"
    longeron_rigidity = "2e7N"   # EA
    node_mass = "0.5kg"
    rayleigh_alpha = "0.5/s"     # multiplies M: a rate in 1/s (or rad/s); Hz is refused
    rayleigh_beta = "2e-6s"      # multiplies K: a time

    [joint]                  # the same hinge joint in every longeron (a mast needs one)
    clearance = "50um"
    compression_stiffness = "5e7N/m"
    gap_stiffness = "1e5N/m"

    [excitation]             # for "respond"
    frequency = "15Hz"
    force_dof = "n21x"
    force_amplitude = "20N"
    periods = 50

    [decay]                  # for "decay": deflect along closed mode 1, read its backbone
    dof = "n21x"
    initial_amplitude = "3mm"
    mode = 1
    duration = "1s"

A truss takes ``nodes`` (a list of coordinates, with units), ``members`` (pairs of node
indices), ``supports``, ``member_stiffness``, ``masses`` (one per node, or one for all) and
``joint_members`` (indices of the members that carry the [joint]). A chain takes
``masses``, ``stiffnesses`` (``"inf"`` for a rigid link), ``dampers`` (``"50N*s/m"``) as lists
and ``joints`` as a list of true/false (the [joint] on that link or none). A [joint]
that no member carries is refused, as is friction in it (the structure solver does not
carry Coulomb friction).

A ``[model]`` section instead of ``[structure]`` reads a finite-element model's matrix
files and joints (:mod:`clearjoint.structure.fe.model_file`); its DOF names are the
model's, and a reduced model's forces, decays and watched DOFs are named on the full
model's DOFs too.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.io_toml import UNIT_SUFFIXES, quantity, read_toml
from clearjoint.joint import ClearanceJoint
from clearjoint.structure.builders import chain, mast, truss
from clearjoint.structure.fe.model_file import MODEL_KEYS, model_system
from clearjoint.structure.model import Member, Structure, StructureError, system_modes
from clearjoint.system import VibrationSystem

KEYS: dict[str, dict[str, str]] = {
    "structure": {
        "kind": "text",
        "bays": "count",
        "width": "length",
        "bay_height": "length",
        "longeron_rigidity": "force",
        "batten_rigidity": "force",
        "diagonal_rigidity": "force",
        "node_mass": "mass",
        "tip_mass": "mass",
        "member_damping": "damping",
        "rayleigh_alpha": "rate",
        "rayleigh_beta": "time",
        "masses": "mass list",
        "stiffnesses": "stiffness list",
        "dampers": "damping list",
        "joints": "flag list",
        "nodes": "points",
        "members": "pairs",
        "supports": "index list",
        "member_stiffness": "stiffness",
        "joint_members": "index list",
    },
    "joint": {
        "clearance": "length",
        "compression_stiffness": "stiffness",
        "tension_stiffness": "stiffness",
        "gap_stiffness": "stiffness",
        "gap_offset": "length",
        "restitution": "dimensionless",
        # known so that they are refused with the reason, not as unknown keys:
        "friction_coefficient": "dimensionless",
        "lateral_load": "force",
        "friction_region": "text",
    },
    "excitation": {
        "frequency": "frequency",
        "force_dof": "text",
        "force_amplitude": "force",
        "periods": "count",
    },
    "decay": {
        "dof": "text",
        "initial_amplitude": "length",
        "mode": "count",
        "duration": "time",
    },
    "output": {"samples_per_period": "count"},
    "model": MODEL_KEYS,
}


#: The [structure] keys each kind reads (besides kind and the Rayleigh pair).
KIND_KEYS: dict[str, tuple[str, ...]] = {
    "mast": (
        "bays",
        "width",
        "bay_height",
        "longeron_rigidity",
        "batten_rigidity",
        "diagonal_rigidity",
        "node_mass",
        "tip_mass",
        "member_damping",
    ),
    "chain": ("masses", "stiffnesses", "dampers", "joints"),
    "truss": (
        "nodes",
        "members",
        "supports",
        "member_stiffness",
        "masses",
        "node_mass",
        "joint_members",
        "member_damping",
    ),
}


class StructureStudyError(ClearjointError, ValueError):
    """A structure study file is missing, unreadable or holds a bad value."""


@dataclass(frozen=True)
class StructureStudy:
    """A parsed structure study (SI; omega in rad/s)."""

    structure: Structure | VibrationSystem  # a [model]: its system, reduced if asked
    omega: float | None
    force: np.ndarray | None
    periods: int
    decay_dof: int | None
    decay_initial: np.ndarray | None
    decay_duration: float | None
    samples_per_period: int
    source: str
    decay_mode: int | None = None


def _unit_kind(kind: str) -> str:
    """The kind of quantity each number of ``kind`` is ("mass list" -> "mass")."""
    return "length" if kind == "points" else kind.removesuffix(" list")


def _read_section(where: str, section: str, body: dict[str, Any]) -> dict[str, Any]:
    """Return one [section]'s values in SI, keyed as in KEYS; refuse unknown keys."""
    spec = KEYS[section]
    aliases = {
        f"{key}_{UNIT_SUFFIXES[_unit_kind(kind)]}": key
        for key, kind in spec.items()
        if _unit_kind(kind) in UNIT_SUFFIXES
    }
    out: dict[str, Any] = {}
    for given, raw in body.items():
        key = aliases.get(given, given)
        if key not in spec:
            raise StructureStudyError(
                f"{where}: unknown key {given!r} in [{section}]; keys are {', '.join(spec)}"
            )
        if key in out:
            raise StructureStudyError(
                f"{where}: {key} is given twice ({key} and {given}); keep one"
            )
        name = f"{where}: [{section}] {given}"
        out[key] = _value(name, spec[key], raw, unit_in_key=given in aliases)
    return out


def _value(name: str, kind: str, raw: Any, *, unit_in_key: bool) -> Any:
    if kind in ("points", "pairs"):
        if not isinstance(raw, list) or not all(isinstance(p, list) for p in raw):
            raise StructureStudyError(f"{name} must be a list of lists, got {raw!r}")
        if kind == "pairs":
            if not all(len(p) == 2 and all(isinstance(i, int) for i in p) for p in raw):
                raise StructureStudyError(f"{name} must be pairs of node indices [start, end]")
            return [tuple(p) for p in raw]
        return [[_number(name, "length", v, unit_in_key) for v in p] for p in raw]
    if kind == "joint list":  # checked with the model's DOF names (fe.model_file)
        if not isinstance(raw, list):
            raise StructureStudyError(f"{name} must be a list of joints, got {raw!r}")
        return raw
    if kind == "text list":
        if not isinstance(raw, list) or not all(isinstance(v, str) for v in raw):
            raise StructureStudyError(f"{name} must be a list of names, got {raw!r}")
        return raw
    if kind == "index list":
        if not isinstance(raw, list) or not all(
            isinstance(i, int) and not isinstance(i, bool) for i in raw
        ):
            raise StructureStudyError(f"{name} must be a list of whole numbers, got {raw!r}")
        return raw
    if kind.endswith(" list"):
        if not isinstance(raw, list):
            raise StructureStudyError(f"{name} must be a list, got {raw!r}")
        inner = kind.removesuffix(" list")
        if inner == "flag":
            if not all(isinstance(v, bool) for v in raw):
                raise StructureStudyError(f"{name} must be a list of true/false")
            return raw
        return [_number(name, inner, v, unit_in_key) for v in raw]
    if kind in ("text", "count"):
        return quantity(raw, kind, name=name, error=StructureStudyError)
    return _number(name, kind, raw, unit_in_key)


def _number(name: str, kind: str, raw: Any, unit_in_key: bool) -> float:
    """One number in SI by io_toml's rules; ``"inf"`` (a rigid link) is taken as it is."""
    if isinstance(raw, str) and raw.strip().lower() == "inf":
        return math.inf
    return float(quantity(raw, kind, name=name, error=StructureStudyError, unit_in_key=unit_in_key))


def load_structure_study(path: str | Path) -> StructureStudy:
    """Read and validate a structure study TOML file (see the module docstring)."""
    where = str(path)
    raw = read_toml(path, what="structure study", error=StructureStudyError)
    values: dict[str, dict[str, Any]] = {}
    for section, body in raw.items():
        if section not in KEYS or not isinstance(body, dict):
            raise StructureStudyError(
                f"{where}: unknown section [{section}]; sections are {', '.join(KEYS)}"
            )
        values[section] = _read_section(where, section, body)
    return _build(values, where)


def _build(values: dict[str, dict[str, Any]], where: str) -> StructureStudy:
    joint = _joint(values.get("joint"), where)
    if "model" in values:
        if "structure" in values:
            raise StructureStudyError(
                f"{where}: give [structure] (a model built here) or [model] (matrix files), "
                "not both"
            )
        return _model_study(values, joint, where)
    try:
        structure = _structure(values.get("structure", {}), joint, where)
    except (StructureError, ParameterError) as exc:  # the item and its fix, in the file's words
        raise StructureStudyError(f"{where}: {exc}") from None
    return _structure_tasks(values, structure, where)


def _joint(joint_values: dict[str, Any] | None, where: str) -> ClearanceJoint | None:
    """The [joint] of the study, or None; friction is refused with its reason."""
    if joint_values is None:
        return None
    for key in ("friction_coefficient", "lateral_load", "friction_region"):
        if key in joint_values:
            raise StructureStudyError(
                f"{where}: [joint] {key}: Coulomb friction in a structure's joints is not "
                "carried (a sticking joint is a constraint the exact solver does not hold); "
                "remove it, or study one joint with friction by `clearjoint simulate`"
            )
    for key in ("clearance", "compression_stiffness"):
        if key not in joint_values:
            raise StructureStudyError(f"{where}: [joint] {key} is required")
    try:
        return ClearanceJoint(**joint_values)
    except ParameterError as exc:
        raise StructureStudyError(f"{where}: [joint] {exc}") from None


def _structure(st: dict[str, Any], joint: ClearanceJoint | None, where: str) -> Structure:
    """Build the [structure] with its [joint]; a joint given and never used is refused."""
    kind = st.get("kind", "mast")
    rayleigh = (st.get("rayleigh_alpha", 0.0), st.get("rayleigh_beta", 0.0))
    if kind in KIND_KEYS:
        known = ("kind", "rayleigh_alpha", "rayleigh_beta", *KIND_KEYS[kind])
        other = [key for key in st if key not in known]
        if other:  # read by another kind: it would be dropped without a word
            raise StructureStudyError(
                f"{where}: [structure] {other[0]} is not read for a {kind}; a {kind} takes "
                f"{', '.join(KIND_KEYS[kind])} (and rayleigh_alpha, rayleigh_beta): remove "
                "it or change kind"
            )
    if kind == "mast":
        if "bays" not in st:
            raise StructureStudyError(f"{where}: [structure] bays is required for a mast")
        if joint is None:
            raise StructureStudyError(
                f"{where}: a mast needs a [joint] section (the hinge joint of its longerons, "
                'e.g. clearance = "50um", compression_stiffness = "5e7N/m"); without one it '
                "would have no joints"
            )
        options = {k: st[k] for k in KIND_KEYS["mast"] if k != "bays" and k in st}
        structure = mast(st["bays"], joints=joint, rayleigh=rayleigh, **options)
    elif kind == "chain":
        for key in ("masses", "stiffnesses"):
            if key not in st:
                raise StructureStudyError(f"{where}: [structure] {key} is required for a chain")
        flags = st.get("joints")
        joints = None if flags is None else [joint if f else None for f in flags]
        if flags is not None and any(flags) and joint is None:
            raise StructureStudyError(f"{where}: [structure] joints asks for joints; add [joint]")
        if joint is not None and not (flags and any(flags)):
            raise StructureStudyError(
                f"{where}: [joint] is given but no link carries it; say which do in "
                "[structure], e.g. joints = [true, false], or remove [joint]"
            )
        structure = chain(st["masses"], st["stiffnesses"], joints, st.get("dampers"))
        if rayleigh != (0.0, 0.0):
            structure = replace(structure, rayleigh=rayleigh)
    elif kind == "truss":
        for key in ("nodes", "members", "supports", "member_stiffness"):
            if key not in st:
                raise StructureStudyError(f"{where}: [structure] {key} is required for a truss")
        with_joint = set(st.get("joint_members", []))
        if with_joint and joint is None:
            raise StructureStudyError(f"{where}: [structure] joint_members needs a [joint]")
        if joint is not None and not with_joint:
            raise StructureStudyError(
                f"{where}: [joint] is given but no member carries it; list them in "
                "[structure] joint_members (member indices), or remove [joint]"
            )
        unknown = sorted(i for i in with_joint if not 0 <= i < len(st["members"]))
        if unknown:
            raise StructureStudyError(
                f"{where}: [structure] joint_members names member {unknown[0]}, which does "
                f"not exist (members are 0 to {len(st['members']) - 1})"
            )
        members = [
            Member(
                a,
                b,
                stiffness=st["member_stiffness"],
                joint=joint if i in with_joint else None,
                damping=st.get("member_damping", 0.0),
            )
            for i, (a, b) in enumerate(st["members"])
        ]
        masses = st.get("masses", [st.get("node_mass", 1.0)] * len(st["nodes"]))
        if len(masses) == 1:
            masses = masses * len(st["nodes"])
        structure = truss(st["nodes"], members, st["supports"], masses=masses, rayleigh=rayleigh)
    else:
        raise StructureStudyError(
            f"{where}: [structure] kind must be 'mast', 'chain' or 'truss', got {kind!r}"
        )
    return structure


def _structure_tasks(
    values: dict[str, dict[str, Any]], structure: Structure, where: str
) -> StructureStudy:
    """The [excitation], [decay] and [output] of the study, on its structure."""
    names = structure.dof_names

    def dof_index(section: str, name: str) -> int:
        axes = "xyz"[: structure.dim]
        if name in {f"n{node}{axis}" for node in structure.supports for axis in axes}:
            raise StructureStudyError(
                f"{where}: [{section}] names DOF {name!r} of node {name[1:-1]}, a support "
                f"(fixed); give a DOF of a free node: {', '.join(names[:3])} ... {names[-1]}"
            )
        if name not in names:
            raise StructureStudyError(
                f"{where}: [{section}] names DOF {name!r}, which does not exist; "
                f"DOFs are {', '.join(names[:3])} ... {names[-1]}"
            )
        return names.index(name)

    closed = structure.modes("closed") if values.get("decay") else None
    return _tasks(values, where, structure, names, dof_index, closed)


def _tasks(
    values: dict[str, dict[str, Any]],
    where: str,
    system: Structure | VibrationSystem,
    names: Sequence[str],
    dof_index: Callable[[str, str], int],
    closed: Any,
    reduced: Any = None,
) -> StructureStudy:
    """The [excitation], [decay] and [output] of a study, on its structure or model.

    ``names`` and ``dof_index`` are the DOFs a study names (a model's full DOFs);
    ``closed`` is ``system``'s closed modes (None without a [decay] section). With
    ``reduced`` (a ReducedSystem) the force is projected onto it (``project_force``) and
    the decay starts along its closed mode, scaled so that the named DOF (through
    ``expand``) moves by initial_amplitude.
    """
    ex = values.get("excitation", {})
    omega = force = None
    if ex:
        for key in ("frequency", "force_dof", "force_amplitude"):
            if key not in ex:
                raise StructureStudyError(f"{where}: [excitation] {key} is required")
        if not (math.isfinite(ex["frequency"]) and ex["frequency"] > 0.0):
            raise StructureStudyError(
                f"{where}: [excitation] frequency must be finite and > 0, got "
                f'{ex["frequency"]:g} Hz; e.g. frequency = "15Hz"'
            )
        if ex.get("periods", 20) < 1:
            raise StructureStudyError(
                f"{where}: [excitation] periods must be at least 1, got {ex['periods']}"
            )
        omega = 2.0 * math.pi * ex["frequency"]
        force = np.zeros(len(names))
        force[dof_index("excitation", ex["force_dof"])] = ex["force_amplitude"]
        if reduced is not None:
            force = reduced.project_force(force)
    de = values.get("decay", {})
    decay_dof = initial = duration = mode = None
    if de:
        for key in ("dof", "initial_amplitude", "duration"):
            if key not in de:
                raise StructureStudyError(f"{where}: [decay] {key} is required")
        decay_dof = dof_index("decay", de["dof"])
        mode = de.get("mode", 1)
        if not 1 <= mode <= closed.shapes.shape[1]:
            raise StructureStudyError(
                f"{where}: [decay] mode must be 1 to {closed.shapes.shape[1]} (the closed "
                f"modes, lowest first), got {mode}"
            )
        if not (math.isfinite(de["initial_amplitude"]) and de["initial_amplitude"] != 0.0):
            raise StructureStudyError(
                f"{where}: [decay] initial_amplitude must be finite and not 0 (a decay needs a "
                f'deflection), got {de["initial_amplitude"]:g} m; e.g. initial_amplitude = "3mm"'
            )
        if not (math.isfinite(de["duration"]) and de["duration"] > 0.0):
            raise StructureStudyError(
                f"{where}: [decay] duration must be finite and > 0, got {de['duration']:g} s"
            )
        shape = closed.shapes[:, mode - 1]
        moved = reduced.expand(shape)[decay_dof] if reduced is not None else shape[decay_dof]
        if moved == 0.0:
            raise StructureStudyError(
                f"{where}: [decay] mode {mode} does not move {de['dof']}; "
                "choose another dof or mode"
            )
        initial = de["initial_amplitude"] * shape / moved
        if reduced is not None:  # the reduced model's own coordinate that moves most
            decay_dof = int(np.argmax(np.abs(shape)))
        duration = de["duration"]
    samples = values.get("output", {}).get("samples_per_period", 64)
    if samples < 8:  # time_response would refuse it without naming the file and section
        raise StructureStudyError(
            f"{where}: [output] samples_per_period must be at least 8, got {samples}"
        )
    return StructureStudy(
        structure=system,
        omega=omega,
        force=force,
        periods=ex.get("periods", 20),
        decay_dof=decay_dof,
        decay_initial=initial,
        decay_duration=duration,
        samples_per_period=samples,
        source=where,
        decay_mode=mode,
    )


def _model_study(
    values: dict[str, dict[str, Any]], joint: ClearanceJoint | None, where: str
) -> StructureStudy:
    """A study of a [model]: its system (reduced if asked), force and decay on its DOFs.

    The DOFs named in [excitation] and [decay] are the full model's; on a reduced model
    they are kept on the boundary, the force is projected (``project_force``) and the
    decay starts along the reduced model's closed mode (its modal coordinate q_mode,
    scaled so the named DOF moves by initial_amplitude).
    """
    from clearjoint.structure.fe.reduction import ReducedSystem

    ex, de = values.get("excitation", {}), values.get("decay", {})
    watched = tuple(d for d in (ex.get("force_dof"), de.get("dof")) if isinstance(d, str))
    try:
        system = model_system(values["model"], joint, Path(where).parent, keep=watched)
    except (ClearjointError, ValueError) as exc:
        raise StructureStudyError(f"{where}: {exc}") from None
    full = system.full if isinstance(system, ReducedSystem) else system
    assert full is not None
    names = full.dof_names

    def dof_index(section: str, name: str) -> int:
        if name not in names:
            raise StructureStudyError(
                f"{where}: [{section}] names DOF {name!r}, which does not exist; "
                f"DOFs are {', '.join(names[:3])} ... {names[-1]}"
            )
        return names.index(name)

    reduced = system if isinstance(system, ReducedSystem) else None
    closed = system_modes(system, "closed") if de else None
    return _tasks(values, where, system, names, dof_index, closed, reduced)


def read_model(path: str | Path) -> VibrationSystem:
    """Return the system of a model TOML (a structure study with a ``[model]`` section).

    The matrices read, the joints added, reduced if the file asks for it
    (:mod:`clearjoint.structure.fe.model_file`); the study's other sections are checked too.

    Raises
    ------
    StructureStudyError
        The file, a matrix file, a joint or a value is bad (one line naming it).
    """
    study = load_structure_study(path)
    if not isinstance(study.structure, VibrationSystem):
        raise StructureStudyError(
            f"{path}: read_model reads a [model] section (matrix files and joints); this file "
            "builds a [structure]: use load_structure_study"
        )
    return study.structure
