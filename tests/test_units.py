"""units.py: engineering units at the edges, converted to SI."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import Friction, Joint, Losses, Pin, stiffness
from clearjoint.errors import ParameterError
from clearjoint.simulate import steady_state
from clearjoint.units import parse_quantity, parse_quantity_list, registry, to_si


@pytest.mark.parametrize(
    ("text", "kind", "si"),
    [
        ("0.106mm", "length", 0.106e-3),
        ("5um", "length", 5e-6),
        ("5 µm", "length", 5e-6),
        ("0.001in", "length", 2.54e-5),
        ("8e7N/m", "stiffness", 8e7),
        ("80 kN/mm", "stiffness", 8e7),
        ("1.5kg", "mass", 1.5),
        ("20Hz", "frequency", 20.0),
        ("0", "length", 0.0),  # zero needs no unit
    ],
)
def test_parses_to_si(text: str, kind: str, si: float) -> None:
    assert parse_quantity(text, kind, name="--x") == pytest.approx(si, rel=1e-12)


def test_bare_numbers_are_si_only_when_asked() -> None:
    assert parse_quantity("3", "length", name="x", bare="si") == 3.0
    with pytest.raises(ParameterError, match="give a unit"):
        parse_quantity("3", "length", name="x")


def test_wrong_dimension_names_the_option() -> None:
    with pytest.raises(ParameterError, match=r"--clearance: '2kg' is not a length"):
        parse_quantity("2kg", "length", name="--clearance")


def test_list() -> None:
    assert parse_quantity_list("1um,5um,20um", "length", name="--a") == pytest.approx(
        [1e-6, 5e-6, 2e-5]
    )
    with pytest.raises(ParameterError, match="empty entry"):
        parse_quantity_list("1um,", "length", name="--a")


# ---- issue 16: every quantity by its dimension, bare numbers refused where asked ----------


@pytest.mark.parametrize(
    ("text", "hz"),
    [
        ("2513rad/s", 2513.0 / (2.0 * math.pi)),  # 399.96 Hz, not 2513 Hz
        ("400rpm", 400.0 / 60.0),  # 6.667 Hz, not 41.89 Hz
        ("360deg/s", 1.0),
        ("12kHz", 12000.0),
    ],
)
def test_frequencies_keep_their_two_pi(text: str, hz: float) -> None:
    assert parse_quantity(text, "frequency", name="frequency") == pytest.approx(hz, rel=1e-12)
    omega = parse_quantity(text, "angular_frequency", name="omega")
    assert omega == pytest.approx(2.0 * math.pi * hz, rel=1e-12)


@pytest.mark.parametrize("text", ["0.1m", "2kg", "3rad"])
def test_a_non_frequency_is_refused_where_a_frequency_is_expected(text: str) -> None:
    with pytest.raises(ParameterError, match="is not a frequency"):
        parse_quantity(text, "frequency", name="--frequency")


def test_bare_number_refused_with_the_way_to_write_it() -> None:
    with pytest.raises(ParameterError) as info:
        parse_quantity("0.106", "length", name="--clearance", bare="refuse")
    assert str(info.value) == "--clearance 0.106: give a unit, e.g. 0.106mm"
    # dimensionless quantities take bare numbers everywhere
    assert parse_quantity("0.3", "dimensionless", name="--x", bare="refuse") == 0.3


def test_to_si_takes_pint_quantities_strings_and_leaves_floats() -> None:
    ureg = registry()
    assert to_si(ureg.Quantity(0.106, "mm"), "m", name="c") == pytest.approx(1.06e-4)
    assert to_si("400rpm", "rad/s", name="w") == pytest.approx(400.0 * 2 * math.pi / 60.0)
    np.testing.assert_allclose(to_si(ureg.Quantity([1.0, 5.0], "um"), "m", name="a"), [1e-6, 5e-6])
    assert to_si(2.5, "m", name="c") == 2.5  # a bare float is SI, untouched
    with pytest.raises(ParameterError, match="is not a length"):
        to_si(ureg.Quantity(2.0, "kg"), "m", name="clearance")


def test_the_python_api_takes_units_wherever_it_takes_floats() -> None:
    ureg = registry()
    joint = Joint(mass="2kg", clearance=ureg.Quantity(0.106, "mm"), compression_stiffness="80kN/mm")
    assert (joint.mass, joint.clearance, joint.compression_stiffness) == pytest.approx(
        (2.0, 0.106e-3, 8e7)
    )
    assert joint.tension_stiffness == pytest.approx(8e7)
    friction = Friction(0.2, "300N")
    assert friction.force == pytest.approx(60.0)
    pin = Pin.for_clearance("5mm", "0.106mm", "25mm", youngs_modulus="206GPa")
    assert pin.hole_radius == pytest.approx(5e-3 + 0.053e-3)
    assert pin.youngs_modulus == pytest.approx(2.06e11)
    bare = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    assert stiffness.period(joint, "20um") == pytest.approx(stiffness.period(bare, 20e-6))
    with pytest.raises(ParameterError, match="mass"):
        Joint(mass="2mm", clearance=1e-4, compression_stiffness=8e7)


def test_the_simulator_takes_a_frequency_in_hz_for_omega() -> None:
    joint = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    si = steady_state(joint, 1000.0, 2.0 * math.pi * 400.0, losses=Losses(damping_ratio=0.02))
    united = steady_state(joint, "1kN", "400Hz", losses=Losses(damping_ratio=0.02))
    assert united.amplitude == pytest.approx(si.amplitude, rel=1e-12)


def test_sweeps_and_records_take_units_too() -> None:
    from clearjoint.records import Record
    from clearjoint.simulate import frequency_sweep

    joint = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    hz = registry().Quantity(np.array([390.0, 400.0]), "Hz")
    united = frequency_sweep(joint, "1kN", hz, losses=Losses(damping_ratio=0.02), direction="up")
    si = frequency_sweep(
        joint,
        1000.0,
        2 * math.pi * np.array([390.0, 400.0]),
        losses=Losses(damping_ratio=0.02),
        direction="up",
    )
    np.testing.assert_allclose(united.omega, si.omega, rtol=1e-12)
    np.testing.assert_allclose(united.amplitude_up, si.amplitude_up, rtol=1e-12)
    t = np.arange(100) / 100.0
    record = Record(time=t, force=t, displacement=t, clearance="0.1mm", mass="1500g")
    assert (record.clearance, record.mass) == pytest.approx((1e-4, 1.5))


# ---- review: text pint would read silently wrong ---------------------------------------------


@pytest.mark.parametrize(
    ("text", "kind", "words"),
    [
        ("0,106mm", "length", "--x 0,106mm: write the decimal point as '.', e.g. 0.106mm"),
        ("400,5Hz", "frequency", "e.g. 400.5Hz"),  # pint: 4005 Hz
        ("0,8", "dimensionless", "e.g. 0.8"),  # pint: 0
        (
            "mm",
            "length",
            "--x: cannot read 'mm' as a length; start with the number, e.g. 0.106mm",
        ),  # pint: 1 mm
        ("Hz", "frequency", "start with the number"),
        ("nan", "length", "--x nan: not a finite number"),
        ("1 000 mm", "length", "write one number, then its unit"),  # pint: 0 mm
        ("2 3mm", "length", "write one number"),  # pint: 6 mm
        ("2(3)mm", "length", "write one number"),  # pint: a measurement 2 +/- 0.3 mm
    ],
)
def test_text_pint_misreads_is_refused(text: str, kind: str, words: str) -> None:
    with pytest.raises(ParameterError) as info:
        parse_quantity(text, kind, name="--x")
    assert words in str(info.value)


def test_a_list_where_one_value_is_expected_is_not_taken_for_a_decimal_comma() -> None:
    # '1um,5um' (as `clearjoint stiffness --amplitude` takes it) given to an option that wants
    # one value: the old hint 'e.g. 1um.5um' was no fix
    with pytest.raises(ParameterError) as info:
        parse_quantity("1um,5um", "length", name="--amplitude")
    assert str(info.value) == "--amplitude 1um,5um: give one length here, not a list, e.g. 0.106mm"
    with pytest.raises(ParameterError, match=r"e\.g\. 0\.106 mm"):
        parse_quantity("0,106 mm", "length", name="--x")  # a decimal comma is still one


@pytest.mark.parametrize(
    ("text", "value"),
    [("1%", 0.01), ("80 %", 0.8), ("500 ppm", 5e-4), ("2mm/m", 2e-3), ("0.3", 0.3), ("1e-2", 0.01)],
)
def test_dimensionless_units_are_converted_not_dropped(text: str, value: float) -> None:
    # "1%" is a unitless pint quantity of magnitude 1: a damping ratio of 1%, not 1
    assert parse_quantity(text, "dimensionless", name="--damping-ratio") == pytest.approx(value)


def test_one_over_second_is_hz_for_a_frequency_but_ambiguous_for_omega() -> None:
    assert parse_quantity("50 1/s", "frequency", name="f") == pytest.approx(50.0)
    assert parse_quantity("3000 1/min", "frequency", name="f") == pytest.approx(50.0)
    ureg = registry()
    # sqrt(k/m) in pint is 1/s: that is rad/s, so reading it as Hz would add a 2 pi
    omega_n = (ureg.Quantity(8e7, "N/m") / ureg.Quantity(2.0, "kg")) ** 0.5
    with pytest.raises(ParameterError, match="ambiguous for an angular frequency"):
        to_si(omega_n, "rad/s", name="omega")
    with pytest.raises(ParameterError, match="ambiguous for an angular frequency"):
        parse_quantity("2513 1/s", "angular_frequency", name="omega")
    assert to_si(omega_n.to("rad/s"), "rad/s", name="omega") == pytest.approx(math.sqrt(4e7))


def test_damping_is_a_kind_of_quantity() -> None:
    """N s/m, the unit of a dashpot (structure study dampers): 0.05 kN s/m = 50 N s/m."""
    assert parse_quantity("0.05kN*s/m", "damping", name="d") == pytest.approx(50.0)
    assert parse_quantity("50 N s/m", "damping", name="d") == pytest.approx(50.0)
    with pytest.raises(ParameterError, match="is not a damping"):
        parse_quantity("50N/m", "damping", name="d")
