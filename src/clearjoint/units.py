"""Engineering units at the edges: parse "0.106mm", "5um", "8e7N/m" into SI floats (pint).

Only the command line and file readers use this module; the physics never
sees a unit. A bare number is taken as SI.
"""

from __future__ import annotations

from functools import lru_cache
from typing import TYPE_CHECKING, Any

from clearjoint.errors import ParameterError

if TYPE_CHECKING:
    import pint

#: The SI unit each kind of quantity is converted to, by name.
SI_UNITS: dict[str, str] = {
    "length": "m",
    "mass": "kg",
    "stiffness": "N/m",
    "force": "N",
    "frequency": "Hz",
    "time": "s",
    "pressure": "Pa",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "dimensionless": "",
}


#: A value of each kind that parses, for error messages.
EXAMPLES: dict[str, str] = {
    "length": "0.106mm",
    "mass": "1.5kg",
    "stiffness": "8e7N/m",
    "force": "200N",
    "frequency": "20Hz",
    "time": "2s",
    "pressure": "206GPa",
    "velocity": "0.1m/s",
    "acceleration": "100m/s^2",
    "dimensionless": "0.3",
}


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry[float]:
    """The one pint registry (built on first use: it takes a fraction of a second)."""
    import pint

    return pint.UnitRegistry()


def parse_quantity(text: str, kind: str, *, name: str) -> float:
    """Return ``text`` (e.g. ``"0.106mm"``) as a float in the SI unit of ``kind``.

    Raises
    ------
    ParameterError
        The text is not a number with a unit, or its unit is not a ``kind``;
        the message names the option ``name`` and an example that would work.
    """
    import pint

    si = SI_UNITS[kind]
    example = EXAMPLES[kind]
    raw = text.strip()
    if not raw:
        raise ParameterError(f"{name}: empty value; give a {kind} such as {example}")
    ureg = registry()
    try:
        quantity: Any = ureg.Quantity(raw)
    except (pint.errors.PintError, ValueError, TypeError, AttributeError, SyntaxError) as exc:
        raise ParameterError(
            f"{name}: cannot read {raw!r} as a {kind} ({exc}); write it like {example}"
        ) from None
    if isinstance(quantity, int | float):
        return float(quantity)
    if quantity.unitless:  # a bare number is SI
        return float(quantity.magnitude)
    try:
        return float(quantity.to(si if si else "dimensionless").magnitude)
    except pint.errors.DimensionalityError:
        raise ParameterError(
            f"{name}: {raw!r} is not a {kind} (its unit is {quantity.units:~}); "
            f"write it like {example}"
        ) from None


def parse_quantity_list(text: str, kind: str, *, name: str) -> list[float]:
    """Return a comma-separated list such as ``"1um,5um,20um"`` as SI floats."""
    parts = [part for part in text.split(",")]
    if not parts or any(not part.strip() for part in parts):
        raise ParameterError(f"{name}: {text!r} has an empty entry; write it like 1um,5um,20um")
    return [parse_quantity(part, kind, name=name) for part in parts]
