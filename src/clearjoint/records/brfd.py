"""The BRFD JSON records of the friction-damper-with-backlash data set (inches, kips).

See data/brfd/README.md and docs/records.md; read by :func:`read_brfd`, cite
:data:`BRFD_CITATION`.
"""

from __future__ import annotations

import gc
import itertools
import re
from pathlib import Path
from typing import Any, cast

import numpy as np

from clearjoint.records.record import FloatArray, Record, RecordError, _assemble, _factor

__all__ = [
    "BRFD_CITATION",
    "read_brfd",
]

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
