"""CSV records: clearjoint's own layout with a header block, and lab files with a sidecar.

Two layouts, one reader (docs/records.md):

* clearjoint's CSV: a ``# clearjoint record 1`` header block of ``key = value`` lines
  (TOML), then a column line ``time [s],force [N],displacement [mm],...`` whose units
  are converted to SI; :func:`~clearjoint.records.write_record` writes this one.
* a lab CSV: whatever a DAQ or a spreadsheet exported (delimiter, decimal comma,
  preamble, units in the names or in a row under them, rounded time stamps), with its
  metadata in a sidecar ``<name>.toml`` beside it.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint.records.record import (
    CHANNELS,
    SI,
    UNIFORM_TOLERANCE,
    FloatArray,
    Record,
    RecordError,
    RecordWarning,
    _assemble,
    _factor,
)
from clearjoint.units import SI_UNITS, registry

__all__ = [
    "CSV_MAGIC",
    "SIDECAR_SUFFIX",
    "regular_time",
    "sidecar_path",
]

CSV_MAGIC = "# clearjoint record 1"
#: The ending of a lab CSV's sidecar: ``test.csv`` keeps its metadata in ``test.toml``.
SIDECAR_SUFFIX = ".toml"


def sidecar_path(path: Path) -> Path:
    """Return the sidecar TOML file that holds a lab CSV's metadata (it may not exist)."""
    return path.with_suffix(SIDECAR_SUFFIX)


#: Metadata keys of the CSV header and sidecar, with the kind of quantity (or text).
#: A quantity takes its unit (``clearance = "0.106mm"``), or a bare number in a key that
#: names the SI unit (``clearance_m = 1.06e-4``, ``frequency_hz = 20``).
_META_KINDS = {
    "joint_id": "text",
    "control": "text",
    "notes": "text",
    "clearance": "length",
    "force_amplitude": "force",
    "displacement_amplitude": "length",
    "frequency": "frequency",
    "mass": "mass",
}
_SUFFIX = {
    "clearance": "m",
    "force_amplitude": "n",
    "displacement_amplitude": "m",
    "frequency": "hz",
    "mass": "kg",
}


def _metadata_from_toml(where: str, table: dict[str, Any]) -> dict[str, Any]:
    """Record metadata from a header block or sidecar, in SI (io_toml: units or unit keys)."""
    from clearjoint.io_toml import read_table

    unknown = sorted(set(table) - set(_META_KINDS) - {f"{k}_{_SUFFIX[k]}" for k in _SUFFIX})
    if unknown:
        raise RecordError(f"{where}: unknown metadata {unknown}; known: {sorted(_META_KINDS)}")
    values = read_table(table, _META_KINDS, where=where, section="", error=RecordError)
    return {("frequency_hz" if key == "frequency" else key): val for key, val in values.items()}


_DELIMITERS = ("\t", ";", ",")
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
_COMMENT = re.compile(r"^\s*(#|//|;|%|!)")
_NAME_UNIT = re.compile(
    r"^\s*(?P<name>[A-Za-z][A-Za-z _]*?)\s*(?:[\[(](?P<unit>[^\])]*)[\])])?\s*$"
)
#: Rows a block must hold to count as the data (and not a preamble line of numbers).
_DATA_ROWS = 4
#: The data must start within this many lines (a DAQ preamble is a few dozen).
_PREAMBLE_LINES = 1000


def _decode(where: str, data: bytes) -> str:
    """A lab file's text: UTF-8 (with or without a BOM), UTF-16 with its BOM (Excel's
    "Unicode text"), else Latin-1 (Windows DAQ software)."""
    if data.startswith(_UTF16_BOMS):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            raise RecordError(f"{where}: starts as UTF-16 text but does not decode as it") from None
    if b"\x00" in data[:4096]:
        raise RecordError(f"{where}: a binary file of unknown format; not a record")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _fields(line: str, delimiter: str) -> list[str]:
    """The cells of one line, unquoted; a trailing delimiter (common in DAQ exports) ignored."""
    cells = [cell.strip().strip('"').strip() for cell in line.rstrip("\r\n").split(delimiter)]
    return cells[:-1] if len(cells) > 1 and not cells[-1] else cells


def _numbers(fields: list[str], decimal_comma: bool) -> bool:
    try:
        for field in fields:
            float(field.replace(",", ".") if decimal_comma else field)
    except ValueError:
        return False
    return True


