"""Structures with many clearance joints: model, builders and exact motion (MODEL.md 5.2).

``Structure`` holds nodes with lumped masses, axial members (each optionally with a
:class:`~clearjoint.ClearanceJoint` in series), supports and damping; ``chain`` and
``truss`` build one; ``time_response`` and ``free_decay`` give its exact event-driven
motion with an energy ledger, and ``system_modes`` the linear modes of a contact pattern;
``periodic_orbit``, ``frequency_response`` and ``stepped_sine`` its exact steady response
(MODEL.md 5.1 on 5.2): periodic orbits by shooting with their Floquet multipliers, whole
curves by continuation, and what the motion does where no orbit is stable.
Each of them takes a Structure or the :class:`~clearjoint.system.VibrationSystem` it
produces (``Structure.to_system()``), or one built from matrices: ``from_matrices``
takes a finite-element model's M, C, K with joints between its DOFs, and ``reduce`` is
its Craig-Bampton reduction onto the joints (subpackage ``fe``).
"""

import importlib
from typing import Any

from clearjoint.structure.backbone import Backbone, decay_backbone
from clearjoint.structure.builders import chain, mast, truss
from clearjoint.structure.fe import from_matrices, from_opensees, reduce
from clearjoint.structure.model import Member, Modes, Structure, StructureError, system_modes
from clearjoint.structure.motion import StructureMotion, free_decay, time_response
from clearjoint.structure.poincare import OrbitError, StructureOrbit
from clearjoint.structure.stepped import SteppedSine, SteppedSineError, stepped_sine
from clearjoint.structure.study import read_model

# periodic_orbit (seeded by harmonic balance) and frequency_response (its events found as
# harmonic balance finds them) import clearjoint.harmonic, whose check of its own orbits
# imports this package's exact motion: they are imported on first use (PEP 562), so this
# package's import never needs harmonic balance
_LAZY = {
    "periodic_orbit": "clearjoint.structure.orbit",
    "frequency_response": "clearjoint.structure.shooting",
}


def __getattr__(name: str) -> Any:
    """Import ``periodic_orbit`` and ``frequency_response`` from their modules on first use."""
    home = _LAZY.get(name)
    if home is None:
        raise AttributeError(f"module 'clearjoint.structure' has no attribute {name!r}")
    value = getattr(importlib.import_module(home), name)
    globals()[name] = value
    return value


__all__ = [
    "Backbone",
    "Member",
    "Modes",
    "OrbitError",
    "SteppedSine",
    "SteppedSineError",
    "Structure",
    "StructureError",
    "StructureMotion",
    "StructureOrbit",
    "chain",
    "decay_backbone",
    "free_decay",
    "frequency_response",
    "from_matrices",
    "from_opensees",
    "mast",
    "periodic_orbit",
    "read_model",
    "reduce",
    "stepped_sine",
    "system_modes",
    "time_response",
    "truss",
]
