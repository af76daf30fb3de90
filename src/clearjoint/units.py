"""Engineering units at the edges: "0.106mm", "5um", "2513rad/s", "400rpm" into SI floats (pint).

The command line, the file readers and the Python API's checks (``clearjoint.checks``) use
this module; the physics never sees a unit. Every quantity is converted by its
dimension. Frequencies keep their 2 pi: an angular unit (rad/s, deg/s, rpm) is
an angular frequency, so "2513rad/s" is 400 Hz and "400rpm" is 6.667 Hz, while
Hz counts cycles. A bare 1/s (or 1/min) is a frequency in Hz where one is
expected, but is refused where an angular frequency is (the API's ``omega``):
pint gives sqrt(k/m) in 1/s, which is rad/s, so reading it as Hz would silently
multiply it by 2 pi. On the command line a bare number for a dimensional
quantity is refused (``bare="refuse"``); in the Python API a bare float is SI.
Text must be one number, written with a decimal point, then its unit: pint reads
"0,106mm" as 0 mm, "mm" as 1 mm and "1 000 mm" as 0 mm, so these are refused.
"""

from __future__ import annotations

import math
import re
from functools import lru_cache
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from clearjoint.errors import ParameterError

if TYPE_CHECKING:
    import pint

#: Per kind of quantity, by name: the SI unit it is converted to, a unit to show after a
#: bare number in the "give a unit" message, and a value that parses (for error messages).
_KINDS: dict[str, tuple[str, str, str]] = {
    "length": ("m", "mm", "0.106mm"),
    "mass": ("kg", "kg", "1.5kg"),
    "stiffness": ("N/m", "N/m", "8e7N/m"),
    "force": ("N", "N", "200N"),
    "frequency": ("Hz", "Hz", "20Hz"),
    "angular_frequency": ("rad/s", "rad/s", "2513rad/s"),
    "time": ("s", "s", "2s"),
    "pressure": ("Pa", "GPa", "206GPa"),
    "velocity": ("m/s", "m/s", "0.1m/s"),
    "acceleration": ("m/s^2", "m/s^2", "100m/s^2"),
    "damping": ("N s/m", "N*s/m", "50N*s/m"),
    "rate": ("1/s", "/s", "0.5/s"),
    "dimensionless": ("", "", "0.3"),
}

#: The SI unit each kind of quantity is converted to, by name.
SI_UNITS: dict[str, str] = {kind: si for kind, (si, _, _) in _KINDS.items()}

#: A unit to show after a bare number in the "give a unit" message, per kind.
UNIT_HINTS: dict[str, str] = {kind: hint for kind, (_, hint, _) in _KINDS.items()}

#: A value of each kind that parses, for error messages.
EXAMPLES: dict[str, str] = {kind: example for kind, (_, _, example) in _KINDS.items()}

#: The SI unit a result's name ends with ("energy_per_cycle_j" is in J), longest ending first.
NAME_SUFFIX_UNITS: tuple[tuple[str, str], ...] = (
    ("_n_per_m", "N/m"),
    ("_hz", "Hz"),
    ("_kg", "kg"),
    ("_j", "J"),
    ("_m", "m"),
    ("_n", "N"),
)


def unit_of_name(name: str, dimensionless: str = "") -> str:
    """The SI unit of a result named by :data:`NAME_SUFFIX_UNITS` (else ``dimensionless``)."""
    return next((unit for end, unit in NAME_SUFFIX_UNITS if name.endswith(end)), dimensionless)


#: The number a quantity's text must start with (pint would read "mm" as 1 mm).
#: One comma between two digits, as in '0,106mm': a decimal comma.
_DECIMAL_COMMA = re.compile(r"[^,]*\d,\d[^,]*")
_LEADING_NUMBER = re.compile(r"^[+-]?((\d+\.?\d*|\.\d+)(e[+-]?\d+)?|nan|inf)", re.IGNORECASE)
#: A second number right after the first, which pint multiplies: "1 000 mm" is 0 mm.
_SECOND_NUMBER = re.compile(r"^\s*(?!1\s*/)[\d.(]")  # "50 1/s" is one number and a unit

_KIND_OF_UNIT = {unit: kind for kind, unit in SI_UNITS.items()}
_TWO_PI = 2.0 * math.pi

Bare = Literal["si", "refuse"]


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry[float]:
    """The one pint registry (built on first use: it takes a fraction of a second)."""
    import pint

    return pint.UnitRegistry()


