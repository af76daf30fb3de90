"""netCDF-4 / HDF5 records: written through xarray (h5netcdf engine), read back with h5py.

Variables ``time``, ``force``, ``displacement`` (and ``velocity``, ``acceleration``)
with ``units`` attributes, metadata as global attributes (``clearance_m``, ``mass_kg``,
...); the layout is documented in docs/records.md and made by :func:`record_dataset`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from clearjoint.records.record import (
    CHANNELS,
    SI,
    FloatArray,
    Record,
    RecordError,
    _assemble,
    _factor,
)

__all__ = [
    "record_dataset",
]

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