def _data_start(lines: list[str], delimiter: str) -> tuple[int, int] | None:
    """Index of the first line of the numeric block under ``delimiter`` and its width.

    The block a header names wins: numbers in the preamble (a calibration table, a
    line of settings) come first in the file but have no channel names above them.
    Without a named block, the first block of numbers (the caller says what is missing).
    """
    comma = delimiter != ","
    first: tuple[int, int] | None = None
    for i, line in enumerate(lines[:_PREAMBLE_LINES]):
        if delimiter not in line:
            continue
        fields = _fields(line, delimiter)
        if len(fields) < 2 or not _numbers(fields, comma):
            continue
        following = [x for x in lines[i : i + 3 * _DATA_ROWS] if x.strip()][:_DATA_ROWS]
        rows = [_fields(x, delimiter) for x in following]
        if all(len(r) == len(fields) and _numbers(r, comma) for r in rows):
            if _header_above(lines, i, delimiter) is not None:
                return i, len(fields)
            first = first or (i, len(fields))
    return first


def _names_a_channel(line: str, delimiter: str) -> bool:
    """True when a cell of ``line`` names a record channel (``time [s]``, ``Force``)."""
    for cell in _fields(line, delimiter):
        match = _NAME_UNIT.match(cell)
        if match and match["name"].strip().lower().replace(" ", "_") in SI:
            return True
    return False


def _blank(line: str, delimiter: str) -> bool:
    """A blank line, or a row of delimiters alone (``;;``, a blank spreadsheet row)."""
    return not line.strip().strip(delimiter).strip()


def _header_above(lines: list[str], start: int, delimiter: str) -> tuple[int, int | None] | None:
    """The lines of the column names and of the units row (or None) above the numbers.

    The names are the last line above the numbers, or the one above it when that last
    line is a row of units; None when neither names a channel (no header).
    """
    above = [i for i in range(start) if not _blank(lines[i], delimiter)][-2:]
    if not above:
        return None
    last = above[-1]
    if _names_a_channel(lines[last], delimiter):
        return last, None
    units = len(above) == 2 and _units_row(_fields(lines[last], delimiter))
    if units and _names_a_channel(lines[above[0]], delimiter):
        return above[0], last
    return None


def _preamble_note(line: str, delimiter: str) -> str:
    """One preamble line as a note: as written, less a comment's mark and the empty
    cells a spreadsheet leaves at its end (``Device;Rig A;;`` is ``Device;Rig A``)."""
    comment = _COMMENT.match(line)
    if comment:
        return line[comment.end() :].strip()
    return line.strip().rstrip(delimiter).strip()


def _units_row(fields: list[str]) -> bool:
    """True when every field reads as a unit and none as a channel name."""

    ureg = registry()
    for cell in fields:
        text = cell.strip("[]() ")
        if text.lower() in SI:
            return False
        try:
            ureg.Unit(text)
        except Exception:  # pint's parser raises many types on odd text
            return False
    return True


def _resolution(texts: list[str]) -> FloatArray:
    """The resolution each time stamp is written to: 10^-decimals, less its exponent.

    Per stamp, since in scientific notation ("8.333333e-05", "1.999167e-01") the
    resolution grows with the stamp: one figure for the whole column, the finest,
    would call a uniform clock written with ``%.6e`` uneven.
    """
    places = []
    for text in texts:
        mantissa, _, exponent = text.lower().replace(",", ".").partition("e")
        places.append(len(mantissa.partition(".")[2]) - (int(exponent) if exponent else 0))
    return np.power(10.0, -np.asarray(places, dtype=np.float64))


def regular_time(time: FloatArray, resolution: float | FloatArray) -> tuple[FloatArray, float]:
    """A uniform clock t0 + i dt fitted to time stamps rounded to ``resolution``.

    Stamps of a uniform clock rounded to its resolution (12 kHz written to 1 us)
    have steps that differ by up to the resolution: that is rounding, not uneven
    sampling. ``resolution`` may differ from stamp to stamp (scientific notation):
    each stamp then weighs in by 1 / its resolution. Returns the fitted uniform
    times and the largest distance of a stamp from them, in units of its own
    resolution; the caller accepts the fit only when that is at most 1.
    """
    index = np.arange(time.size, dtype=np.float64)
    scale = np.broadcast_to(np.asarray(resolution, dtype=np.float64), time.shape)
    slope, intercept = np.polyfit(index, time, 1, w=1.0 / scale)
    uniform = intercept + slope * index
    return uniform, float(np.max(np.abs(time - uniform) / scale))


