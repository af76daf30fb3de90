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

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import ParamSpec, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.errors import ParameterError, ParameterTypeError

_P = ParamSpec("_P")
_R = TypeVar("_R")


@dataclass(frozen=True)
class ClearanceJoint:
    """A massless pin joint with axial clearance: a law of the relative displacement across it.

    MODEL.md section 0 and 5.2: the force f(delta) it transmits at the relative
    displacement delta (positive in compression) is piecewise linear, with gap edges
    at delta = g_c and delta = -g_t. It knows nothing of the masses it links.

    Parameters
    ----------
    clearance : float
        Total axial clearance c in m (the free-play stroke), >= 0.
    compression_stiffness : float
        Contact stiffness k_c in compression, N/m, > 0.
    tension_stiffness : float, optional
        Contact stiffness k_t in tension, N/m, > 0. Defaults to ``compression_stiffness``.
    gap_stiffness : float, optional
        Stiffness k0 inside the gap (free-play), N/m, >= 0. Default 0 (the paper's choice).
    gap_offset : float, optional
        Position d of the gap's centre relative to delta = 0 (the rest position of the
        k0 spring), m, positive toward compression, with abs(d) <= c/2. Default 0.
    friction : Friction, optional
        Coulomb sliding friction in the joint (MODEL.md eq 10). Default none.
    restitution : float, optional
        Coefficient of restitution e in [0, 1] on entering contact (MODEL.md eq 16).
        Default 1 (no impact loss).

    Raises
    ------
    ParameterError
        A value is NaN, infinite or outside its range; the message names the field.
    """

    clearance: float
    compression_stiffness: float
    tension_stiffness: float = field(default=None)  # type: ignore[assignment]
    gap_stiffness: float = 0.0
    gap_offset: float = 0.0
    friction: Friction | None = None
    restitution: float = 1.0

    def __post_init__(self) -> None:
        set_ = object.__setattr__
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
        if self.friction is not None and not isinstance(self.friction, Friction):
            raise ParameterTypeError(
                "friction must be a clearjoint.Friction(coefficient, lateral_load) or None, "
                f"got {self.friction!r}"
            )
        set_(self, "restitution", _restitution(self.restitution))

    @property
    def compression_gap(self) -> float:
        """Distance g_c from delta = 0 to the compression gap edge, m."""
        return 0.5 * self.clearance + self.gap_offset

    @property
    def tension_gap(self) -> float:
        """Distance g_t from delta = 0 to the tension gap edge, m."""
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

    def force(self, delta: ArrayLike) -> NDArray[np.float64]:
        """Return the force f(delta) in N the joint carries at relative displacement delta in m.

        MODEL.md sec. 0 (:func:`clearjoint.laws.clearance.force`). ``delta`` of any shape
        (e.g. (N_t, n)); the result has its shape.
        """
        from clearjoint.laws import clearance  # here: numba loads on first use only

        samples = np.asarray(delta, dtype=np.float64)
        force, _ = prefer(clearance.forces_and_tangents)(
            _column(samples), *clearance.parameters((self,))
        )
        return force.reshape(samples.shape)

    def tangent_stiffness(self, delta: ArrayLike) -> NDArray[np.float64]:
        """Return df/d(delta) in N/m at relative displacement delta in m (same shape).

        MODEL.md sec. 0 (:func:`clearjoint.laws.clearance.tangent`). At a gap edge itself
        (a kink of f) the free-play stiffness k0 is returned.
        """
        from clearjoint.laws import clearance  # here: numba loads on first use only

        samples = np.asarray(delta, dtype=np.float64)
        _, stiffness = prefer(clearance.forces_and_tangents)(
            _column(samples), *clearance.parameters((self,))
        )
        return stiffness.reshape(samples.shape)

    def potential_energy(self, delta: ArrayLike) -> NDArray[np.float64]:
        """Return the energy V(delta) in J stored in the joint, the integral of f from 0.

        MODEL.md sec. 0 (:func:`clearjoint.laws.clearance.potential`); any shape.
        """
        from clearjoint.laws import clearance  # here: numba loads on first use only

        samples = np.asarray(delta, dtype=np.float64)
        energy = prefer(clearance.potentials)(_column(samples), *clearance.parameters((self,)))
        return energy.reshape(samples.shape)

    def contact_force(self, delta: ArrayLike) -> NDArray[np.float64]:
        """Return the normal force on the pin in N, >= 0, at relative displacement delta in m.

        MODEL.md sec. 0 and eq 14 (:func:`clearjoint.laws.clearance.contact_force`): the
        force less its free-play spring k0 delta, as a magnitude; any shape.
        """
        from clearjoint.laws import clearance  # here: numba loads on first use only

        samples = np.asarray(delta, dtype=np.float64)
        _, k_c, k_t, g_c, g_t = clearance.parameters((self,))
        forces = prefer(clearance.contact_forces)(_column(samples), k_c, k_t, g_c, g_t)
        return forces.reshape(samples.shape)

    def in_series(self, stiffness: float) -> ClearanceJoint:
        """Return the one massless law of this joint in series with a spring (MODEL.md 5.2).

        In each state the stiffnesses add in series, K k_m / (K + k_m), and with
        k0 > 0 the gap edges, measured on the total elongation, move by the spring's
        share: g_s (1 + k0 / k_m). ``stiffness`` = inf returns the joint itself.

        Raises
        ------
        ParameterError
            The joint has a restitution below 1 or friction: a massless spring has no
            mass to stop, so neither is defined in series with it.
        """
        k_m = positive_or_inf("member stiffness", stiffness, unit="N/m")
        if math.isinf(k_m):
            return self
        if self.restitution != 1.0:
            raise ParameterError(
                f"restitution {self.restitution!r} on a joint in series with a member of "
                f"stiffness {k_m!r} N/m is not defined (no mass between them to stop); "
                "set restitution=1 or make the member rigid (stiffness=inf)"
            )
        if self.friction is not None:
            raise ParameterError(
                "friction on a joint in series with a member is not supported; "
                "set friction=None or make the member rigid (stiffness=inf)"
            )
        k0 = self.gap_stiffness

        def series(k: float) -> float:
            return k * k_m / (k + k_m)

        k0_s = series(k0)
        stretch = 1.0 + k0 / k_m
        return ClearanceJoint(
            clearance=self.clearance * stretch,
            compression_stiffness=series(k0 + self.compression_stiffness) - k0_s,
            tension_stiffness=series(k0 + self.tension_stiffness) - k0_s,
            gap_stiffness=k0_s,
            gap_offset=self.gap_offset * stretch,
        )


