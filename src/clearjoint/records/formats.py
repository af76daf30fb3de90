"""The record file formats: one registry of file endings, and reading and writing through it.

:data:`FORMATS` is the one place that says which file endings hold records, what each
must contain, which reader and writer it has and which modules its reader imports. Every
place that looks at a record file's name asks it: :func:`read_record`, :func:`write_record`
and :func:`sniff` here, :func:`mass_advice`, ``clearjoint.identify`` (the readers it
imports before its workers fork), ``clearjoint.reproduction`` (the record files of a
folder) and ``clearjoint.rig`` (the formats a campaign may write). A new format is a
module of this package with a reader (and perhaps a writer) and one entry here.

A record is read by its content (:func:`sniff`), whatever its name: a file whose name
claims one format and whose content is another is refused, so that a mistake is caught
before it is read as something else.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from clearjoint.checks import refuse_to_overwrite
from clearjoint.records.brfd import read_brfd
from clearjoint.records.lab_csv import (
    _UTF16_BOMS,
    CSV_MAGIC,
    SIDECAR_SUFFIX,
    _decode,
    _read_csv,
    _write_csv,
    sidecar_path,
)
from clearjoint.records.netcdf import _read_netcdf, _write_netcdf
from clearjoint.records.record import Record, RecordError

__all__ = [
    "FORMATS",
    "Reader",
    "RecordFormat",
    "Writer",
    "import_readers",
    "is_record_file",
    "mass_advice",
    "read_record",
    "record_format",
    "record_suffixes",
    "sniff",
    "write_record",
]

#: A reader: (path, resample) -> the file's Record.
Reader = Callable[[Path, bool], Record]
#: A writer: (record, path) -> None; the path is checked and its folder made by the caller.
Writer = Callable[[Record, Path], None]


def _read_json(path: Path, resample_: bool) -> Record:
    return read_brfd(path, resample=resample_)


@dataclass(frozen=True)
class RecordFormat:
    """One file ending that holds records: what it must contain, how it is read and written.

    Attributes
    ----------
    suffix : str
        The file ending, lower case with its dot (``".nc"``).
    content : {"netcdf", "json", "csv"}
        What :func:`sniff` must find in a file of this name.
    description : str
        The format's name in messages (``"netCDF"``, ``"HDF5"``).
    read : callable
        ``read(path, resample)`` -> :class:`~clearjoint.records.Record`.
    write : callable or None
        ``write(record, path)``, or None when clearjoint does not write this ending.
    modules : tuple of str
        Modules the reader imports (imported before worker processes fork).
    """

    suffix: str
    content: str
    description: str
    read: Reader
    write: Writer | None
    modules: tuple[str, ...] = ()


#: The record file endings, suffix -> format, in the order messages list them.
FORMATS: Mapping[str, RecordFormat] = {
    entry.suffix: entry
    for entry in (
        RecordFormat(".csv", "csv", "CSV", _read_csv, _write_csv),
        RecordFormat(".nc", "netcdf", "netCDF", _read_netcdf, _write_netcdf, ("h5py",)),
        RecordFormat(".h5", "netcdf", "HDF5", _read_netcdf, None, ("h5py",)),
        RecordFormat(".hdf5", "netcdf", "HDF5", _read_netcdf, None, ("h5py",)),
        RecordFormat(".json", "json", "JSON", _read_json, None, ("simdjson",)),
    )
}


def record_format(path: str | Path) -> RecordFormat | None:
    """Return the format a file's name claims (:data:`FORMATS`), or None for another ending."""
    return FORMATS.get(Path(path).suffix.lower())


def record_suffixes(*, writable: bool = False) -> tuple[str, ...]:
    """Return the record file endings (``".nc"``...), or only those clearjoint writes."""
    return tuple(s for s, entry in FORMATS.items() if not writable or entry.write is not None)


def is_record_file(path: str | Path) -> bool:
    """Return True when a file's name ends as a record's (:data:`FORMATS`), any case."""
    return record_format(path) is not None


def import_readers(paths: Iterable[str | Path]) -> None:
    """Import the modules the readers of these files need (h5py, simdjson...), once.

    For a pool of worker processes: imported before they fork, each worker starts with
    them loaded instead of importing them again. Files of other endings need none.
    """
    claims = [record_format(path) for path in paths]
    needed = {module for claim in claims if claim is not None for module in claim.modules}
    for module in sorted(needed):
        importlib.import_module(module)


def _reader(content: str) -> Reader:
    return next(entry.read for entry in FORMATS.values() if entry.content == content)


# ---- reading and writing by content -------------------------------------------------------

_HDF5 = b"\x89HDF\r\n\x1a\n"


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
    if path.suffix.lower() == SIDECAR_SUFFIX:  # else read as a CSV whose sidecar is itself
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
    claim = record_format(path)
    if claim and claim.content != kind:
        raise RecordError(
            f"{where}: named as {claim.description} but its content is {kind.upper()}; "
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
        return _reader(kind)(path, resample)
    except OSError as exc:  # truncated, or gone or locked between the sniff and the read
        raise RecordError(f"{path}: cannot read it ({exc.strerror or exc})") from None


def mass_advice(source: str) -> str:
    """How to add the moving mass to the record file ``source``, in words a user can follow.

    The fix depends on where that file's metadata is read from: a clearjoint CSV (first
    line :data:`~clearjoint.records.CSV_MAGIC`) reads its ``#`` header; a lab CSV reads
    only its sidecar ``NAME.toml`` (a ``# mass`` line in it would be a comment); a netCDF
    file reads its global attribute ``mass_kg``.

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
    claim = record_format(path)
    if claim is not None and claim.content == "netcdf":
        return f"set the global attribute mass_kg{mine}, in kg, in {path}"
    if claim is None or claim.content != "csv" or not path.is_file():
        return (
            f"a clearjoint CSV: the header line '# mass = {value}'; a lab CSV: the line "
            f"'mass = {value}' in its sidecar NAME.toml; netCDF: the attribute mass_kg"
        )
    lines = _decode(source, path.read_bytes()).splitlines()  # as _read_csv decodes it
    if lines and lines[0].strip() == CSV_MAGIC:
        return f"add the line '# mass = {value}'{mine} under the first line '{CSV_MAGIC}' of {path}"
    sidecar = sidecar_path(path)
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
    """Write ``record`` to ``path`` in the format its suffix names, and return the path.

    The writable endings are :func:`record_suffixes` ``(writable=True)``: ``.csv`` and
    ``.nc``. Never overwrites an existing file unless ``force``.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    claim = record_format(path)
    if claim is None or claim.write is None:
        endings = " or ".join(record_suffixes(writable=True))
        raise RecordError(f"{path}: write records as {endings}, not {suffix or 'no suffix'}")
    refuse_to_overwrite([path], force=force)
    path.parent.mkdir(parents=True, exist_ok=True)
    claim.write(record, path)
    return path
