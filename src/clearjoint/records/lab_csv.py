"""Test records: time, force and displacement with their metadata, in real file formats.

A :class:`Record` is validated when it is made (strictly increasing, uniformly
sampled, finite, long enough for three cycles); everything inside is SI with the
frequencies in Hz, as in files. Formats, recognised by their content:

* CSV: a ``# clearjoint record 1`` header block of ``key = value`` lines (TOML),
  then a column line ``time [s],force [N],displacement [mm],...`` whose units
  are converted to SI; or a plain CSV with a sidecar ``<name>.toml`` beside it.
* netCDF / HDF5, written through xarray (h5netcdf engine) and read back with h5py:
  variables ``time``, ``force``, ``displacement`` (and ``velocity``,
  ``acceleration``) with ``units`` attributes, metadata as global attributes.
* The BRFD JSON files of the friction-damper-with-backlash data set (inches,
  kips; see data/brfd/README.md), through :func:`read_brfd`.

The layouts are documented in docs/records.md. Nothing is overwritten unless asked.
"""

from __future__ import annotations

import gc
import itertools
import json
import math
import re
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint.checks import refuse_to_overwrite
from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.units import SI_UNITS, is_quantity, registry, to_si

FloatArray = NDArray[np.float64]

CSV_MAGIC = "# clearjoint record 1"
CHANNELS = ("force", "displacement", "velocity", "acceleration")
SI = {"time": "s", "force": "N", "displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}
#: Relative spread of the time step allowed in a "uniformly sampled" record.
UNIFORM_TOLERANCE = 1e-4
#: Cycles a record must span when its frequency is known.
MIN_CYCLES = 3
MIN_SAMPLES = 16
#: The SI unit of each metadata quantity (a pint Quantity or "0.1mm" is converted to it).
_META_SI = {
    "clearance": "m",
    "force_amplitude": "N",
    "displacement_amplitude": "m",
    "frequency_hz": "Hz",
    "mass": "kg",
}


class RecordError(ClearjointError, ValueError):
    """A record or a record file is unusable; the message names the file and the fix."""


class RecordWarning(UserWarning):
    """A record file was read, but part of it was left out (the message says which)."""


@dataclass(frozen=True)
class Record:
    """One test record in SI units (frequencies in Hz, as in files).

    Attributes
    ----------
    time : (N,) ndarray
        s, strictly increasing and uniformly sampled.
    force, displacement : (N,) ndarray
        N and m: the force on, and the displacement of, the jointed end.
    velocity, acceleration : (N,) ndarray or None
        m/s and m/s^2, when measured.
    control : {"force", "displacement"}
        What the test controlled: a force-controlled test's restoring force is
        force - m x''; a displacement-controlled test measures it directly.
    joint_id : str
    clearance : float or None
        Nominal clearance, m.
    force_amplitude, displacement_amplitude : float or None
        Nominal excitation amplitude, N or m.
    frequency_hz : float or None
        Nominal excitation frequency, Hz.
    mass : float or None
        Moving mass behind the force sensor, kg (for the inertia correction).
    units : dict
        The units each channel had in its file.
    notes, source : str
        Free-form notes; the file it came from.
    """

    time: FloatArray
    force: FloatArray
    displacement: FloatArray
    velocity: FloatArray | None = None
    acceleration: FloatArray | None = None
    control: str = "force"
    joint_id: str = ""
    clearance: float | None = None
    force_amplitude: float | None = None
    displacement_amplitude: float | None = None
    frequency_hz: float | None = None
    mass: float | None = None
    units: dict[str, str] = field(default_factory=dict)
    notes: str = ""
    source: str = ""

    def __post_init__(self) -> None:
        where = self.source or "record"
        set_ = object.__setattr__
        time = _channel(where, "time", self.time)
        n = time.size
        if n < MIN_SAMPLES:
            raise RecordError(f"{where}: only {n} samples; a record needs at least {MIN_SAMPLES}")
        set_(self, "time", time)
        for name in CHANNELS:
            value = getattr(self, name)
            if value is None:
                continue
            array = _channel(where, name, value)
            if array.size != n:
                raise RecordError(
                    f"{where}: {name} has {array.size} samples but time has {n}; "
                    "every channel must have one sample per time"
                )
            set_(self, name, array)
        step = np.diff(time)
        if np.any(step <= 0.0):
            i = int(np.argmax(step <= 0.0))
            raise RecordError(
                f"{where}: time is not strictly increasing (sample {i + 1}: "
                f"{time[i]!r} -> {time[i + 1]!r} s); sort the record or remove repeated samples"
            )
        spread = float(np.ptp(step) / np.mean(step))
        if spread > UNIFORM_TOLERANCE:
            raise RecordError(
                f"{where}: not uniformly sampled (time step from {step.min():.6g} to "
                f"{step.max():.6g} s); read it with resample=True (--resample) to interpolate "
                "onto a uniform grid"
            )
        if self.control not in ("force", "displacement"):
            raise RecordError(
                f"{where}: control must be 'force' or 'displacement', got {self.control!r}"
            )
        for name in (
            "clearance",
            "force_amplitude",
            "displacement_amplitude",
            "frequency_hz",
            "mass",
        ):
            value = getattr(self, name)
            if value is None:
                continue
            try:
                number = float(to_si(value, _META_SI[name], name=f"{where}: {name}"))
            except ParameterError as exc:  # a unit string without or with the wrong unit
                raise RecordError(str(exc)) from None
            except (TypeError, ValueError) as exc:
                raise RecordError(f"{where}: {name} must be a number, got {value!r}") from exc
            if not math.isfinite(number) or number < 0.0:
                raise RecordError(f"{where}: {name} must be finite and >= 0, got {value!r}")
            set_(self, name, number)
        if self.frequency_hz:
            cycles = (time[-1] - time[0]) * self.frequency_hz
            if cycles < MIN_CYCLES:
                # the one steady-cycle rule, word for word as every identification path
                # states it (imported here: clearjoint.identify imports this module)
                from clearjoint.identify.cycles import STEADY_RULE

                raise RecordError(
                    f"{where}: spans {cycles:.2f} cycles at {self.frequency_hz:g} Hz; {STEADY_RULE}"
                )

    @property
    def sampling_rate(self) -> float:
        """Samples per second, Hz."""
        return float((self.time.size - 1) / (self.time[-1] - self.time[0]))

    def metadata(self) -> dict[str, Any]:
        """The metadata fields (everything but the arrays) as a plain dict."""
        return {
            f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("time", *CHANNELS)
        }


def _channel(where: str, name: str, value: ArrayLike) -> FloatArray:
    if is_quantity(value):  # np.asarray would drop the unit: a time in ms read as s
        try:
            value = to_si(value, SI[name], name=f"{where}: {name}")
        except ParameterError as exc:
            raise RecordError(str(exc)) from None
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise RecordError(f"{where}: {name} is not numeric") from None
    if array.ndim != 1:
        raise RecordError(f"{where}: {name} must be one-dimensional, got shape {array.shape}")
    bad = ~np.isfinite(array)
    if bad.any():
        i = int(np.argmax(bad))
        raise RecordError(
            f"{where}: {name} has {int(bad.sum())} NaN or infinite values (first at sample {i}); "
            "remove or repair them before loading"
        )
    return array


def resample(
    time: ArrayLike, channels: dict[str, ArrayLike], rate: float | None = None
) -> tuple[FloatArray, dict[str, FloatArray]]:
    """Interpolate channels sampled at increasing ``time`` onto a uniform grid (linear).

    ``rate`` defaults to the median sampling rate. Returns (time, channels).
    """
    t = np.asarray(time, dtype=np.float64)
    order = np.argsort(t, kind="stable")
    t = t[order]
    keep = np.concatenate(([True], np.diff(t) > 0.0))
    t = t[keep]
    step = 1.0 / rate if rate else float(np.median(np.diff(t)))
    grid = np.arange(t[0], t[-1] + 0.5 * step, step)
    grid = grid[grid <= t[-1]]
    out = {
        name: np.interp(grid, t, np.asarray(values, dtype=np.float64)[order][keep])
        for name, values in channels.items()
    }
    return grid, out


# ---- units --------------------------------------------------------------------------------


#: Exact factors of the units most files use, so that reading them does not build pint's
#: registry (a second or two); tests/test_records.py checks each against pint.
FAST_FACTORS = {
    ("time", "s"): 1.0,
    ("force", "N"): 1.0,
    ("force", "kN"): 1e3,
    ("force", "kip"): 4448.2216152605,
    ("displacement", "m"): 1.0,
    ("displacement", "mm"): 1e-3,
    ("displacement", "um"): 1e-6,
    ("displacement", "in"): 0.0254,
    ("velocity", "m/s"): 1.0,
    ("velocity", "in/s"): 0.0254,
    ("acceleration", "m/s^2"): 1.0,
}


#: Standard gravity, m/s^2: accelerometers speak g, where pint's "g" is the gram.
STANDARD_GRAVITY = 9.80665
#: Spellings of standard gravity taken for an acceleration column (and for no other).
GRAVITY_UNITS = ("g", "gn", "g0")


def _factor(where: str, channel: str, unit: str) -> float:
    """The factor that takes ``channel`` in ``unit`` to SI; errors name the file and channel."""
    fast = FAST_FACTORS.get((channel, unit.strip()))
    if fast is not None:
        return fast
    if channel == "acceleration" and unit.strip() in GRAVITY_UNITS:
        return STANDARD_GRAVITY
    import pint

    target = SI[channel]
    try:
        return float(registry().Quantity(1.0, unit.strip()).to(target).magnitude)
    except pint.errors.DimensionalityError:
        raise RecordError(
            f"{where}: {channel} is in {unit!r}, which is not a unit of {target}; "
            "fix the unit in the file"
        ) from None
    except Exception:  # pint's parser raises many types on odd text ("(", "[")
        raise RecordError(
            f"{where}: unknown unit {unit!r} for {channel}; write a unit such as {target}"
        ) from None


# ---- CSV ----------------------------------------------------------------------------------

_COLUMN = re.compile(r"^\s*(?P<name>[A-Za-z_]+)\s*\[(?P<unit>[^\]]+)\]\s*$")

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
_KEY_VALUE = re.compile(r"^\s*(?P<key>[^:=,;\t]+?)\s*[:=,;\t]\s*(?P<value>.*)$")
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
    """Index of the first line of the numeric block under ``delimiter`` and its width."""
    comma = delimiter != ","
    for i, line in enumerate(lines[:_PREAMBLE_LINES]):
        if delimiter not in line:
            continue
        fields = _fields(line, delimiter)
        if len(fields) < 2 or not _numbers(fields, comma):
            continue
        following = [x for x in lines[i : i + 3 * _DATA_ROWS] if x.strip()][:_DATA_ROWS]
        rows = [_fields(x, delimiter) for x in following]
        if all(len(r) == len(fields) and _numbers(r, comma) for r in rows):
            return i, len(fields)
    return None


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
    semicolon or tab delimiter), a preamble of comment or key-value lines above the
    column names, units in the names (``time [s]``, ``Force (kN)``) or in a row under
    them, and time stamps rounded to the clock's resolution.
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
        sidecar = path.with_suffix(".toml")
        if sidecar.exists():
            from clearjoint.io_toml import read_toml

            table = read_toml(sidecar, what="record metadata", error=RecordError)
            meta = _metadata_from_toml(str(sidecar), table.get("record", table))
    found = {d: _data_start(lines[body:], d) for d in _DELIMITERS}
    candidates = [(hit[1], d) for d, hit in found.items() if hit is not None]
    if not candidates:
        _no_numbers(where, lines[body:], body)
        raise RecordError(
            f"{where}: no block of numbers found; a CSV record has columns time, force and "
            "displacement separated by commas, semicolons or tabs"
        )
    _, delimiter = max(candidates)
    start, width = found[delimiter]  # type: ignore[misc]
    start += body
    # a row of delimiters alone (";;", a blank spreadsheet row) is a blank line
    above = [i for i in range(body, start) if lines[i].strip().strip(delimiter).strip()]
    if not above:
        raise RecordError(
            f"{where}: no column names above the numbers; name them like "
            "'time [s]', 'force [N]', 'displacement [mm]'"
        )
    header_at = units_at = above.pop()
    unit_fields: list[str] | None = None
    if _units_row(_fields(lines[header_at], delimiter)) and above:
        unit_fields = _fields(lines[header_at], delimiter)
        header_at = above.pop()
    names = _fields(lines[header_at], delimiter)
    for line_at, what, row in (
        (header_at, "names", names),
        (units_at, "has units for", unit_fields),
    ):
        if row is not None and len(row) != width:
            raise RecordError(
                f"{where}: line {line_at + 1} {what} {len(row)} columns but the numbers under "
                f"it have {width}; check the delimiter {delimiter!r} and the column names"
            )
    notes = []
    for i in above:
        line = lines[i]
        if _COMMENT.match(line):
            continue
        pair = _KEY_VALUE.match(line)
        if not pair or not pair["value"].strip():
            raise RecordError(
                f"{where}: line {i + 1} ({line.strip()[:40]!r}) above the column names is "
                "neither a comment (#, //) nor a key and value; remove it or comment it out"
            )
        notes.append(f"{pair['key'].strip()}: {pair['value'].strip().strip(chr(34))}")
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


