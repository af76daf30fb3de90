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

import json
import math
import re
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint._checks import refuse_to_overwrite
from clearjoint.errors import ClearjointError
from clearjoint.units import SI_UNITS, registry

FloatArray = NDArray[np.float64]

CSV_MAGIC = "# clearjoint record 1"
CHANNELS = ("force", "displacement", "velocity", "acceleration")
SI = {"time": "s", "force": "N", "displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}
#: Relative spread of the time step allowed in a "uniformly sampled" record.
UNIFORM_TOLERANCE = 1e-4
#: Cycles a record must span when its frequency is known.
MIN_CYCLES = 3
MIN_SAMPLES = 16


class RecordError(ClearjointError, ValueError):
    """A record or a record file is unusable; the message names the file and the fix."""


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
            number = float(value)
            if not math.isfinite(number) or number < 0.0:
                raise RecordError(f"{where}: {name} must be finite and >= 0, got {value!r}")
            set_(self, name, number)
        if self.frequency_hz:
            cycles = (time[-1] - time[0]) * self.frequency_hz
            if cycles < MIN_CYCLES:
                raise RecordError(
                    f"{where}: spans {cycles:.2f} cycles at {self.frequency_hz:g} Hz; "
                    f"a record needs at least {MIN_CYCLES}"
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


def _factor(where: str, channel: str, unit: str) -> float:
    """The factor that takes ``channel`` in ``unit`` to SI; errors name the file and channel."""
    fast = FAST_FACTORS.get((channel, unit.strip()))
    if fast is not None:
        return fast
    import pint

    target = SI[channel]
    try:
        return float(registry().Quantity(1.0, unit.strip()).to(target).magnitude)
    except pint.errors.DimensionalityError:
        raise RecordError(
            f"{where}: {channel} is in {unit!r}, which is not a unit of {target}; "
            "fix the unit in the file"
        ) from None
    except (pint.errors.PintError, ValueError, AttributeError, TypeError):
        raise RecordError(
            f"{where}: unknown unit {unit!r} for {channel}; write a unit such as {target}"
        ) from None


# ---- CSV ----------------------------------------------------------------------------------

_COLUMN = re.compile(r"^\s*(?P<name>[A-Za-z_]+)\s*\[(?P<unit>[^\]]+)\]\s*$")

#: Metadata keys of the CSV header and sidecar, with the kind of quantity (or text).
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


def _metadata_from_toml(where: str, table: dict[str, Any]) -> dict[str, Any]:
    from clearjoint.units import parse_quantity

    unknown = sorted(set(table) - set(_META_KINDS))
    if unknown:
        raise RecordError(f"{where}: unknown metadata {unknown}; known: {sorted(_META_KINDS)}")
    meta: dict[str, Any] = {}
    for key, value in table.items():
        kind = _META_KINDS[key]
        target = "frequency_hz" if key == "frequency" else key
        if kind == "text":
            meta[target] = str(value)
        elif isinstance(value, int | float) and not isinstance(value, bool):
            meta[target] = float(value)
        else:
            try:
                meta[target] = parse_quantity(str(value), kind, name=f"{where}: {key}")
            except ClearjointError as exc:
                raise RecordError(str(exc)) from None
    return meta


def _read_csv(path: Path, resample_: bool) -> Record:
    import pandas as pd

    where = str(path)
    header: list[str] = []
    with path.open(encoding="utf-8") as handle:
        first = handle.readline()
        if first.strip() == CSV_MAGIC:
            for line in handle:
                if not line.startswith("#"):
                    break
                header.append(line[1:].strip())
    skip = len(header) + 1 if header else 0
    if header:
        try:
            meta = _metadata_from_toml(where, tomllib.loads("\n".join(header)))
        except tomllib.TOMLDecodeError as exc:
            raise RecordError(
                f"{where}: the header block is not key = value lines ({exc})"
            ) from None
    else:
        sidecar = path.with_suffix(".toml")
        if not sidecar.exists():
            meta = {}
        else:
            try:
                table = tomllib.loads(sidecar.read_text(encoding="utf-8"))
            except tomllib.TOMLDecodeError as exc:
                raise RecordError(f"{sidecar}: not valid TOML ({exc})") from None
            meta = _metadata_from_toml(str(sidecar), table.get("record", table))
    try:
        frame = pd.read_csv(path, skiprows=skip, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise RecordError(f"{where}: not a readable CSV file ({exc})") from None
    columns: dict[str, FloatArray] = {}
    units: dict[str, str] = {}
    for column in frame.columns:
        match = _COLUMN.match(str(column))
        if not match:
            raise RecordError(
                f"{where}: column {column!r} has no unit; name columns like "
                "'time [s]', 'force [N]', 'displacement [mm]'"
            )
        name, unit = match["name"].lower(), match["unit"]
        if name not in SI:
            raise RecordError(f"{where}: unknown column {name!r}; known: {', '.join(SI)}")
        try:
            values = frame[column].to_numpy(dtype=np.float64)
        except (TypeError, ValueError):
            raise RecordError(f"{where}: column {column!r} is not numeric") from None
        columns[name] = values * _factor(where, name, unit)
        units[name] = unit
    return _assemble(where, columns, units, meta, resample_)


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
    does not need it, and h5py takes a tenth of the time.
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
        for name in ("time", *CHANNELS):
            if name not in handle:
                continue
            variable = handle[name]
            unit = _text(variable.attrs.get("units", ""))
            if not unit:
                raise RecordError(f"{where}: variable {name!r} has no units attribute")
            columns[name] = np.asarray(variable[...], dtype=np.float64) * _factor(where, name, unit)
            units[name] = unit
        meta: dict[str, Any] = {}
        for attr, key in _NC_META.items():
            if attr in handle.attrs:
                value = handle.attrs[attr]
                meta[key] = (
                    _text(value)
                    if key in ("joint_id", "control", "notes")
                    else float(np.asarray(value).item())
                )
    return _assemble(where, columns, units, meta, resample_)


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _write_netcdf(record: Record, path: Path) -> None:
    import xarray as xr

    variables = {
        name: ("time", getattr(record, name), {"units": SI[name]})
        for name in CHANNELS
        if getattr(record, name) is not None
    }
    attrs: dict[str, Any] = {"clearjoint_record": 1}
    meta = record.metadata()
    for attr, key in _NC_META.items():
        if meta.get(key) not in (None, ""):
            attrs[attr] = meta[key]
    data = xr.Dataset(
        variables, coords={"time": ("time", record.time, {"units": "s"})}, attrs=attrs
    )
    data.to_netcdf(path, engine="h5netcdf")


# ---- the BRFD data set --------------------------------------------------------------------

_BRFD_NAME = re.compile(
    r"(?P<frequency>[\d.]+)Hz(?P<tension>\d+)lbtension(?P<amplitude>[\d.]+)amplitude"
)
_BRFD_COLUMNS = ("time", "displacement", "force", "velocity", "actuator_1", "actuator_2")
BRFD_CITATION = (
    'D. Coble, P. Huggins, L. Cao, J. Ricles, A. Downey, "Dataset-Friction-Damper-with-Backlash", '
    "GitHub, ARTS-Laboratory, 2022 (CC BY-SA 4.0)"
)


_DATA_KEY = re.compile(r'"data"\s*:\s*\[')


def _brfd_json(where: str, text: str) -> tuple[dict[str, Any], FloatArray]:
    """The JSON's metadata and its 'data' matrix.

    The matrix is tens of thousands of rows; it is parsed as numbers straight from
    the text (several times faster than building Python lists), and the rest of
    the object by the json module. Anything unexpected goes through json whole.
    """
    match = _DATA_KEY.search(text)
    end = text.find("]]", match.end()) if match else -1
    if match and end > 0:
        body = text[match.end() - 1 : end + 2]
        rows = body.count("[") - 1
        numbers = np.fromstring(body.replace("[", " ").replace("]", " "), sep=",")
        if rows > 0 and numbers.size % rows == 0:
            rest = text[: match.start()] + '"data": null' + text[end + 2 :]
            try:
                content = json.loads(rest)
            except json.JSONDecodeError as exc:
                raise RecordError(f"{where}: not a JSON file ({exc})") from None
            return content, numbers.reshape(rows, numbers.size // rows)
    try:
        content = json.loads(text)
    except json.JSONDecodeError as exc:
        raise RecordError(f"{where}: not a JSON file ({exc})") from None
    if not isinstance(content, dict) or "data" not in content:
        raise RecordError(f"{where}: JSON without a 'data' matrix; not a BRFD record")
    try:
        data = np.asarray(content["data"], dtype=np.float64)
    except (TypeError, ValueError):
        raise RecordError(f"{where}: the 'data' matrix is not numeric") from None
    return content, data


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
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise RecordError(f"{where}: not a JSON file ({exc})") from None
    content, data = _brfd_json(where, text)
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
    if not head:
        raise RecordError(f"{where}: empty file")
    if head.startswith(_HDF5):
        kind = "netcdf"
    elif head.startswith(b"CDF\x01") or head.startswith(b"CDF\x02"):
        raise RecordError(f"{where}: a classic (netCDF-3) file; save it as netCDF-4 / HDF5")
    elif head.lstrip().startswith(b"{"):
        kind = "json"
    elif b"\x00" in head:
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
    if kind == "netcdf":
        return _read_netcdf(path, resample)
    if kind == "json":
        return read_brfd(path, resample=resample)
    return _read_csv(path, resample)


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
