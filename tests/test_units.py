"""units.py: engineering units at the edges, converted to SI."""

from __future__ import annotations

import pytest

from clearjoint.errors import ParameterError
from clearjoint.units import parse_quantity, parse_quantity_list


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
        ("3", "length", 3.0),
    ],
)
def test_parses_to_si(text: str, kind: str, si: float) -> None:
    assert parse_quantity(text, kind, name="--x") == pytest.approx(si, rel=1e-12)


def test_wrong_dimension_names_the_option() -> None:
    with pytest.raises(ParameterError, match=r"--clearance: '2kg' is not a length"):
        parse_quantity("2kg", "length", name="--clearance")


def test_list() -> None:
    assert parse_quantity_list("1um,5um,20um", "length", name="--a") == pytest.approx(
        [1e-6, 5e-6, 2e-5]
    )
    with pytest.raises(ParameterError, match="empty entry"):
        parse_quantity_list("1um,", "length", name="--a")