def _assemble(
    where: str,
    columns: dict[str, Any],
    units: dict[str, str],
    meta: dict[str, Any],
    resample_: bool,
) -> Record:
    for required in ("time", "force", "displacement"):
        if required not in columns:
            raise RecordError(
                f"{where}: no {required} channel; a record needs time, force and displacement"
            )
    time = columns.pop("time")
    if resample_:
        step = np.diff(time)
        if step.size and (np.any(step <= 0) or np.ptp(step) > UNIFORM_TOLERANCE * np.mean(step)):
            time, columns = resample(time, columns)
    return Record(time=time, units=units, source=where, **columns, **meta)


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


# ---- netCDF / HDF5 ------------------------------------------------------------------------

_NC_META = {
    "joint_id": "joint_id",
    "control": "control",
    "notes": "notes",
    "clearance_m": "clearance",
    "force_amplitude_n": "force_amplitude",
    "displacement_amplitude_m": "displacement_amplitude",
    "frequency_hz": "frequency_hz",
    "mass_kg": "mass",
}


def _read_netcdf(path: Path, resample_: bool) -> Record:
    """Read the HDF5 layer of a netCDF-4 file with h5py: the variables are its datasets.

    Writing goes through xarray (h5netcdf engine); reading a handful of 1-D variables
    does not need it, and h5py takes a tenth of the time. A 1-D float variable and its
    ``units`` string are read through h5py's low-level calls (h5py's ``Dataset`` objects
    cost more than reading their data: a third of the read time of a rig record), anything
    else through its usual interface.
    """
    import h5py

    where = str(path)
    try:
        handle = h5py.File(path, "r")
    except (OSError, ValueError) as exc:
        raise RecordError(f"{where}: not a readable netCDF/HDF5 file ({exc})") from None
    with handle:
        columns: dict[str, FloatArray] = {}
        units: dict[str, str] = {}
        root = handle.id
        for name in ("time", *CHANNELS):
            if name.encode() not in root:
                continue
            fast = _h5_variable(h5py, root, name.encode())
            if fast is None:
                variable = handle[name]
                unit = _text(variable.attrs.get("units", ""))
                values = np.asarray(variable[...], dtype=np.float64)
            else:
                unit, values = fast
            if not unit:
                raise RecordError(f"{where}: variable {name!r} has no units attribute")
            columns[name] = values * _factor(where, name, unit)
            units[name] = unit
        meta: dict[str, Any] = {}
        for attr, key in _NC_META.items():
            if h5py.h5a.exists(root, attr.encode()):
                value = _h5_attribute(h5py, root, attr.encode())
                if value is None:  # empty, or of an array type: h5py's own reading
                    value = handle.attrs[attr]
                meta[key] = (
                    _text(value)
                    if key in ("joint_id", "control", "notes")
                    else float(np.asarray(value).item())
                )
    return _assemble(where, columns, units, meta, resample_)