def _read_csv(path: Path, resample_: bool) -> Record:
    """Read a CSV record: clearjoint's own layout or a lab file (docs/records.md).

    Tolerated: the delimiter (comma, semicolon, tab; sniffed), a decimal comma (with a
    semicolon or tab delimiter), any preamble above the column names (free text, key and
    value, comments, numbers: kept as the record's notes, one "; " between lines), units
    in the names (``time [s]``, ``Force (kN)``) or in a row under them, and time stamps
    rounded to the clock's resolution. The column names are the line above the numbers
    (or above their row of units) that names a channel; without one, one error line.
    """
    where = str(path)
    lines = _decode(where, path.read_bytes()).splitlines()
    meta: dict[str, Any] = {}
    body = 0
    if lines and lines[0].strip() == CSV_MAGIC:
        body = 1
        while body < len(lines) and lines[body].startswith("#"):
            body += 1
        block = [line[1:].strip() for line in lines[1:body]]
        from clearjoint.io_toml import parse_toml

        table = parse_toml("\n".join(block), where=where, what="record header", error=RecordError)
        meta = _metadata_from_toml(where, table)
    else:
        sidecar = sidecar_path(path)
        if sidecar.exists():
            from clearjoint.io_toml import read_toml

            table = read_toml(sidecar, what="record metadata", error=RecordError)
            meta = _metadata_from_toml(str(sidecar), table.get("record", table))
    found = {d: _data_start(lines[body:], d) for d in _DELIMITERS}
    candidates = [  # a block under column names first, then the widest
        (_header_above(lines[body:], hit[0], d) is not None, hit[1], d)
        for d, hit in found.items()
        if hit is not None
    ]
    if not candidates:
        _no_numbers(where, lines[body:], body)
        raise RecordError(
            f"{where}: no block of numbers found; a CSV record has columns time, force and "
            "displacement separated by commas, semicolons or tabs"
        )
    *_, delimiter = max(candidates)
    start, width = found[delimiter]  # type: ignore[misc]
    start += body
    header = _header_above(lines, start, delimiter)
    if header is None or header[0] < body:
        above = [i for i in range(body, start) if not _blank(lines[i], delimiter)]
        shown = f" (line {above[-1] + 1}: {lines[above[-1]].strip()[:40]!r})" if above else ""
        raise RecordError(
            f"{where}: no column names above the numbers{shown}; name them like "
            "'time [s]', 'force [N]', 'displacement [mm]' on the line above the numbers"
        )
    header_at, units_at = header
    unit_fields = None if units_at is None else _fields(lines[units_at], delimiter)
    names = _fields(lines[header_at], delimiter)
    checks = [(header_at, "names", names)]
    if units_at is not None and unit_fields is not None:
        checks.append((units_at, "has units for", unit_fields))
    for line_at, what, row in checks:
        if len(row) != width:
            raise RecordError(
                f"{where}: line {line_at + 1} {what} {len(row)} columns but the numbers under "
                f"it have {width}; check the delimiter {delimiter!r} and the column names"
            )
    # every line above the names (free text, key and value, comment) is kept as a note
    notes = [_preamble_note(lines[i], delimiter) for i in range(body, header_at)]
    notes = [note for note in notes if note]
    if notes:
        preamble = "; ".join(notes)
        meta["notes"] = f"{meta['notes']}; {preamble}" if meta.get("notes") else preamble
    channels: list[tuple[str, str]] = []
    ignored: list[str] = []  # columns a record has no channel for (a temperature, ...)
    for k, name_text in enumerate(names):
        match = _NAME_UNIT.match(name_text)
        name = match["name"].strip().lower().replace(" ", "_") if match else ""
        if match is None or name not in SI:
            ignored.append(name_text.strip())
            channels.append(("", ""))  # keeps each channel at its column
            continue
        unit = (match["unit"] or "").strip()
        if unit_fields is not None and not unit:
            unit = unit_fields[k].strip("[]() ")
        if not unit:
            raise RecordError(
                f"{where}: column {name_text!r} has no unit; name columns like "
                "'time [s]', 'force [N]', 'displacement [mm]', or put a row of units under them"
            )
        channels.append((name, unit))
    import io

    import pandas as pd

    rows = lines[start:]
    try:
        frame = pd.read_csv(
            io.StringIO("\n".join(rows)),
            sep=delimiter,
            header=None,
            decimal="," if delimiter != "," and any("," in r for r in rows[:100]) else ".",
            skipinitialspace=True,
            dtype=np.float64,
        )
    except (ValueError, pd.errors.ParserError) as exc:
        raise RecordError(f"{where}: a column is not numeric ({exc})") from None
    if frame.shape[1] == width + 1 and frame.iloc[:, -1].isna().all():
        frame = frame.iloc[:, :-1]  # the empty cell after a trailing delimiter
    table_ = frame.to_numpy(dtype=np.float64)
    if table_.shape[1] != width:
        raise RecordError(f"{where}: rows of {table_.shape[1]} values under {width} column names")
    columns: dict[str, FloatArray] = {}
    units: dict[str, str] = {}
    for k, (name, unit) in enumerate(channels):
        if name:
            columns[name] = table_[:, k] * _factor(where, name, unit)
            units[name] = unit
    if ignored:
        missing = [c for c in ("time", "force", "displacement") if c not in columns]
        shown = ", ".join(repr(c) for c in ignored)
        if missing:
            raise RecordError(
                f"{where}: no {missing[0]} column, and no channel for {shown}; a record has "
                f"columns {', '.join(SI)}: rename the column that holds {missing[0]}"
            )
        import warnings

        warnings.warn(
            f"{where}: ignored column(s) {shown}: a record has no such channel (it reads "
            f"{', '.join(SI)})",
            RecordWarning,
            stacklevel=3,
        )
    if "time" in columns:
        columns["time"] = _clock(where, columns["time"], rows, delimiter, channels, resample_)
    return _assemble(where, columns, units, meta, resample_)


