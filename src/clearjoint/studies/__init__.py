"""The study layer: a study file plus given values -> the model's objects -> the task, run.

Both the command line and the sweep build and run studies here, so the rules are
written once:

* :mod:`~clearjoint.studies.joint_study`: the joint study file (``load_study``,
  ``DEFAULT_STUDY``, ``run_study``, its netCDF record); the structure study file is
  :mod:`clearjoint.structure.study`;
* :mod:`~clearjoint.studies.rules`: one value derived from another (the hole radius
  R_h = R_p + c/2, k_t following k_c, the default H);
* :mod:`~clearjoint.studies.overrides`: values (options, a sweep's point) merged over a
  study into a Joint, Pin, Losses, Study or StructureStudy;
* :mod:`~clearjoint.studies.harmonic`: what harmonic balance cannot carry, refused;
* :mod:`~clearjoint.studies.curves`: frequency-response curves and nonlinear modes,
  the method chosen, run and written;
* :mod:`~clearjoint.studies.structure`: a structure study's modes, response, decay and stepped sine;
* :mod:`~clearjoint.studies.identify`: a set of identifications written.
"""

from __future__ import annotations

import importlib
from typing import Any

# Each name is imported from its module on first use (PEP 562), so that importing one
# module of the layer (say studies.identify, for the identify command) does not load every
# solver behind the others.
_HOMES = {
    "DEFAULT_HARMONICS": "rules",
    "DEFAULT_STUDY": "joint_study",
    "STRUCTURE_TASKS": "structure",
    "StructureTaskResult": "structure",
    "Study": "joint_study",
    "StudyError": "joint_study",
    "checked_samples": "harmonic",
    "curve_summary": "curves",
    "frequency_response_of": "curves",
    "hole_radius": "rules",
    "joint_at": "overrides",
    "load_any_study": "curves",
    "load_study": "joint_study",
    "losses_at": "overrides",
    "marched_periods": "structure",
    "mode_summary": "curves",
    "name_dofs": "curves",
    "nonlinear_modes_of": "curves",
    "pin_at": "overrides",
    "refuse_harmonic_losses": "harmonic",
    "refuse_harmonic_structure": "harmonic",
    "run_structure_task": "structure",
    "run_study": "joint_study",
    "stepped_sine_of": "structure",
    "structure_at": "overrides",
    "study_at": "overrides",
    "summary": "joint_study",
    "tension_follows": "rules",
    "write_curve": "curves",
    "write_netcdf": "joint_study",
    "write_structure_result": "structure",
}


__all__ = [
    "DEFAULT_HARMONICS",
    "DEFAULT_STUDY",
    "STRUCTURE_TASKS",
    "StructureTaskResult",
    "Study",
    "StudyError",
    "checked_samples",
    "curve_summary",
    "frequency_response_of",
    "hole_radius",
    "joint_at",
    "load_any_study",
    "load_study",
    "losses_at",
    "marched_periods",
    "mode_summary",
    "name_dofs",
    "nonlinear_modes_of",
    "pin_at",
    "refuse_harmonic_losses",
    "refuse_harmonic_structure",
    "run_structure_task",
    "run_study",
    "stepped_sine_of",
    "structure_at",
    "study_at",
    "summary",
    "tension_follows",
    "write_curve",
    "write_netcdf",
    "write_structure_result",
]


def __getattr__(name: str) -> Any:
    """Import ``name`` from the module of the study layer that defines it."""
    if name not in _HOMES:
        raise AttributeError(f"module 'clearjoint.studies' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"clearjoint.studies.{_HOMES[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