def _h5_variable(h5py: Any, root: Any, name: bytes) -> tuple[str, FloatArray] | None:
    """A 1-D float dataset's ``units`` (a scalar string, or "") and its values as float64,
    by h5py's low-level calls; None for anything else (read by the usual interface)."""
    try:
        dataset = h5py.h5d.open(root, name)
    except (KeyError, TypeError, ValueError):  # a group, or a link to nothing
        return None
    if dataset.dtype.kind != "f" or len(dataset.shape) != 1:
        return None
    unit = ""
    if h5py.h5a.exists(dataset, b"units"):
        attr = h5py.h5a.open(dataset, b"units")
        if attr.shape != () or h5py.h5t.check_string_dtype(attr.dtype) is None:
            return None
        text = np.empty((), dtype=attr.dtype)
        attr.read(text)
        unit = _text(text[()])
    values = np.empty(dataset.shape, dtype=np.float64)
    dataset.read(h5py.h5s.ALL, h5py.h5s.ALL, values)
    return unit, values


def _h5_attribute(h5py: Any, owner: Any, name: bytes) -> Any:
    """An attribute's value as ``h5py.AttributeManager.__getitem__`` gives it (the same
    steps, without building the manager, which cost most of a rig record's metadata
    reading); None for an empty attribute or one of an array type (read by h5py then)."""
    attr = h5py.h5a.open(owner, name)
    shape = attr.shape
    dtype = attr.dtype
    if shape is None or dtype.subdtype is not None:
        return None
    values = np.zeros(shape, dtype=dtype, order="C")
    attr.read(values, mtype=h5py.h5t.py_create(dtype))
    info = h5py.h5t.check_string_dtype(dtype)
    if info and info.length is None:  # variable-length strings: Python str, as h5py does
        values = np.array(
            [b.decode("utf-8", "surrogateescape") for b in values.flat], dtype=dtype
        ).reshape(values.shape)
    return values[()] if values.ndim == 0 else values


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def record_dataset(time: ArrayLike, channels: dict[str, Any], metadata: dict[str, Any]) -> Any:
    """Return the one netCDF layout of a time record, as an xarray Dataset (not validated).

    Every time record the package writes (``write_record``, ``clearjoint simulate
    --out``) goes through here, so that ``read_record`` and ``clearjoint identify``
    read them all.

    Parameters
    ----------
    time : (N,) array_like
        Sample times, s.
    channels : dict
        Channel name of :data:`CHANNELS` -> (N,) array in SI (None: not measured).
    metadata : dict
        Record metadata by field name (``clearance``, ``mass``, ``frequency_hz``...).

    Returns
    -------
    xarray.Dataset
        Variables ``force``, ``displacement``... on ``time``, each with ``units``;
        metadata as global attributes ``clearance_m``, ``mass_kg``... Callers may add
        variables on other dimensions (a simulation adds its stages and impacts).
    """
    import xarray as xr

    unknown = sorted(set(channels) - set(CHANNELS))
    if unknown:
        raise RecordError(f"unknown channel(s) {unknown}; a record has {', '.join(CHANNELS)}")
    variables = {
        name: ("time", np.asarray(channels[name], dtype=np.float64), {"units": SI[name]})
        for name in CHANNELS
        if channels.get(name) is not None
    }
    attrs: dict[str, Any] = {"clearjoint_record": 1}
    for attr, key in _NC_META.items():
        if metadata.get(key) not in (None, ""):
            attrs[attr] = metadata[key]
    coords = {"time": ("time", np.asarray(time, dtype=np.float64), {"units": "s"})}
    return xr.Dataset(variables, coords=coords, attrs=attrs)