@dataclass(frozen=True)
class Joint:
    """A pin joint with axial clearance, carrying a moving mass (all SI).

    The paper's single joint: a mass ``mass`` on a :class:`ClearanceJoint` to ground
    (``element``), so x is the joint's relative displacement.

    Parameters
    ----------
    mass : float
        Moving mass m in kg (link plus the moving part of the bearing), > 0.
    clearance, compression_stiffness, tension_stiffness, gap_stiffness, gap_offset : float
        The law of the :class:`ClearanceJoint` the mass sits on: c, k_c, k_t, k0 and d,
        with their ranges and defaults as documented there (its delta is x here).

    Every value may also be a pint Quantity or a unit string (``mass="2kg"``,
    ``clearance="0.106mm"``): it is converted to SI; a bare number is SI.

    Raises
    ------
    ParameterError
        A value is NaN, infinite or outside its range, or its unit is not of the
        field's dimension; the message names the field.

    Attributes
    ----------
    element : ClearanceJoint
        The massless joint the mass sits on (no friction, restitution 1), built and
        validated once with the Joint; left out of ``==``, ``hash`` and ``repr``.
    """

    mass: float
    clearance: float
    compression_stiffness: float
    tension_stiffness: float = field(default=None)  # type: ignore[assignment]
    gap_stiffness: float = 0.0
    gap_offset: float = 0.0
    element: ClearanceJoint = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "mass", _checks.positive("mass", self.mass, unit="kg"))
        element = ClearanceJoint(
            self.clearance,
            self.compression_stiffness,
            self.tension_stiffness,
            self.gap_stiffness,
            self.gap_offset,
        )
        for name in (
            "clearance",
            "compression_stiffness",
            "tension_stiffness",
            "gap_stiffness",
            "gap_offset",
        ):
            set_(self, name, getattr(element, name))
        set_(self, "element", element)

    @property
    def compression_gap(self) -> float:
        """Distance g_c from x = 0 to the compression gap edge, m."""
        return self.element.compression_gap

    @property
    def tension_gap(self) -> float:
        """Distance g_t from x = 0 to the tension gap edge, m."""
        return self.element.tension_gap

    @property
    def large_amplitude_stiffness(self) -> float:
        """The limit k_inf of the dynamic stiffness at large amplitude, N/m (MODEL.md sec. 1)."""
        return self.element.large_amplitude_stiffness

    def restoring_force(self, x: ArrayLike) -> NDArray[np.float64]:
        """Return the restoring force f(x) in N at displacement x in m (MODEL.md sec. 0)."""
        return self.element.force(x)

    def potential_energy(self, x: ArrayLike) -> NDArray[np.float64]:
        """Return the potential energy V(x) in J, the integral of f from 0 to x."""
        return self.element.potential_energy(x)


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


