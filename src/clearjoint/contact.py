"""Hertz line contact of a pin in its hole, and the friction power on the contact arc.

MODEL.md eq 11-14. For a contact force F_n (N) on a pin of radius R_p in a hole
of radius R_h, over a length L_p:

    b   = sqrt(4 F_n R* / (pi L_p E*)),   1/R* = 1/R_p - 1/R_h,
    1/E* = (1 - nu_p^2)/E_p + (1 - nu_h^2)/E_h,
    p0  = 2 F_n / (pi b L_p),             theta0 = b / R_p,

and the friction power of tangential slip v sin(theta) over the arc (small angles) is

    P_C = (4 mu_c / (3 pi)) (b / R_p) F_n abs(v) = (4 mu_c beta_H / (3 pi R_p)) F_n^(3/2) abs(v),

with b = beta_H sqrt(F_n), beta_H = sqrt(4 R* / (pi L_p E*)).

Hertz's solution assumes a contact arc that is small against the radii. We warn
when the half-angle theta0 exceeds ``HERTZ_HALF_ANGLE_LIMIT`` = 0.2 rad (11.5 deg):
there the small-angle forms above are still within 1 % (sin 0.2 = 0.993 x 0.2), but
for a conformal pin-in-hole contact the arc grows faster than Hertz predicts
(Persson's solution) and the error in b becomes several per cent.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.joint import Pin

#: Largest contact half-angle theta0 (rad) for which Hertz's solution is used without a warning.
HERTZ_HALF_ANGLE_LIMIT = 0.2

FloatArray = NDArray[np.float64]


class HertzValidityWarning(UserWarning):
    """The contact arc is too wide for Hertz's small-contact solution."""


def effective_radius(pin: Pin) -> float:
    """Return R* with 1/R* = 1/R_p - 1/R_h (internal contact), m."""
    return pin.radius * pin.hole_radius / (pin.hole_radius - pin.radius)


def effective_modulus(pin: Pin) -> float:
    """Return E* with 1/E* = (1 - nu_p^2)/E_p + (1 - nu_h^2)/E_h, Pa."""
    compliance = (1.0 - pin.poisson_ratio**2) / pin.youngs_modulus + (
        1.0 - pin.hole_poisson_ratio**2
    ) / pin.hole_youngs_modulus
    return 1.0 / compliance


def hertz_coefficient(pin: Pin) -> float:
    """Return beta_H = sqrt(4 R* / (pi L_p E*)), so that b = beta_H sqrt(F_n), m N^-1/2."""
    return math.sqrt(4.0 * effective_radius(pin) / (math.pi * pin.length * effective_modulus(pin)))


@dataclass(frozen=True)
class HertzContact:
    """Hertz line contact at given normal forces (arrays shaped like the force).

    Attributes
    ----------
    half_width : ndarray
        b, m.
    peak_pressure : ndarray
        p0, Pa.
    half_angle : ndarray
        theta0 = b / R_p, rad.
    """

    half_width: FloatArray
    peak_pressure: FloatArray
    half_angle: FloatArray


def hertz_contact(pin: Pin, normal_force: ArrayLike) -> HertzContact:
    """Return the half-width, peak pressure and half-angle of the pin-hole contact (MODEL.md eq 13).

    Warns with :class:`HertzValidityWarning` when theta0 > ``HERTZ_HALF_ANGLE_LIMIT``.
    """
    force = _checks.non_negative_array("normal_force", normal_force, unit="N")
    b = hertz_coefficient(pin) * np.sqrt(force)
    with np.errstate(invalid="ignore", divide="ignore"):
        p0 = np.where(b > 0.0, 2.0 * force / (math.pi * np.where(b > 0, b, 1.0) * pin.length), 0.0)
    theta0 = b / pin.radius
    worst = float(np.max(theta0)) if theta0.size else 0.0
    if worst > HERTZ_HALF_ANGLE_LIMIT:
        warnings.warn(
            f"Hertz contact half-angle {worst:.3g} rad exceeds {HERTZ_HALF_ANGLE_LIMIT} rad: "
            "the pin-hole contact is conformal and Hertz underestimates the arc; "
            "treat the contact-friction energy as an estimate",
            HertzValidityWarning,
            stacklevel=2,
        )
    return HertzContact(half_width=b, peak_pressure=p0, half_angle=theta0)


def contact_friction_power(
    pin: Pin, friction_coefficient: float, normal_force: ArrayLike, velocity: ArrayLike
) -> FloatArray:
    """Return the friction power on the contact arc, W (MODEL.md eq 12, 14).

    P_C = (4 mu_c beta_H / (3 pi R_p)) F_n^(3/2) abs(v), the arc integral of
    mu_c p abs(v sin(theta)) L_p R_p dtheta for a Hertz pressure at small angles.
    """
    mu = _checks.non_negative("contact friction coefficient", friction_coefficient)
    force = np.maximum(np.asarray(normal_force, dtype=np.float64), 0.0)
    speed = np.abs(np.asarray(velocity, dtype=np.float64))
    factor = 4.0 * mu * hertz_coefficient(pin) / (3.0 * math.pi * pin.radius)
    return factor * force**1.5 * speed