def _write_netcdf(record: Record, path: Path) -> None:
    channels = {name: getattr(record, name) for name in CHANNELS}
    record_dataset(record.time, channels, record.metadata()).to_netcdf(path, engine="h5netcdf")


# ---- the BRFD data set --------------------------------------------------------------------

_BRFD_NAME = re.compile(
    r"(?P<frequency>[\d.]+)Hz(?P<tension>\d+)lbtension(?P<amplitude>[\d.]+)amplitude"
)
_BRFD_COLUMNS = ("time", "displacement", "force", "velocity", "actuator_1", "actuator_2")
BRFD_CITATION = (
    'D. Coble, P. Huggins, L. Cao, J. Ricles, A. Downey, "Dataset-Friction-Damper-with-Backlash", '
    "GitHub, ARTS-Laboratory, 2022 (CC BY-SA 4.0)"
)


def _brfd_json(where: str, raw: bytes) -> tuple[dict[str, Any], FloatArray]:
    """The JSON's metadata (without 'data') and its 'data' matrix, from the file's bytes.

    A plain matrix of numbers (every row a list of numbers, all of one length, no other
    list in the file, each key once) is parsed by simdjson straight into doubles
    (:func:`_simd_matrix`: no Python object per number; about three times faster than
    the route below over the 31 BRFD files, side by side by ``python
    benchmarks/bench_identify.py --parsers``). Anything else goes by orjson, as before
    (its lists, then :func:`_rows_matrix`), which also says what is wrong with it. Both
    give the correctly rounded doubles that Python's ``float`` gives, bit for bit.
    orjson runs with the garbage collector off from the parse until the rows' lists are
    freed (they hold only numbers: no cycles to collect; with the collector on while they
    live, its next pass walks every one of them).
    """
    fast = _simd_matrix(raw)
    if fast is not None:
        return fast
    import orjson  # only a JSON record that is not a plain matrix needs it

    collecting = gc.isenabled()
    gc.disable()  # tens of thousands of new lists, no cycles: the collector only costs time
    try:
        return _json_matrix(where, raw, orjson)
    finally:
        if collecting:
            gc.enable()


