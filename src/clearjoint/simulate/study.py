"""The joint study file, kept importable here: it lives in :mod:`clearjoint.studies.joint_study`.

The study layer (:mod:`clearjoint.studies`) reads the file, merges command-line or sweep
values over it and runs it; these names stay importable from ``clearjoint.simulate.study``.
"""

from __future__ import annotations

from clearjoint.studies.joint_study import *  # noqa: F403  (every public name, as before)
from clearjoint.studies.joint_study import __all__ as __all__
