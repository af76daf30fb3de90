"""Structures with many clearance joints: model, builders and exact motion (MODEL.md 5.2).

``Structure`` holds nodes with lumped masses, axial members (each optionally with a
:class:`~clearjoint.ClearanceJoint` in series), supports and damping; ``chain`` and
``truss`` build one; ``time_response`` and ``free_decay`` give its exact event-driven
motion with an energy ledger.
"""

from clearjoint.structure.backbone import Backbone, decay_backbone
from clearjoint.structure.builders import chain, mast, truss
from clearjoint.structure.model import Member, Modes, Structure, StructureError
from clearjoint.structure.motion import StructureMotion, free_decay, time_response

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
    "mast",
    "time_response",
    "truss",
]