_OPEN = ord("[")
#: Errors of simdjson's parser and accessors: the file goes to the orjson route instead.
_SIMD_DECLINES = (ValueError, TypeError, KeyError, RuntimeError, AttributeError)


def _simd_matrix(raw: bytes) -> tuple[dict[str, Any], FloatArray] | None:
    """The metadata and the 'data' matrix of a JSON object by simdjson, or None.

    None (the caller then parses with orjson) unless the bytes are one JSON object (no
    byte-order mark: orjson refuses one) whose keys are all different, whose 'data' is a
    non-empty list of equally long, non-empty lists of numbers, and which holds no other
    list (its ``[`` bytes number exactly the rows plus one: a list nested in a row, whose
    numbers simdjson's buffer would flatten into the matrix, or a ``[`` in any text,
    sends the file to orjson). The numbers are simdjson's correctly rounded doubles (an
    integer converted to the nearest double), those of orjson and Python's ``float``.
    """
    import simdjson  # only a JSON record needs it

    if raw.startswith(b"\xef\xbb\xbf"):
        return None
    try:
        document = simdjson.Parser().parse(raw)
        if not isinstance(document, simdjson.Object):
            return None
        keys = list(document.keys())
        rows = document["data"] if "data" in keys else None
        if len(set(keys)) != len(keys) or not isinstance(rows, simdjson.Array):
            return None
        n = len(rows)
        # numpy counts the bytes faster than bytes.count (1.6 GB/s here: 25 ms of 50 MB)
        if n == 0 or np.count_nonzero(np.frombuffer(raw, dtype=np.uint8) == _OPEN) != n + 1:
            return None
        widths = set(map(len, cast(list[list[float]], rows)))  # a number for a row: TypeError
        width = widths.pop() if len(widths) == 1 else 0
        flat = np.frombuffer(rows.as_buffer(of_type="d"), dtype=np.float64)
        if width == 0 or flat.size != n * width:
            return None
        meta = {key: _plain(simdjson, document[key]) for key in keys if key != "data"}
    except _SIMD_DECLINES:  # not JSON, not UTF-8, a text or null among the numbers...
        return None
    return meta, flat.reshape(n, width)


