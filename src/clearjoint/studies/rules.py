"""The rules that derive one study value from another, written once for files, cli and sweep.

* The hole of a pin left to its default is R_h = R_p + c/2 (MODEL.md sec. 2, eq 13: one
  pin-hole pair carries the whole clearance c), and follows a changed c or R_p.
* A tension stiffness left equal to the compression one (a symmetric joint, MODEL.md
  sec. 1) follows a changed k_c.
* Harmonic balance keeps H = :data:`DEFAULT_HARMONICS` harmonics unless told otherwise.
"""

from __future__ import annotations

import math
from typing import Protocol

__all__ = [
    "DEFAULT_HARMONICS",
    "hole_radius",
    "is_default_hole",
    "tension_follows",
]

#: Harmonics H that harmonic balance keeps when a study or command does not say.
DEFAULT_HARMONICS = 7


class _Stiffnesses(Protocol):
    @property
    def compression_stiffness(self) -> float: ...

    @property
    def tension_stiffness(self) -> float: ...


def hole_radius(pin_radius: float, clearance: float) -> float:
    """Return the default hole radius R_h = R_p + c/2, m (MODEL.md sec. 2, under eq 13).

    Parameters
    ----------
    pin_radius : float
        R_p, m.
    clearance : float
        Total axial clearance c, m.
    """
    return pin_radius + 0.5 * clearance


def is_default_hole(pin_radius: float, hole: float, clearance: float) -> bool:
    """Return True when ``hole`` is the default R_p + c/2 of this pin and clearance."""
    return math.isclose(hole, hole_radius(pin_radius, clearance), rel_tol=1e-12)


def tension_follows(joint: _Stiffnesses | None) -> bool:
    """Return True when k_t follows k_c: no joint yet, or one with k_t = k_c (MODEL.md sec. 1)."""
    return joint is None or joint.tension_stiffness == joint.compression_stiffness