def _no_numbers(where: str, lines: list[str], offset: int) -> None:
    """Raise the error for column names over rows that are not all numbers, if so."""
    for delimiter in _DELIMITERS:
        for i, line in enumerate(lines[:_PREAMBLE_LINES]):
            fields = _fields(line, delimiter)
            matches = [_NAME_UNIT.match(f) for f in fields]
            if len(fields) >= 2 and all(m and m["name"].strip().lower() in SI for m in matches):
                below = [(j, x) for j, x in enumerate(lines[i + 1 :], start=i + 1) if x.strip()]
                if below:
                    j, row = below[0]
                    if _units_row(_fields(row, delimiter)) and len(below) > 1:
                        j, row = below[1]
                    raise RecordError(
                        f"{where}: the rows under the column names are not numeric "
                        f"(line {offset + j + 1}: {row.strip()[:40]!r})"
                    )


def _clock(
    where: str,
    time: FloatArray,
    rows: list[str],
    delimiter: str,
    channels: list[tuple[str, str]],
    resample_: bool,
) -> FloatArray:
    """The time column, made uniform when its steps differ only by the stamps' rounding."""
    step = np.diff(time)
    if step.size == 0 or np.any(step <= 0.0):
        return time
    if np.ptp(step) <= UNIFORM_TOLERANCE * np.mean(step):
        return time
    k = [name for name, _ in channels].index("time")
    factor = _factor(where, "time", channels[k][1])
    stamps = [_fields(row, delimiter)[k] for row in rows if row.strip()]
    resolution = _resolution(stamps) * factor
    uniform, ratio = regular_time(time, resolution)
    if ratio <= 1.0:  # every stamp within its own resolution of the fitted clock
        return uniform
    worst = int(np.argmax(np.abs(time - uniform) / resolution))
    stray, resolution_at = float(abs(time[worst] - uniform[worst])), float(resolution[worst])
    if resample_:
        return time  # uneven beyond the rounding: _assemble interpolates it
    raise RecordError(
        f"{where}: not uniformly sampled: time stamps stray up to {stray:.3g} s from a uniform "
        f"clock, beyond their resolution {resolution_at:.3g} s; read it with resample=True "
        "(--resample) to interpolate onto a uniform grid"
    )


def _write_csv(record: Record, path: Path) -> None:
    meta = record.metadata()
    lines = [CSV_MAGIC]
    for key, kind in _META_KINDS.items():
        source_key = "frequency_hz" if key == "frequency" else key
        value = meta.get(source_key)
        if value in (None, ""):
            continue
        if kind == "text":
            lines.append(f"# {key} = {json.dumps(str(value))}")
        else:
            unit = SI_UNITS[kind]
            lines.append(f'# {key} = "{value!r} {unit}"')
    names = ["time", *[c for c in CHANNELS if getattr(record, c) is not None]]
    lines.append(",".join(f"{name} [{SI[name]}]" for name in names))
    data = np.column_stack([getattr(record, name) for name in names])
    with path.open("w", encoding="utf-8", newline="\n") as handle:
        handle.write("\n".join(lines) + "\n")
        np.savetxt(handle, data, delimiter=",", fmt="%.17g")
