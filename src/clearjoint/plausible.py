"""Values that are legal but unusual for a pin joint: one warning line each, never an error.

A clearance in the centimetre-to-metre range, a moving mass above a tonne, or a frequency
written in rpm (revolutions per minute, 100rpm = 1.667 Hz) are more often a slip of the
unit than what was meant; the command line prints what this module says and goes on.
No physics here: thresholds only.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

__all__ = ["CLEARANCE_LIMIT_M", "MASS_LIMIT_KG", "rpm_note", "unusual_values"]

#: A pin joint's clearance is micrometres to a millimetre or so: from this on, say so, m.
CLEARANCE_LIMIT_M = 0.01
#: The moving mass of a joint test or a deployable structure's link: above this, say so, kg.
MASS_LIMIT_KG = 1000.0

_RPM = re.compile(r"(rpm|revolutions?\s*/\s*min(ute)?)\s*$", re.IGNORECASE)


def unusual_values(values: Mapping[str, float], names: Mapping[str, str]) -> list[str]:
    """The warnings for ``values`` (SI, by study key), each naming its option from ``names``."""
    notes = []
    clearance = values.get("joint.clearance")
    if isinstance(clearance, float) and clearance >= CLEARANCE_LIMIT_M:
        name = names.get("joint.clearance", "clearance")
        notes.append(
            f"{name} is {clearance * 1e3:g} mm, unusual for a pin joint (micrometres to a "
            "millimetre or so): check its unit, e.g. 0.1mm"
        )
    mass = values.get("joint.mass")
    if isinstance(mass, float) and mass > MASS_LIMIT_KG:
        name = names.get("joint.mass", "mass")
        notes.append(
            f"{name} is {mass / 1e3:g} t, above a tonne: unusual for a joint's moving mass; "
            "check the unit (g, kg)"
        )
    return notes


def rpm_note(text: str, hz: float, name: str) -> str | None:
    """A warning when frequency ``text`` (``hz`` once read) was written in rpm, else None."""
    unit = _RPM.search(text.strip())
    if unit is None:
        return None
    number = text.strip()[: unit.start()].strip()
    return (
        f"{name} {text.strip()} is {hz:.4g} Hz (rpm counts revolutions per minute); "
        f"write {number}Hz if hertz was meant"
    )
