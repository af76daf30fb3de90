"""A study with values given beside it (command-line options, a sweep's point) merged over it.

Values are keyed as in the study file (``"joint.clearance"``, ``"losses.lateral_load"``,
``"pin.radius"``, ``"excitation.frequency"``), already in SI (text for
``"losses.friction_region"``); a key that is absent keeps the study's value, or the
default of :data:`clearjoint.studies.DEFAULT_STUDY` when there is no study. ``names``
says how the caller spells each key in its errors (``{"joint.mass": "--mass"}`` for the
command line); a key it leaves out is named as it is. The rules of
:mod:`clearjoint.studies.rules` apply as in a study file: a hole left to its default
follows the clearance and the pin radius, a symmetric joint's k_t follows k_c.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from clearjoint.errors import ParameterError
from clearjoint.joint import Friction, Joint, Losses, Pin
from clearjoint.structure.model import Structure
from clearjoint.structure.study import StructureStudy
from clearjoint.studies.joint_study import DEFAULT_STUDY, Study
from clearjoint.studies.rules import hole_radius, is_default_hole, tension_follows

__all__ = [
    "JOINT_FIELDS",
    "PIN_FIELDS",
    "joint_at",
    "losses_at",
    "pin_at",
    "structure_at",
    "study_at",
]

#: The fields of a Joint a value may set, in the order a missing one is reported.
JOINT_FIELDS = (
    "mass",
    "clearance",
    "compression_stiffness",
    "tension_stiffness",
    "gap_stiffness",
    "gap_offset",
)
#: The Pin fields a value may set (keys "pin.<field>").
PIN_FIELDS = ("radius", "length", "hole_radius", "youngs_modulus", "poisson_ratio")

Values = Mapping[str, Any]


def _namer(names: Mapping[str, str] | None) -> Any:
    return lambda key: (names or {}).get(key, key)


def joint_at(base: Joint | None, values: Values, names: Mapping[str, str] | None = None) -> Joint:
    """Return the joint of ``values`` over the ``base`` joint (MODEL.md sec. 1).

    Without a base, mass, clearance and compression stiffness must be given. A tension
    stiffness the base left equal to the compression one follows a new k_c; one set on
    its own is kept unless given.

    Raises
    ------
    ParameterError
        A required value is missing (named as in ``names``), or the joint is invalid.
    """
    name = _namer(names)
    fields: dict[str, float] = {}
    for field in JOINT_FIELDS:
        value = values.get(f"joint.{field}")
        if value is None and base is not None:
            value = getattr(base, field)
        if value is None and field in ("mass", "clearance", "compression_stiffness"):
            key = name(f"joint.{field}")
            raise ParameterError(f"{key} is missing: give {key} or put it in the study file")
        if value is not None:
            fields[field] = value
    if values.get("joint.tension_stiffness") is None and tension_follows(base):
        fields["tension_stiffness"] = fields["compression_stiffness"]
    return Joint(**fields)


def pin_at(
    base: Study | None, clearance: float, values: Values, names: Mapping[str, str] | None = None
) -> Pin | None:
    """Return the pin of ``values`` over the study's pin, for a joint of ``clearance``; or None.

    A hole the study left at its default R_p + c/2 (MODEL.md eq 13) follows a new pin
    radius or clearance; E and nu default to :data:`DEFAULT_STUDY`'s steel.

    Raises
    ------
    ParameterError
        A pin without its radius or length.
    """
    name = _namer(names)
    base_pin = base.pin if base is not None else None
    given = any(values.get(f"pin.{field}") is not None for field in PIN_FIELDS)
    if not given and (base_pin is None or values.get("joint.clearance") is None):
        return base_pin
    defaults = DEFAULT_STUDY["pin"]

    def value(field: str) -> float:
        number = values.get(f"pin.{field}")
        if number is None:
            number = getattr(base_pin, field) if base_pin is not None else defaults[field][0]
        if number is None:
            raise ParameterError(
                f"{name(f'pin.{field}')} is missing: a pin needs {name('pin.radius')} and "
                f"{name('pin.length')} (or a [pin] table in the study file)"
            )
        return float(number)

    radius, length = value("radius"), value("length")
    hole = values.get("pin.hole_radius")
    if hole is None:
        default_hole = (
            base is not None
            and base_pin is not None
            and is_default_hole(base_pin.radius, base_pin.hole_radius, base.joint.clearance)
        )
        hole = (
            base_pin.hole_radius
            if base_pin and not default_hole
            else hole_radius(radius, clearance)
        )
    return Pin(
        radius=radius,
        hole_radius=hole,
        length=length,
        youngs_modulus=value("youngs_modulus"),
        poisson_ratio=value("poisson_ratio"),
    )


def losses_at(
    base: Study | None, joint: Joint, values: Values, names: Mapping[str, str] | None = None
) -> Losses:
    """Return the losses of ``values`` over the study's, for ``joint`` (MODEL.md sec. 2).

    Sliding friction needs both mu_s and P: one given alone, where the study has no
    friction, is refused (it would be no force), as is a friction region without
    friction and a pin-contact coefficient without a pin.

    Raises
    ------
    ParameterError
        One of the refusals above, named as in ``names``.
    """
    name = _namer(names)
    old = base.losses if base is not None else Losses()
    friction = old.friction

    def number(key: str, default: float) -> float:
        value = values.get(f"losses.{key}")
        return default if value is None else float(value)

    mu_s = number("friction_coefficient", friction.coefficient if friction else 0)
    load = number("lateral_load", friction.lateral_load if friction else 0.0)
    region = values.get("losses.friction_region") or (
        friction.region if friction else DEFAULT_STUDY["losses"]["friction_region"][0]
    )
    pin = pin_at(base, joint.clearance, values, names)
    if friction is None:  # neither the study nor the values gave both: one alone is no force
        for given, key, other, example in (
            (mu_s, "losses.friction_coefficient", "losses.lateral_load", "300N"),
            (load, "losses.lateral_load", "losses.friction_coefficient", "0.2"),
        ):
            if given != 0.0 and values.get(other) is None:
                raise ParameterError(
                    f"{name(key)} needs {name(other)} too (e.g. {name(other)} {example}): "
                    "without it there is no sliding friction"
                )
    sliding = None
    if mu_s != 0.0 or load != 0.0:
        sliding = Friction(mu_s, load, region)  # validates the signs
        sliding = sliding if sliding.force > 0.0 else None
    if values.get("losses.friction_region") and sliding is None:
        raise ParameterError(
            f"{name('losses.friction_region')} needs sliding friction: give "
            f"{name('losses.friction_coefficient')} and {name('losses.lateral_load')} "
            "(or put them in the study file)"
        )
    mu_c = number("contact_friction_coefficient", old.contact_friction_coefficient)
    if mu_c > 0.0 and pin is None:
        raise ParameterError(
            f"{name('losses.contact_friction_coefficient')} acts on the pin: give "
            f"{name('pin.radius')} and {name('pin.length')} (or a [pin] table in the study file)"
        )
    return Losses(
        damping_ratio=number("damping_ratio", old.damping_ratio),
        friction=sliding,
        restitution=number("restitution", old.restitution),
        pin=pin,
        contact_friction_coefficient=mu_c,
    )


def study_at(study: Study, values: Values, names: Mapping[str, str] | None = None) -> Study:
    """Return the joint study with ``values`` merged over it (see the module docstring).

    ``excitation.frequency`` is in Hz, ``excitation.force_amplitude`` in N.

    Raises
    ------
    ParameterError
        As :func:`joint_at` and :func:`losses_at`.
    """
    joint = joint_at(study.joint, values, names)
    losses = losses_at(study, joint, values, names)
    omega = study.omega
    if "excitation.frequency" in values:
        omega = 2.0 * math.pi * values["excitation.frequency"]
    return replace(
        study,
        joint=joint,
        pin=losses.pin,
        friction=losses.friction,
        omega=omega,
        force_amplitude=values.get("excitation.force_amplitude", study.force_amplitude),
        damping_ratio=losses.damping_ratio,
        restitution=losses.restitution,
        contact_friction_coefficient=losses.contact_friction_coefficient,
    )


def _joint_key(key: str) -> tuple[str, int | None]:
    """``joint.clearance[3]`` -> (clearance, 3); ``joint.clearance`` -> (clearance, None)."""
    name = key.split(".", 1)[1]
    if name.endswith("]") and "[" in name:
        field_name, index = name[:-1].split("[", 1)
        return field_name, int(index)
    return name, None


def structure_at(study: StructureStudy, values: Values) -> StructureStudy:
    """Return the structure study with the ``joint.`` values applied to its joints.

    ``joint.<key>`` sets that value on every joint of the structure; ``joint.<key>[j]``
    on joint ``j`` only (0-based, in ``Structure.joint_members`` order: for a mast,
    bay 1 left, bay 1 right, bay 2 left, ...). A symmetric joint (k_t = k_c) stays
    symmetric when only k_c is given, as in :func:`joint_at`.

    Raises
    ------
    ParameterError
        A joint index the structure does not have.
    """
    structure = study.structure
    if not isinstance(structure, Structure):
        raise ParameterError(
            f"{study.source}: joint overrides and sweeps take a [structure] study; a [model] "
            "(matrix files) is not swept yet"
        )
    n_joints = len(structure.joint_members)
    common: dict[str, float] = {}
    each: dict[int, dict[str, float]] = {}
    for key, value in values.items():
        if not key.startswith("joint."):
            continue
        name, index = _joint_key(key)
        if index is None:
            common[name] = value
        elif not 0 <= index < n_joints:
            raise ParameterError(
                f"{key}: the structure has {n_joints} joints (0 to {n_joints - 1}); "
                "check the per-joint draw"
            )
        else:
            each.setdefault(index, {})[name] = value
    if not common and not each:
        return study
    members = list(structure.members)
    for j, m in enumerate(structure.joint_members):
        joint: Any = members[m].joint  # a joint member carries its joint
        changes: dict[str, Any] = {**common, **each.get(j, {})}
        if (
            "compression_stiffness" in changes
            and "tension_stiffness" not in changes
            and tension_follows(joint)
        ):
            changes["tension_stiffness"] = changes["compression_stiffness"]
        members[m] = replace(members[m], joint=replace(joint, **changes))
    built = Structure(
        structure.nodes,
        structure.masses,
        tuple(members),
        supports=structure.supports,
        rayleigh=structure.rayleigh,
    )
    return replace(study, structure=built)
