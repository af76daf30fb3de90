"""Identify a joint from a test record: clearance, contact stiffness, friction, energy per cycle.

MODEL.md section 3. From a :class:`~clearjoint.records.Record` alone (this package never
imports the rig or the simulator, so it cannot peek at the truth it is judged against):

* :mod:`~clearjoint.identify.cycles`: frequency, cycles, the steady-cycle rule, the
  cycle average;
* :mod:`~clearjoint.identify.segments`: stages by segmented least squares, model choice;
* :mod:`~clearjoint.identify.weak`: the clearance joint's parameters by a weak form;
* :mod:`~clearjoint.identify.damper`: a friction damper with backlash;
* :mod:`~clearjoint.identify.core`: :func:`identify`, standard errors, flags;
* :mod:`~clearjoint.identify.result`: :class:`Identification` and its views.
"""

from clearjoint.identify.core import (
    flag_outliers,
    identify,
    identify_files,
    restoring_force,
)
from clearjoint.identify.cycles import (
    STEADY_RULE,
    IdentificationError,
    excitation_frequency,
    steady_rule,
)
from clearjoint.identify.result import (
    QUANTITIES,
    CycleResult,
    Identification,
    identifications_figure,
)
from clearjoint.identify.segments import STAGE_COMPRESSION, STAGE_FREE, STAGE_TENSION

__all__ = [
    "QUANTITIES",
    "STAGE_COMPRESSION",
    "STAGE_FREE",
    "STAGE_TENSION",
    "STEADY_RULE",
    "CycleResult",
    "Identification",
    "IdentificationError",
    "excitation_frequency",
    "flag_outliers",
    "identifications_figure",
    "identify",
    "identify_files",
    "restoring_force",
    "steady_rule",
]