def kind_of(unit: str) -> str:
    """The kind of quantity whose SI unit is ``unit`` ("m" -> "length"; "" -> dimensionless)."""
    try:
        return _KIND_OF_UNIT[unit]
    except KeyError:
        raise ValueError(f"no kind of quantity has the SI unit {unit!r}") from None


def is_quantity(value: Any) -> bool:
    """True for a pint Quantity (checked without importing pint)."""
    return type(value).__module__.startswith("pint") and hasattr(value, "magnitude")


def _convert(quantity: Any, kind: str, name: str, raw: str) -> Any:
    """Magnitude of a pint quantity in the SI unit of ``kind`` (float or array)."""
    import pint

    si = SI_UNITS[kind]
    example = EXAMPLES[kind]
    root = quantity.to_root_units()
    turns = dict(root.unit_items()).get("radian", 0)
    try:
        if kind == "rate":
            return _rate(quantity, root, turns, name, raw)
        if kind in ("frequency", "angular_frequency") and turns == 1:
            radians_per_second = root.to("radian / second").magnitude
            return radians_per_second / _TWO_PI if kind == "frequency" else radians_per_second
        if kind in ("frequency", "angular_frequency"):
            if turns != 0:
                raise pint.errors.DimensionalityError(quantity.units, "Hz")
            hertz = quantity.to("Hz").magnitude
            cycles = any("hertz" in unit for unit, _ in quantity.unit_items())
            if kind == "angular_frequency" and not cycles:
                raise ParameterError(
                    f"{name}: {raw!r} is ambiguous for an angular frequency (1/s is rad/s in "
                    f"SI but Hz to many); write it in rad/s or Hz, like {example} or 400Hz"
                )
            return hertz if kind == "frequency" else hertz * _TWO_PI
        return quantity.to(si if si else "dimensionless").magnitude
    except pint.errors.DimensionalityError:
        kind_words = kind.replace("_", " ")
        raise ParameterError(
            f"{name}: {raw!r} is not a {kind_words} (its unit is {quantity.units:~}); "
            f"write it like {example}"
        ) from None


def _rate(quantity: Any, root: Any, turns: int, name: str, raw: str) -> Any:
    """Magnitude in 1/s of a rate such as Rayleigh's alpha (it multiplies M, as omega does).

    The radian is a pure number here (alpha = 2 zeta omega is in rad/s, which is 1/s), so
    "2rad/s" and "2/s" are both 2 /s; Hz counts cycles and is refused as ambiguous by 2 pi.
    """
    import pint

    if any("hertz" in unit for unit, _ in quantity.unit_items()):
        raise ParameterError(
            f"{name}: {raw!r} is ambiguous for a rate in 1/s (Hz counts cycles, 2 pi apart "
            f"from rad/s); write it in 1/s or rad/s, like {EXAMPLES['rate']}"
        )
    if turns not in (0, 1):
        raise pint.errors.DimensionalityError(quantity.units, "1/s")
    plain = root / registry().radian if turns == 1 else root
    return plain.to("1/s").magnitude


def parse_quantity(text: str, kind: str, *, name: str, bare: Bare = "refuse") -> float:
    """Return ``text`` (e.g. ``"0.106mm"``) as a float in the SI unit of ``kind``.

    Parameters
    ----------
    text : str
        A number with a unit, e.g. ``"0.106mm"``, ``"8e7 N/m"``, ``"400rpm"``.
    kind : str
        A key of :data:`SI_UNITS`.
    name : str
        The option or key the text came from, for error messages.
    bare : {"refuse", "si"}
        What a number without a unit means: by default an error that shows how to
        write it (``--clearance 0.106: give a unit, e.g. 0.106mm``), or SI.
        Dimensionless kinds, and zero, always take bare numbers.

    Returns
    -------
    float
        The value in SI (frequency in Hz, angular frequency in rad/s).

    Raises
    ------
    ParameterError
        The text is not a number with a unit, or its unit is not a ``kind``;
        the message names ``name`` and an example that would work.
    """

    example = EXAMPLES[kind]
    raw = text.strip()
    if not raw:
        raise ParameterError(f"{name}: empty value; give a {kind} such as {example}")
    if "," in raw:
        if _DECIMAL_COMMA.fullmatch(raw):
            raise ParameterError(
                f"{name} {raw}: write the decimal point as '.', e.g. {raw.replace(',', '.')}"
            )
        # '1um,5um' is a list, not a decimal comma: '1um.5um' would be no fix
        raise ParameterError(f"{name} {raw}: give one {kind} here, not a list, e.g. {example}")
    number = _LEADING_NUMBER.match(raw)
    if not number:
        raise ParameterError(
            f"{name}: cannot read {raw!r} as a {kind}; start with the number, e.g. {example}"
        )
    if _SECOND_NUMBER.match(raw[number.end() :]):
        raise ParameterError(
            f"{name}: cannot read {raw!r} as a {kind}; write one number, then its unit "
            f"(pint multiplies numbers side by side: '1 000 mm' is 0 mm), e.g. {example}"
        )
    ureg = registry()
    try:
        quantity: Any = ureg.Quantity(raw)
    except Exception as exc:  # pint's parser raises many types on odd text
        raise ParameterError(
            f"{name}: cannot read {raw!r} as a {kind} ({exc}); write it like {example}"
        ) from None
    if isinstance(quantity, int | float) or quantity.unitless:
        # "1%" is unitless with magnitude 1: its value is 0.01
        plain = isinstance(quantity, int | float)
        magnitude = quantity if plain else quantity.to("dimensionless").magnitude
        if kind != "dimensionless" and bare == "refuse" and magnitude != 0:
            if not math.isfinite(magnitude):
                raise ParameterError(f"{name} {raw}: not a finite number; write it like {example}")
            raise ParameterError(f"{name} {raw}: give a unit, e.g. {raw}{UNIT_HINTS[kind]}")
        return float(magnitude)
    return float(_convert(quantity, kind, name, raw))


