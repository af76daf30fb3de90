"""contact.py: Hertz line contact of a pin in a hole, and the arc friction power."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from clearjoint import ParameterError, Pin
from clearjoint.contact import (
    HertzValidityWarning,
    contact_friction_power,
    effective_modulus,
    effective_radius,
    hertz_coefficient,
    hertz_contact,
)

PIN = Pin.for_clearance(radius=5e-3, clearance=0.106e-3, length=10e-3)


def test_half_width_against_the_worked_value() -> None:
    # R* = R_p R_h / (R_h - R_p) = 5 x 5.053 / 0.053 mm; E* = E / (2 (1 - nu^2)) for steel on steel
    r_star = 5e-3 * 5.053e-3 / 0.053e-3
    e_star = 2.06e11 / (2 * (1 - 0.3**2))
    assert effective_radius(PIN) == pytest.approx(r_star, rel=1e-12)
    assert effective_modulus(PIN) == pytest.approx(e_star, rel=1e-12)
    contact = hertz_contact(PIN, 1000.0)
    b = math.sqrt(4 * 1000.0 * r_star / (math.pi * 10e-3 * e_star))
    assert float(contact.half_width) == pytest.approx(b, rel=1e-12)
    assert b == pytest.approx(7.32e-4, rel=2e-3)  # by hand
    # MODEL.md: theta0 ~ sqrt(8 F / (pi L E* c)) ~ 0.15 at 1 kN, L = 10 mm, c = 0.106 mm
    assert float(contact.half_angle) == pytest.approx(
        math.sqrt(8 * 1000.0 / (math.pi * 10e-3 * e_star * 0.106e-3)), rel=2e-2
    )
    assert float(contact.half_angle) == pytest.approx(0.146, abs=0.005)


def test_pressure_carries_the_force() -> None:
    contact = hertz_contact(PIN, 800.0)
    b, p0 = float(contact.half_width), float(contact.peak_pressure)
    carried, _ = quad(lambda s: p0 * math.sqrt(1 - (s / b) ** 2), -b, b)
    assert carried * PIN.length == pytest.approx(800.0, rel=1e-9)


def test_arc_friction_power_matches_the_arc_integral_at_small_angles() -> None:
    mu, force, speed = 0.2, 300.0, 0.05
    contact = hertz_contact(PIN, force)
    b, p0 = float(contact.half_width), float(contact.peak_pressure)
    theta0 = b / PIN.radius

    def integrand(theta: float) -> float:
        pressure = p0 * math.sqrt(max(1 - (PIN.radius * theta / b) ** 2, 0.0))
        return mu * pressure * abs(speed * math.sin(theta)) * PIN.length * PIN.radius

    numeric, _ = quad(integrand, -theta0, theta0, points=[0.0])
    closed = float(contact_friction_power(PIN, mu, force, speed))
    assert closed == pytest.approx(numeric, rel=theta0**2)  # small-angle error O(theta0^2)
    assert closed == pytest.approx(
        4 * mu * hertz_coefficient(PIN) * force**1.5 * speed / (3 * math.pi * PIN.radius)
    )


def test_wide_contact_warns() -> None:
    with pytest.warns(HertzValidityWarning, match="exceeds 0.2 rad"):
        hertz_contact(PIN, 5000.0)


def test_zero_force_has_no_contact() -> None:
    contact = hertz_contact(PIN, np.array([0.0, 10.0]))
    assert contact.half_width[0] == 0.0
    assert contact.peak_pressure[0] == 0.0


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"hole_radius": 4e-3}, "hole_radius must be larger"),
        ({"length": 0.0}, "pin length must be > 0"),
        ({"poisson_ratio": 0.5}, "poisson_ratio must satisfy"),
        ({"hole_youngs_modulus": -1.0}, "hole_youngs_modulus must be > 0"),
    ],
)
def test_bad_pins_are_refused(kwargs: dict[str, float], words: str) -> None:
    values = {"radius": 5e-3, "hole_radius": 5.05e-3, "length": 1e-2}
    values.update(kwargs)
    with pytest.raises(ParameterError, match=words):
        Pin(**values)
