"""The joint study file, kept importable here: it lives in :mod:`clearjoint.studies.joint_study`.

The study layer (:mod:`clearjoint.studies`) reads the file, merges command-line or sweep
values over it and runs it; these names stay importable from ``clearjoint.simulate.study``.
"""

from __future__ import annotations

from clearjoint.studies.joint_study import (
    DEFAULT_STUDY,
    Study,
    StudyError,
    load_study,
    run_study,
    summary,
    write_netcdf,
)

__all__ = [
    "DEFAULT_STUDY",
    "Study",
    "StudyError",
    "load_study",
    "run_study",
    "summary",
    "write_netcdf",
]