def parse_quantity_list(text: str, kind: str, *, name: str, bare: Bare = "refuse") -> list[float]:
    """Return a comma-separated list such as ``"1um,5um,20um"`` as SI floats."""
    parts = [part for part in text.split(",")]
    if not parts or any(not part.strip() for part in parts):
        raise ParameterError(f"{name}: {text!r} has an empty entry; write it like 1um,5um,20um")
    return [parse_quantity(part, kind, name=name, bare=bare) for part in parts]


def to_si(value: Any, unit: str, *, name: str) -> Any:
    """Return ``value`` in the SI ``unit``: a pint Quantity or a unit string is converted,
    anything else (a float, an array: already SI) is returned unchanged. Text
    without a unit ("0.106") is refused for a dimensional quantity, as on the
    command line: a bare *number* is SI, bare *text* is ambiguous.

    This is the one helper through which the Python API accepts units: the
    validators of ``clearjoint.checks`` call it, so ``Joint(mass="2kg", ...)`` and
    ``steady_state(joint, "1kN", "400Hz")`` work. ``unit`` is an SI unit of
    :data:`SI_UNITS` ("m", "N/m", "rad/s", "" for dimensionless).

    Raises
    ------
    ParameterError
        The unit is not of the dimension ``unit`` needs, or the text does not parse.
    """
    if isinstance(value, str):  # text carries its unit, as on the command line
        return parse_quantity(value, kind_of(unit), name=name, bare="refuse")
    if is_quantity(value):
        kind = kind_of(unit)
        raw = f"{value:~}"
        if value.unitless:
            magnitude = value.to("dimensionless").magnitude
        else:
            magnitude = _convert(value, kind, name, raw)
        return float(magnitude) if np.ndim(magnitude) == 0 else np.asarray(magnitude, float)
    return value


def parse_amplitude_range(text: str, points: int, *, name: str = "--amplitude") -> Any:
    """Return ``points`` lengths (m) spaced logarithmically over a range like ``1um..1mm``.

    One value (``20um``) gives itself. The range must start above zero (a mode has no
    amplitude 0), have a width and run upwards; ``points`` must be >= 1 (``--points``).
    """
    if points < 1:
        raise ParameterError(f"--points must be >= 1, got {points}")
    parts = text.split("..")
    if len(parts) > 2:
        raise ParameterError(f"{name}: write a range like 1um..1mm, got {text!r}")
    values = [parse_quantity(part, "length", name=name) for part in parts]
    if any(not value > 0.0 for value in values):
        raise ParameterError(
            f"{name} must start above zero (a mode has no amplitude 0), got {text!r}; "
            "write it like 1um..1mm"
        )
    if len(values) == 1:
        return np.array(values)
    if values[0] == values[1]:
        raise ParameterError(f"{name} range {text!r} has zero width; give two values")
    if values[0] > values[1]:
        raise ParameterError(
            f"{name} range {text!r} runs downwards; write it from the smaller amplitude "
            f"to the larger, {parts[1].strip()}..{parts[0].strip()}"
        )
    return np.geomspace(values[0], values[1], points)