def _column(samples: NDArray[np.float64]) -> NDArray[np.float64]:
    """Samples of any shape as one contiguous column (N, 1), for the laws' array forms."""
    return np.ascontiguousarray(samples.reshape(-1, 1))


def _poisson(name: str, value: float) -> float:
    nu = _checks.real_scalar(name, value)
    if not 0.0 <= nu < 0.5:
        raise ParameterError(f"{name} must satisfy 0 <= nu < 0.5, got {nu!r}")
    return nu


def _restitution(value: float) -> float:
    e = _checks.real_scalar("restitution", value)
    if not 0.0 <= e <= 1.0:
        raise ParameterError(f"restitution must satisfy 0 <= e <= 1, got {e!r}")
    return e


@dataclass(frozen=True)
class Losses:
    """The losses of a joint's motion as one value (MODEL.md sec. 2).

    Every solver of one joint takes it as ``losses=`` (default: none of them).

    Parameters
    ----------
    damping_ratio : float
        zeta >= 0 of the linear part (c_v = 2 zeta sqrt(m k_c), held fixed).
    friction : Friction, optional
        Coulomb sliding friction mu_s P sign(x').
    restitution : float
        Coefficient of restitution e in [0, 1] on entering contact.
    pin : Pin, optional
        The pin and hole, for contact friction (MODEL.md eq 13-15).
    contact_friction_coefficient : float
        mu_c >= 0 on the pin's contact arc.
    """

    damping_ratio: float = 0.0
    friction: Friction | None = None
    restitution: float = 1.0
    pin: Pin | None = None
    contact_friction_coefficient: float = 0.0

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "damping_ratio", _checks.non_negative("damping_ratio", self.damping_ratio))
        if self.friction is not None and not isinstance(self.friction, Friction):
            raise ParameterTypeError(
                f"friction must be a clearjoint.Friction or None, got {self.friction!r}"
            )
        set_(self, "restitution", _restitution(self.restitution))
        if self.pin is not None and not isinstance(self.pin, Pin):
            raise ParameterTypeError(f"pin must be a clearjoint.Pin or None, got {self.pin!r}")
        set_(
            self,
            "contact_friction_coefficient",
            _checks.non_negative("contact_friction_coefficient", self.contact_friction_coefficient),
        )
        if self.contact_friction_coefficient > 0.0 and self.pin is None:
            raise ParameterError(
                f"contact_friction_coefficient {self.contact_friction_coefficient!r} acts on the "
                "pin's contact arc, and these losses have no pin: give pin=clearjoint.Pin(...) "
                "or leave the coefficient at 0"
            )


LOSS_KEYWORDS = ("damping_ratio", "friction", "restitution", "pin", "contact_friction_coefficient")
"""The five loss keywords that :class:`Losses` replaced (refused by :func:`takes_losses`)."""


def checked_losses(losses: Losses | None) -> Losses:
    """Return ``losses``, or no losses (``Losses()``) for None; anything else is refused."""
    if losses is None:
        return Losses()
    if not isinstance(losses, Losses):
        raise ParameterTypeError(
            f"losses must be a clearjoint.Losses or None, got {losses!r}; "
            "e.g. losses=Losses(damping_ratio=0.02)"
        )
    return losses


def takes_losses(func: Callable[_P, _R]) -> Callable[_P, _R]:
    """Refuse the five loose loss keywords of the earlier API with a line that names the fix.

    ``damping_ratio=``, ``friction=``, ``restitution=``, ``pin=`` and
    ``contact_friction_coefficient=`` now travel in one :class:`Losses` value
    (``losses=``); a call that still passes one gets a ParameterTypeError naming it
    instead of Python's bare "unexpected keyword argument".
    """

    @functools.wraps(func)
    def checked(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        old = [name for name in LOSS_KEYWORDS if name in kwargs]
        if old:
            given = ", ".join(f"{name}={kwargs[name]!r}" for name in old)
            raise ParameterTypeError(
                f"{func.__name__}() takes its losses as one value: write "
                f"losses=Losses({given}) instead of {', '.join(n + '=' for n in old)}"
            )
        return func(*args, **kwargs)

    return checked


def positive_or_inf(name: str, value: float, *, unit: str = "") -> float:
    """Return ``value`` as a float > 0 where +inf is allowed (a rigid member)."""
    if isinstance(value, int | float) and not isinstance(value, bool) and value == math.inf:
        return math.inf
    return _checks.positive(name, value, unit=unit)