def _plain(simdjson: Any, value: Any) -> Any:
    """A simdjson value as Python's own (an object a dict, an array a list)."""
    if isinstance(value, simdjson.Object):
        return value.as_dict()
    if isinstance(value, simdjson.Array):
        return value.as_list()
    return value


def _json_matrix(where: str, raw: bytes, orjson: Any) -> tuple[dict[str, Any], FloatArray]:
    try:
        content = orjson.loads(raw)
    except orjson.JSONDecodeError as exc:  # also bytes that are not UTF-8
        raise RecordError(f"{where}: not a JSON file ({exc})") from None
    if not isinstance(content, dict) or "data" not in content:
        raise RecordError(f"{where}: JSON without a 'data' matrix; not a BRFD record")
    rows = content.pop("data")
    data = _rows_matrix(rows) if isinstance(rows, list) else None
    if data is None:  # not a list of equal rows of numbers: numpy says what it is
        try:
            data = np.array(rows, dtype=np.float64)
        except (TypeError, ValueError):
            raise RecordError(f"{where}: the 'data' matrix is not numeric") from None
    return content, data  # the rows are freed on return, with the collector still off


def _rows_matrix(rows: list[Any]) -> FloatArray | None:
    """A list of equally long lists of numbers as a float64 matrix, or None if it is not one.

    The numbers are taken one after the other by ``numpy.fromiter`` (the same doubles as
    ``numpy.array``, which first walks the nested lists to learn their shape and costs
    about 1.6 times as much here); the checks that make the shape certain (every row a
    list, all of one length) cost a fifth of it.
    """
    if not rows or set(map(type, rows)) != {list}:
        return None
    widths = set(map(len, rows))
    if len(widths) != 1:
        return None
    width = widths.pop()
    try:
        flat = np.fromiter(
            itertools.chain.from_iterable(rows), dtype=np.float64, count=len(rows) * width
        )
    except (TypeError, ValueError, OverflowError):  # a string, a nested list, a null...
        return None
    return flat.reshape(len(rows), width)


