"""The clearance joint's parameters: a frozen, validated dataclass in SI units.

MODEL.md section 0: the restoring force of the joint and structure is

    f(x) = k0 x                      for -g_t < x < g_c        (free-play)
    f(x) = k0 x + k_c (x - g_c)      for x >= g_c              (compression contact)
    f(x) = k0 x + k_t (x + g_t)      for x <= -g_t             (tension contact)

with x positive in compression and the gap edges g_c = c/2 + d, g_t = c/2 - d,
where d is the gap offset (the position of the gap's centre; d = 0 is a
centred gap).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import _checks
from clearjoint.errors import ParameterError


@dataclass(frozen=True)
class Joint:
    """A pin joint with axial clearance, carrying a moving mass (all SI).

    Parameters
    ----------
    mass : float
        Moving mass m in kg (link plus the moving part of the bearing), > 0.
    clearance : float
        Total axial clearance c in m (the free-play stroke), >= 0.
    compression_stiffness : float
        Contact stiffness k_c in compression, N/m, > 0.
    tension_stiffness : float, optional
        Contact stiffness k_t in tension, N/m, > 0. Defaults to ``compression_stiffness``.
    gap_stiffness : float, optional
        Stiffness k0 inside the gap (free-play), N/m, >= 0. Default 0 (the paper's choice).
    gap_offset : float, optional
        Position d of the gap's centre relative to x = 0 (the rest position of the
        k0 spring), m, positive toward compression, with abs(d) <= c/2. Default 0.

    Every value may also be a pint Quantity or a unit string (``mass="2kg"``,
    ``clearance="0.106mm"``): it is converted to SI; a bare number is SI.

    Raises
    ------
    ParameterError
        A value is NaN, infinite or outside its range, or its unit is not of the
        field's dimension; the message names the field.
    """

    mass: float
    clearance: float
    compression_stiffness: float
    tension_stiffness: float = field(default=None)  # type: ignore[assignment]
    gap_stiffness: float = 0.0
    gap_offset: float = 0.0

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "mass", _checks.positive("mass", self.mass, unit="kg"))
        set_(self, "clearance", _checks.non_negative("clearance", self.clearance, unit="m"))
        k_c = _checks.positive("compression_stiffness", self.compression_stiffness, unit="N/m")
        set_(self, "compression_stiffness", k_c)
        k_t = k_c if self.tension_stiffness is None else self.tension_stiffness
        set_(self, "tension_stiffness", _checks.positive("tension_stiffness", k_t, unit="N/m"))
        set_(
            self,
            "gap_stiffness",
            _checks.non_negative("gap_stiffness", self.gap_stiffness, unit="N/m"),
        )
        offset = _checks.real_scalar("gap_offset", self.gap_offset, unit="m")
        half = 0.5 * self.clearance
        if abs(offset) > half:
            raise ParameterError(
                f"gap_offset must lie within the clearance, -c/2 <= gap_offset <= c/2 "
                f"= [{-half!r}, {half!r}] m, got {offset!r}"
            )
        set_(self, "gap_offset", offset)

    @property
    def compression_gap(self) -> float:
        """Distance g_c from x = 0 to the compression gap edge, m."""
        return 0.5 * self.clearance + self.gap_offset

    @property
    def tension_gap(self) -> float:
        """Distance g_t from x = 0 to the tension gap edge, m."""
        return 0.5 * self.clearance - self.gap_offset

    @property
    def large_amplitude_stiffness(self) -> float:
        """The limit k_inf of the dynamic stiffness at large amplitude, N/m (MODEL.md sec. 1).

        k_inf = 4 K_c K_t / (sqrt(K_c) + sqrt(K_t))^2 with K_s = k0 + k_s: the
        stiffness of the bilinear oscillator left when the gap is negligible.
        """
        big_c = self.gap_stiffness + self.compression_stiffness
        big_t = self.gap_stiffness + self.tension_stiffness
        return 4.0 * big_c * big_t / (math.sqrt(big_c) + math.sqrt(big_t)) ** 2

    def restoring_force(self, x: ArrayLike) -> NDArray[np.float64]:
        """Return the restoring force f(x) in N at displacement x in m (MODEL.md sec. 0)."""
        x = np.asarray(x, dtype=np.float64)
        force = self.gap_stiffness * x
        force = force + self.compression_stiffness * np.maximum(x - self.compression_gap, 0.0)
        force = force + self.tension_stiffness * np.minimum(x + self.tension_gap, 0.0)
        return force

    def potential_energy(self, x: ArrayLike) -> NDArray[np.float64]:
        """Return the potential energy V(x) in J, the integral of f from 0 to x."""
        x = np.asarray(x, dtype=np.float64)
        energy = 0.5 * self.gap_stiffness * x**2
        energy = (
            energy
            + 0.5 * self.compression_stiffness * np.maximum(x - self.compression_gap, 0.0) ** 2
        )
        energy = energy + 0.5 * self.tension_stiffness * np.minimum(x + self.tension_gap, 0.0) ** 2
        return energy


FRICTION_REGIONS = ("everywhere", "free-play")


@dataclass(frozen=True)
class Friction:
    """Coulomb sliding friction mu_s P sign(x') from a lateral load (MODEL.md eq 10).

    Parameters
    ----------
    coefficient : float
        Sliding-friction coefficient mu_s >= 0 (static and kinetic taken equal).
    lateral_load : float
        Lateral (transverse) load P >= 0 in the joint or bearing, N.
    region : {"everywhere", "free-play"}
        Where the friction acts: over the whole path (default: P in the bearing, or
        the joint's faces sliding with the structure), or over the free-play stroke
        only (P at the joint faces, which stop slipping once the pin bears).
    """

    coefficient: float
    lateral_load: float
    region: str = "everywhere"

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "coefficient", _checks.non_negative("friction coefficient", self.coefficient))
        set_(
            self, "lateral_load", _checks.non_negative("lateral_load", self.lateral_load, unit="N")
        )
        if self.region not in FRICTION_REGIONS:
            raise ParameterError(
                f"friction region must be one of {FRICTION_REGIONS}, got {self.region!r}"
            )

    @property
    def force(self) -> float:
        """The friction force mu_s P, N."""
        return self.coefficient * self.lateral_load


@dataclass(frozen=True)
class Pin:
    """The pin and its hole: geometry and elastic constants for Hertz contact (MODEL.md eq 13).

    Parameters
    ----------
    radius : float
        Pin radius R_p, m, > 0.
    hole_radius : float
        Hole radius R_h > R_p, m (R_h = R_p + radial clearance).
    length : float
        Contact length L_p, m, > 0.
    youngs_modulus : float
        Young's modulus of the pin E_p, Pa, > 0.
    poisson_ratio : float
        Poisson's ratio of the pin, 0 <= nu < 0.5.
    hole_youngs_modulus, hole_poisson_ratio : float, optional
        Those of the hole's material; default: the pin's.
    """

    radius: float
    hole_radius: float
    length: float
    youngs_modulus: float = 2.06e11
    poisson_ratio: float = 0.3
    hole_youngs_modulus: float = field(default=None)  # type: ignore[assignment]
    hole_poisson_ratio: float = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "radius", _checks.positive("pin radius", self.radius, unit="m"))
        hole = _checks.positive("hole_radius", self.hole_radius, unit="m")
        if hole <= self.radius:
            raise ParameterError(
                f"hole_radius must be larger than the pin radius {self.radius!r} m, got {hole!r}"
            )
        set_(self, "hole_radius", hole)
        set_(self, "length", _checks.positive("pin length", self.length, unit="m"))
        e_p = _checks.positive("youngs_modulus", self.youngs_modulus, unit="Pa")
        set_(self, "youngs_modulus", e_p)
        nu_p = _poisson("poisson_ratio", self.poisson_ratio)
        set_(self, "poisson_ratio", nu_p)
        e_h = e_p if self.hole_youngs_modulus is None else self.hole_youngs_modulus
        set_(self, "hole_youngs_modulus", _checks.positive("hole_youngs_modulus", e_h, unit="Pa"))
        nu_h = nu_p if self.hole_poisson_ratio is None else self.hole_poisson_ratio
        set_(self, "hole_poisson_ratio", _poisson("hole_poisson_ratio", nu_h))

    @classmethod
    def for_clearance(
        cls, radius: float, clearance: float, length: float, **materials: float
    ) -> Pin:
        """A pin whose hole carries the joint's whole axial clearance: R_h = R_p + c/2."""
        c = _checks.positive("clearance", clearance, unit="m")
        r_p = _checks.positive("pin radius", radius, unit="m")
        return cls(radius=r_p, hole_radius=r_p + 0.5 * c, length=length, **materials)


def _poisson(name: str, value: float) -> float:
    nu = _checks.real_scalar(name, value)
    if not 0.0 <= nu < 0.5:
        raise ParameterError(f"{name} must satisfy 0 <= nu < 0.5, got {nu!r}")
    return nu
