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
* :mod:`~clearjoint.studies.structure`: a structure study's modes, response and decay;
* :mod:`~clearjoint.studies.identify`: a set of identifications written.
"""

from __future__ import annotations

from clearjoint.studies.curves import (
    curve_summary,
    frequency_response_of,
    load_any_study,
    mode_summary,
    name_dofs,
    nonlinear_modes_of,
    write_curve,
)
from clearjoint.studies.harmonic import (
    checked_samples,
    refuse_harmonic_losses,
    refuse_harmonic_structure,
)
from clearjoint.studies.joint_study import (
    DEFAULT_STUDY,
    Study,
    StudyError,
    load_study,
    run_study,
    summary,
    write_netcdf,
)
from clearjoint.studies.overrides import joint_at, losses_at, pin_at, structure_at, study_at
from clearjoint.studies.rules import DEFAULT_HARMONICS, hole_radius, tension_follows
from clearjoint.studies.structure import STRUCTURE_TASKS, StructureTaskResult, run_structure_task

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
    "mode_summary",
    "name_dofs",
    "nonlinear_modes_of",
    "pin_at",
    "refuse_harmonic_losses",
    "refuse_harmonic_structure",
    "run_structure_task",
    "run_study",
    "structure_at",
    "study_at",
    "summary",
    "tension_follows",
    "write_curve",
    "write_netcdf",
]
