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
        k0 spring), m, positive toward compression, with |d| <= c/2. Default 0.

    Raises
    ------
    ParameterError
        A value is NaN, infinite or outside its range; the message names the field.
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
