"""clearjoint: dynamics of pin joints with clearance.

Dynamic stiffness from the period of free vibration, energy dissipation by
sliding friction, Hertz contact friction and impact, test-record
identification and fitted laws, after Li et al., Shock and Vibration (2013),
doi:10.1155/2013/583030. Equations: MODEL.md. SI units throughout the API;
circular frequencies in rad/s.
"""

from clearjoint import stiffness
from clearjoint.errors import ClearjointError, ParameterError, ParameterTypeError
from clearjoint.joint import ClearanceJoint, Friction, Joint, Losses, Pin

__all__ = [
    "ClearanceJoint",
    "ClearjointError",
    "Friction",
    "Joint",
    "Losses",
    "ParameterError",
    "ParameterTypeError",
    "Pin",
    "stiffness",
]

__version__ = "0.1.0"
