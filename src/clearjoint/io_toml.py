"""The one reader for TOML files with units: study files, rig campaigns, record metadata.

A value is a quantity with its unit, ``clearance = "0.106mm"``, converted to SI
by its dimension (``clearjoint.units``). A bare number is taken only where it
cannot be misread: for a dimensionless key (``damping_ratio = 0.01``), for zero,
or for a key whose name ends in its SI unit (``frequency_hz = 400``,
``clearance_m = 1.06e-4``; the suffixes are :data:`UNIT_SUFFIXES`). Anything
else, ``clearance = 0.106``, is refused with the line that shows how to write
it. Unknown keys are refused too (they are almost always typos). Every error
names the file and the key, in the caller's own error class.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.units import UNIT_HINTS, parse_quantity

#: The key suffix that names each kind's SI unit: a key ending in it takes a bare number.
UNIT_SUFFIXES: dict[str, str] = {
    "length": "m",
    "mass": "kg",
    "stiffness": "n_per_m",
    "force": "n",
    "frequency": "hz",
    "time": "s",
    "pressure": "pa",
    "velocity": "m_per_s",
    "acceleration": "m_per_s2",
    "damping": "n_s_per_m",
    "rate": "per_s",
}

#: Kinds that are not quantities: checked for their type only.
PLAIN_KINDS = ("text", "count", "dimensionless", "bool")


def read_toml(path: str | Path, *, what: str, error: type[ClearjointError]) -> dict[str, Any]:
    """Return the tables of the TOML file ``path``, or raise ``error`` in one line.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What the file is ("study", "campaign"), for the messages.
    error : type
        The ClearjointError subclass to raise.

    Raises
    ------
    error
        The path is missing, a folder, unreadable, not text, empty or not TOML;
        the message names the path and says what was expected.
    """
    path = Path(path)
    where = str(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise error(f"{where}: no such {what} file") from None
    except IsADirectoryError:
        raise error(f"{where}: is a folder; give a {what} file (TOML)") from None
    except OSError as exc:
        raise error(f"{where}: cannot read the {what} file ({exc.strerror})") from None
    if not data.strip():
        raise error(f"{where}: empty file; a {what} file is TOML, see the documented example")
    try:
        text = data.decode("utf-8-sig")  # Windows editors may start the file with a BOM
    except UnicodeDecodeError:
        raise error(f"{where}: not a text file; a {what} file is TOML") from None
    if "\x00" in text:
        raise error(f"{where}: a binary file; a {what} file is TOML")
    return parse_toml(text, where=where, what=what, error=error)


def parse_toml(text: str, *, where: str, what: str, error: type[ClearjointError]) -> dict[str, Any]:
    """Return the tables of TOML ``text``; a syntax error becomes one line naming ``where``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{where}: not valid TOML, so not a {what} file ({exc})") from None


def quantity(
    raw: Any,
    kind: str,
    *,
    name: str,
    error: type[ClearjointError],
    unit_in_key: bool = False,
    unit_keys: bool = True,
) -> Any:
    """Return one value of a TOML file in SI (or as text, a whole number, a flag).

    Parameters
    ----------
    raw : Any
        The value as TOML gave it.
    kind : str
        A kind of :data:`clearjoint.units.SI_UNITS`, or "text", "count", "bool".
    name : str
        ``"FILE: [section] key"``, for the messages.
    error : type
        The ClearjointError subclass to raise.
    unit_in_key : bool
        The key names the SI unit (``frequency_hz``): a bare number is that unit.
    unit_keys : bool
        The file takes keys that name their unit: the message for a bare number
        suggests one. False where it does not (a sweep's axes, a campaign).

    Raises
    ------
    error
        The value has the wrong type, lacks a unit, or its unit is of another dimension.
    """
    if kind == "text":
        if not isinstance(raw, str):
            raise error(f"{name} must be text in quotes, got {raw!r}")
        return raw
    if kind == "bool":
        if not isinstance(raw, bool):
            raise error(f"{name} must be true or false, got {raw!r}")
        return raw
    if kind == "count":
        if isinstance(raw, bool) or not isinstance(raw, int):
            raise error(f"{name} must be a whole number, got {raw!r}")
        return raw
    if isinstance(raw, bool) or not isinstance(raw, int | float | str):
        raise error(f"{name} must be a number or a quantity with a unit, got {raw!r}")
    if isinstance(raw, int | float):
        if kind == "dimensionless" or unit_in_key or raw == 0:
            return float(raw)
        hint = f'{name} = {raw}: give a unit, e.g. "{raw}{UNIT_HINTS[kind]}"'
        if not unit_keys:
            raise error(hint)
        key = name.rsplit(" ", 1)[-1]
        raise error(f"{hint}, or name the SI unit in the key ({key}_{UNIT_SUFFIXES[kind]} = {raw})")
    if unit_in_key:
        raise error(f"{name} = {raw!r}: the key names its unit, so give a bare number")
    try:
        return parse_quantity(raw, kind, name=name, bare="refuse")
    except ParameterError as exc:
        raise error(str(exc)) from None


def read_table(
    table: Mapping[str, Any],
    spec: Mapping[str, str],
    *,
    where: str,
    section: str,
    error: type[ClearjointError],
) -> dict[str, Any]:
    """Return the keys of ``table`` that ``spec`` knows, each in SI; refuse unknown keys.

    Parameters
    ----------
    table : mapping
        One TOML table.
    spec : mapping
        Key -> kind ("length", "frequency", ..., "text", "count", "bool").
        A quantity key ``k`` may also be given as ``k_<SI unit>`` (``frequency_hz``)
        with a bare number.
    where, section : str
        The file and the table's name (``"[joint]"``, or ``""`` at the top), for messages.
    error : type
        The ClearjointError subclass to raise.

    Returns
    -------
    dict
        Key (as in ``spec``) -> value in SI, for the keys the table gives.
    """
    if not isinstance(table, Mapping):
        raise error(f"{where}: {section or 'the file'} must be a table")
    aliases = {
        f"{key}_{UNIT_SUFFIXES[kind]}": key for key, kind in spec.items() if kind in UNIT_SUFFIXES
    }
    unknown = sorted(set(table) - set(spec) - set(aliases))
    if unknown:
        place = f" in {section}" if section else ""
        raise error(f"{where}: unknown key(s) {unknown}{place}; known: {sorted(spec)}")
    out: dict[str, Any] = {}
    prefix = f"{where}: {section} " if section else f"{where}: "
    for given, raw in table.items():
        key = aliases.get(given, given)
        if key in out:
            raise error(f"{where}: {key} is given twice ({key} and {given}); keep one")
        out[key] = quantity(
            raw, spec[key], name=f"{prefix}{given}", error=error, unit_in_key=given in aliases
        )
    return out


__all__ = ["UNIT_SUFFIXES", "parse_toml", "quantity", "read_table", "read_toml"]
