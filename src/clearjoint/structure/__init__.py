"""Structures with many clearance joints: model, builders and exact motion (MODEL.md 5.2).

``Structure`` holds nodes with lumped masses, axial members (each optionally with a
:class:`~clearjoint.ClearanceJoint` in series), supports and damping; ``chain`` and
``truss`` build one; ``time_response`` and ``free_decay`` give its exact event-driven
motion with an energy ledger, and ``system_modes`` the linear modes of a contact pattern.
Each of them takes a Structure or the :class:`~clearjoint.system.VibrationSystem` it
produces (``Structure.to_system()``), or one built from matrices: ``from_matrices``
takes a finite-element model's M, C, K with joints between its DOFs, and ``reduce`` is
its Craig-Bampton reduction onto the joints (subpackage ``fe``).
"""

from clearjoint.structure.backbone import Backbone, decay_backbone
from clearjoint.structure.builders import chain, mast, truss
from clearjoint.structure.fe import from_matrices, from_opensees, reduce
from clearjoint.structure.model import Member, Modes, Structure, StructureError, system_modes
from clearjoint.structure.motion import StructureMotion, free_decay, time_response
from clearjoint.structure.study import read_model

__all__ = [
    "Backbone",
    "Member",
    "Modes",
    "Structure",
    "StructureError",
    "StructureMotion",
    "chain",
    "decay_backbone",
    "free_decay",
    "from_matrices",
    "from_opensees",
    "mast",
    "read_model",
    "reduce",
    "system_modes",
    "time_response",
    "truss",
]