def read_brfd(path: str | Path, *, resample: bool = False) -> Record:
    """Read one BRFD test (banded rotary friction device with backlash) as an SI Record.

    The JSON's ``data`` columns are time (s), displacement (in), friction force
    (kip), velocity (in/s) and two actuator forces (lb); the unit names come from
    the file itself. The record's force is the friction force, its control is
    displacement; frequency, band tension and amplitude come from the file name
    (e.g. ``0.5Hz30lbtension1amplitude.json``). Cite: :data:`BRFD_CITATION`.
    """
    path = Path(path)
    where = str(path)
    content, data = _brfd_json(where, path.read_bytes())
    if data.ndim != 2 or data.shape[1] != len(_BRFD_COLUMNS):
        raise RecordError(
            f"{where}: 'data' must have {len(_BRFD_COLUMNS)} columns "
            f"({', '.join(_BRFD_COLUMNS)}), got shape {data.shape}"
        )
    units = {
        "time": str(content.get("time units", "s")),
        "displacement": str(content.get("displacement units", "")),
        "force": str(content.get("friction force units", "")),
    }
    units["velocity"] = f"{units['displacement']}/{units['time']}"
    columns = {
        name: data[:, i] * _factor(where, name, units[name])
        for i, name in enumerate(_BRFD_COLUMNS[:4])
    }
    meta: dict[str, Any] = {"control": "displacement", "joint_id": "BRFD"}
    match = _BRFD_NAME.search(path.name)
    notes = [f"BRFD friction damper with backlash; {BRFD_CITATION}"]
    if match:
        meta["frequency_hz"] = float(match["frequency"])
        meta["displacement_amplitude"] = float(match["amplitude"]) * 0.0254
        notes.insert(0, f"band tension {match['tension']} lb")
    meta["notes"] = "; ".join(notes)
    return _assemble(where, columns, units, meta, resample)


# ---- reading and writing by content -------------------------------------------------------

_HDF5 = b"\x89HDF\r\n\x1a\n"
_CLAIMS = {".nc": "netCDF", ".h5": "HDF5", ".hdf5": "HDF5", ".json": "JSON", ".csv": "CSV"}


def sniff(path: str | Path) -> str:
    """Return the format of a file by its content: "netcdf", "json" or "csv".

    Raises RecordError when the file is missing, empty, or not what its name claims.
    """
    path = Path(path)
    where = str(path)
    try:
        with path.open("rb") as handle:
            head = handle.read(512)
    except FileNotFoundError:
        raise RecordError(f"{where}: no such file") from None
    except IsADirectoryError:
        raise RecordError(f"{where}: is a folder, not a record file") from None
    except OSError as exc:
        raise RecordError(f"{where}: cannot read it ({exc.strerror})") from None
    if not head:
        raise RecordError(f"{where}: empty file")
    if path.suffix.lower() == ".toml":  # else read as a CSV whose sidecar is itself
        raise RecordError(
            f"{where}: a TOML file is not a record; give the record file (a .toml beside a "
            "CSV of the same name holds that CSV's metadata)"
        )
    if head.startswith(_HDF5):
        kind = "netcdf"
    elif head.startswith(b"CDF\x01") or head.startswith(b"CDF\x02"):
        raise RecordError(f"{where}: a classic (netCDF-3) file; save it as netCDF-4 / HDF5")
    elif head.lstrip().startswith(b"{"):
        kind = "json"
    elif b"\x00" in head and not head.startswith(_UTF16_BOMS):  # UTF-16 text has NULs
        raise RecordError(f"{where}: a binary file of unknown format; not a record")
    else:
        kind = "csv"
    claim = _CLAIMS.get(path.suffix.lower())
    expected = {"netCDF": "netcdf", "HDF5": "netcdf", "JSON": "json", "CSV": "csv"}
    if claim and expected[claim] != kind:
        raise RecordError(
            f"{where}: named as {claim} but its content is {kind.upper()}; "
            "rename it or check that it is the file you meant"
        )
    return kind


def read_record(path: str | Path, *, resample: bool = False) -> Record:
    """Read a record file of any supported format, recognised by its content.

    With ``resample=True`` a record that is not uniformly sampled (or has
    repeated or unsorted times) is interpolated linearly onto a uniform grid at
    its median rate instead of being refused.
    """
    path = Path(path)
    kind = sniff(path)
    try:
        if kind == "netcdf":
            return _read_netcdf(path, resample)
        if kind == "json":
            return read_brfd(path, resample=resample)
        return _read_csv(path, resample)
    except OSError as exc:  # truncated, or gone or locked between the sniff and the read
        raise RecordError(f"{path}: cannot read it ({exc.strerror or exc})") from None


def mass_advice(source: str) -> str:
    """How to add the moving mass to the record file ``source``, in words a user can follow.

    The fix depends on where that file's metadata is read from: a clearjoint CSV (first
    line :data:`CSV_MAGIC`) reads its ``#`` header; a lab CSV reads only its sidecar
    ``NAME.toml`` (a ``# mass`` line in it would be a comment); a netCDF file reads its
    global attribute ``mass_kg``.

    Parameters
    ----------
    source : str
        The record's file (``Record.source``); empty or unknown gives every way.

    Returns
    -------
    str
        One clause, e.g. ``add the line 'mass = "1.5 kg"' (your moving mass) to x.toml``.
    """
    path = Path(source)
    value = '"1.5 kg"'
    mine = " (your moving mass)"
    suffix = path.suffix.lower()
    if suffix in (".nc", ".h5", ".hdf5"):
        return f"set the global attribute mass_kg{mine}, in kg, in {path}"
    if suffix != ".csv" or not path.is_file():
        return (
            f"a clearjoint CSV: the header line '# mass = {value}'; a lab CSV: the line "
            f"'mass = {value}' in its sidecar NAME.toml; netCDF: the attribute mass_kg"
        )
    lines = _decode(source, path.read_bytes()).splitlines()  # as _read_csv decodes it
    if lines and lines[0].strip() == CSV_MAGIC:
        return f"add the line '# mass = {value}'{mine} under the first line '{CSV_MAGIC}' of {path}"
    sidecar = path.with_suffix(".toml")
    if not sidecar.exists():
        return f"create {sidecar} holding the line 'mass = {value}'{mine}"
    from clearjoint.io_toml import read_toml

    try:
        table = read_toml(sidecar, what="record metadata", error=RecordError)
    except RecordError:
        table = {}
    where = "the [record] table of " if isinstance(table.get("record"), dict) else ""
    return f"add the line 'mass = {value}'{mine} to {where}{sidecar}"


def write_record(record: Record, path: str | Path, *, force: bool = False) -> Path:
    """Write ``record`` to ``path``: ``.csv`` or ``.nc`` by the suffix. Never overwrites
    an existing file unless ``force``."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".nc"):
        raise RecordError(f"{path}: write records as .csv or .nc, not {suffix or 'no suffix'}")
    refuse_to_overwrite([path], force=force)
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".csv":
        _write_csv(record, path)
    else:
        _write_netcdf(record, path)
    return path
