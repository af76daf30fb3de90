"""A sweep's results on disk: a zarr group laid out as the labelled grid, that checks itself.

No physics here. The store is what ``xarray.Dataset.to_zarr`` writes for the sweep's
Dataset: one array per variable over the grid's dimensions (``sample`` and one per
swept parameter; a per-joint draw adds ``joint``), each dimension's coordinate values
as an array of its own, non-index coordinates (drawn values over ``sample``) named in
each variable's ``coordinates`` attribute, the Dataset's attributes on the group, and
consolidated metadata: ``xarray.open_zarr(path)`` opens it with nothing to decode. A
store without a grid (:class:`Grid` not given) lies along one dimension, ``point``.

Points run in C order over the grid; a *task chunk* is ``chunk_size`` consecutive
points, and a zarr chunk file holds whole rows of the grid's first dimension (at least
:data:`POINTS_PER_FILE` points), so a file may hold several task chunks, or part of
one. The bookkeeping lives in the subgroup ``clearjoint`` (which ``xarray.open_zarr``
does not read): a ``chunk_done`` flag per task chunk written after its values, and a
``chunk_digest`` per task chunk and variable: a 64-bit BLAKE2b of the chunk's index,
the variable's name and its values, written with them. Every array chunk also carries
zarr's own crc32c codec (the zarr v3 ``crc32c`` codec, checked as the chunk is decoded),
and each coordinate a digest of its values (in the subgroup's attributes).

A chunk flagged done is *damaged* when one of its variables' data is missing, does
not decode (a checksum of its bytes that fails, a truncated or emptied file), or
does not match its digest (a flipped bit that still decodes, a neighbour chunk's
file copied over it, a deleted chunk read back as fill values). :meth:`ResultStore.read`
refuses a damaged store with one line naming the chunk (or the coordinate);
:meth:`ResultStore.check` lists the damage so that a resumed run recomputes those chunks
(and :meth:`ResultStore.write_coordinates` writes the coordinates again).

A store records the fingerprint of the sweep that made it (resuming from another
sweep is refused) and its format (:data:`STORE_FORMAT`): a store of an older format
(format 2 and before: flat along ``point``) is refused with one line.
"""

from __future__ import annotations

import hashlib
import math
import shutil
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import ClearjointError, OutputExistsError

__all__ = [
    "STORE_FORMAT",
    "Grid",
    "ResultStore",
    "StoreError",
    "StoreWarning",
    "Variable",
]

#: The store layout this clearjoint writes: 2 added crc32c and the chunk digests, 3 the
#: labelled grid (what ``xarray.open_zarr`` reads) with the bookkeeping in a subgroup.
STORE_FORMAT = 3

#: Points per zarr chunk file, at least (rounded up to whole task chunks and to whole
#: rows of the grid's first dimension): a batch of small task chunks is a few files.
POINTS_PER_FILE = 256

_FINGERPRINT = "clearjoint_sweep_fingerprint"
_FORMAT = "clearjoint_store_format"
_META = "clearjoint"  # the subgroup of the bookkeeping
_DONE = "chunk_done"
_DIGEST = "chunk_digest"
_OWN = (_DONE, _DIGEST)
#: What each older format lacks, as a refusal says it.
_OLD_FORMATS = {1: "no checksums", 2: "flat along point"}
_XARRAY_ATTRS = ("coordinates", "_FillValue")  # what xarray adds to a variable's attributes


class StoreError(ClearjointError, ValueError):
    """A result store cannot be used: another sweep's, not a sweep store, damaged, or in use."""


class StoreWarning(UserWarning):
    """Said once by a run that repairs a store or takes over a stale lock, then goes on."""


@dataclass(frozen=True)
class Variable:
    """One array of a store: its name, numpy dtype ('f8', 'i8' or 'str') and attributes.

    ``shape`` is what each point holds beyond the grid's dimensions: () for one
    value, (n,) for n values (dimension ``joint``).
    """

    name: str
    dtype: str
    attrs: Mapping[str, Any]
    shape: tuple[int, ...] = ()


@dataclass(frozen=True)
class Grid:
    """The labelled grid a store's variables lie on, as xarray names it.

    ``dims`` and ``shape``: the dimensions in C order of the points (``sample`` first
    for a Monte Carlo study, then one per swept parameter); ``coords``: name ->
    (dims, values, attributes), each dimension's values and any other coordinate (a
    drawn parameter over ``sample``). Without a grid a store lies along ``point``.
    """

    dims: tuple[str, ...]
    shape: tuple[int, ...]
    coords: Mapping[str, tuple[tuple[str, ...], Any, Mapping[str, Any]]] = field(
        default_factory=dict
    )

    def __post_init__(self) -> None:
        if len(self.dims) != len(self.shape) or not self.dims:
            raise StoreError(f"a grid needs one size per dimension, got {self.dims}, {self.shape}")
        if min(self.shape) < 1:
            raise StoreError(f"every dimension of a grid needs a value, got shape {self.shape}")

    @property
    def n_points(self) -> int:
        """The number of points: the product of the shape."""
        return math.prod(self.shape)


def _bounds(n_points: int, chunk_size: int) -> list[tuple[int, int]]:
    return [(a, min(a + chunk_size, n_points)) for a in range(0, n_points, chunk_size)]


def _digest(chunk: int, name: str, values: NDArray[Any]) -> int:
    """The 64-bit BLAKE2b of a chunk's index, a variable's name and its values (as read back)."""
    h = hashlib.blake2b(f"{chunk}\x1f{name}\x1f".encode(), digest_size=8)
    if values.dtype.kind in "OTUS":
        h.update("\x1e".join(str(s) for s in values.tolist()).encode("utf-8", "surrogatepass"))
    else:
        h.update(np.ascontiguousarray(values).tobytes())
    # 0 is the fill value of an unwritten digest: never a real one
    return int.from_bytes(h.digest(), "little") or 1


def _as_stored(dtype: str, values: Any) -> NDArray[Any]:
    """``values`` as they read back from an array of ``dtype`` ('f8', 'i8' or 'str')."""
    if dtype == "str":
        return np.asarray([str(s) for s in np.asarray(values).ravel().tolist()], dtype=str)
    return np.ascontiguousarray(values, dtype=np.dtype(dtype))


def _short(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else ""
    if "checksum" in text:  # zarr's crc32c codec: its bytes are not what was written
        return "its crc32c checksum fails"
    return f"{type(exc).__name__}: {text}"[:120] if text else type(exc).__name__


class ResultStore:
    """A zarr group of point-wise results written chunk by chunk (see the module docstring)."""

    def __init__(self, path: Path, group: Any) -> None:
        self.path = path
        self._group = group
        self._meta = group[_META]
        self.chunk_size = int(self._meta.attrs["chunk_size"])
        self._names = [str(n) for n in self._meta.attrs["variables"]]
        self._coords = {str(k): int(v) for k, v in self._meta.attrs["coordinates"].items()}
        first = group[self._names[0]]
        self.grid_ndim = int(self._meta.attrs["grid_ndim"])
        self.grid_shape = tuple(int(n) for n in first.shape[: self.grid_ndim])
        self.n_points = math.prod(self.grid_shape)
        self.rows = int(first.chunks[0])  # rows of the first dimension per data file
        self.per_file = self.rows * math.prod(self.grid_shape[1:])  # points per data file
        self.per_flag = int(self._meta[_DONE].chunks[0])  # task chunks per flag file
        self._dtypes = {
            n: ("str" if group[n].dtype.kind in "OTUS" else group[n].dtype.str[1:])
            for n in self._names
        }

    def __repr__(self) -> str:
        done = len(self.done_chunks())
        total = self.n_chunks
        return f"ResultStore({str(self.path)!r}, {self.n_points} points, {done}/{total} chunks)"

    @property
    def n_chunks(self) -> int:
        """The number of task chunks."""
        return -(-self.n_points // self.chunk_size)

    @classmethod
    def create(
        cls,
        path: str | Path,
        *,
        fingerprint: str,
        n_points: int,
        chunk_size: int,
        variables: Sequence[Variable],
        attrs: Mapping[str, Any],
        force: bool = False,
        grid: Grid | None = None,
    ) -> ResultStore:
        """Create an empty store; an existing one is replaced only with ``force``.

        ``grid``: the dimensions and coordinates the variables lie on (default: one
        dimension, ``point``, of ``n_points``). The group is written by xarray
        (``Dataset.to_zarr``), so that ``xarray.open_zarr`` reads it back as it is.

        Raises
        ------
        OutputExistsError
            ``path`` exists and ``force`` is False.
        StoreError
            ``path`` exists and is not a sweep store (it is never deleted, even with force);
            ``grid`` does not hold ``n_points``.
        """
        import xarray as xr
        import zarr
        from zarr.codecs import Crc32cCodec, ZstdCodec

        path = Path(path)
        grid = grid or Grid(("point",), (n_points,))
        if grid.n_points != n_points:
            raise StoreError(
                f"a grid of shape {grid.shape} holds {grid.n_points} points, not {n_points}"
            )
        if path.exists():
            if not force:
                raise OutputExistsError(
                    f"will not overwrite {path}; pass resume=True to finish it, force=True "
                    f"to start again, or choose another out"
                )
            _group_of(path)  # a StoreError unless it is a sweep store: never delete anything else
            shutil.rmtree(path)
        n_chunks = -(-n_points // chunk_size)
        inner = math.prod(grid.shape[1:])
        points = chunk_size * -(-POINTS_PER_FILE // chunk_size)  # whole task chunks a file
        rows = min(grid.shape[0], max(1, -(-points // inner)))
        per_flag = min(max(1, -(-POINTS_PER_FILE // chunk_size)), n_chunks)
        codecs = (ZstdCodec(), Crc32cCodec())
        data: dict[str, Any] = {}
        encoding: dict[str, dict[str, Any]] = {}
        for var in variables:
            shape = (*grid.shape, *var.shape)
            if var.dtype == "str":  # variable-length UTF-8: a reason of any length fits
                values: Any = np.full(shape, "", dtype=object)
                fill: Any = ""
            else:
                fill = np.nan if var.dtype == "f8" else 0
                values = np.full(shape, fill, dtype=np.dtype(var.dtype))
            data[var.name] = ((*grid.dims, *("joint",) * len(var.shape)), values, dict(var.attrs))
            encoding[var.name] = {
                "chunks": (rows, *grid.shape[1:], *var.shape),
                "compressors": codecs,
                "fill_value": fill,
            }
        coords = {
            name: (dims, np.asarray(v), dict(a)) for name, (dims, v, a) in grid.coords.items()
        }
        for name in coords:
            encoding[name] = {"compressors": codecs}
        dataset = xr.Dataset(data, coords=coords, attrs={**dict(attrs), _FORMAT: STORE_FORMAT})
        with warnings.catch_warnings():  # xarray asks that object arrays be strings: they are
            warnings.simplefilter("ignore", category=xr.SerializationWarning)
            # arrays of fill values only: zarr writes no chunk file for them
            dataset.to_zarr(
                str(path), mode="w-", zarr_format=3, consolidated=False, encoding=encoding
            )
        group: Any = zarr.open_group(str(path), mode="r+")
        meta = group.create_group(_META)
        digest = meta.create_array(
            _DIGEST,
            shape=(n_chunks, len(variables)),
            chunks=(per_flag, len(variables)),
            dtype="uint64",
            fill_value=0,
            compressors=codecs,
            dimension_names=["chunk", "variable"],
        )
        digest.attrs["variables"] = [v.name for v in variables]
        meta.create_array(
            _DONE,
            shape=(n_chunks,),
            dtype="bool",
            fill_value=False,
            compressors=codecs,
            chunks=(per_flag,),
            dimension_names=["chunk"],
        )
        written = {name: np.asarray(group[name][...]) for name in coords}
        meta.attrs.update(
            {
                "chunk_size": chunk_size,
                "variables": [v.name for v in variables],
                "grid_ndim": len(grid.dims),
                "coordinates": {n: _digest(-1, n, _flat(v)) for n, v in written.items()},
            }
        )
        # the fingerprint last: a store cut while being made is no sweep store
        group.attrs[_FINGERPRINT] = fingerprint
        _consolidate(path)
        return cls(path, zarr.open_group(str(path), mode="r+"))

    @classmethod
    def open(cls, path: str | Path, *, fingerprint: str | None = None) -> ResultStore:
        """Open an existing store; with ``fingerprint``, refuse one made by another sweep.

        Raises
        ------
        StoreError
            ``path`` is not a sweep store, is of an older format, or its fingerprint differs.
        """
        path = Path(path)
        group = _group_of(path)
        stored = group.attrs[_FINGERPRINT]
        if fingerprint is not None and stored != fingerprint:
            raise StoreError(
                f"{path} was made from a different sweep file (hash {stored[:12]} here, "
                f"{fingerprint[:12]} now); use --force to start again or another --out"
            )
        try:
            return cls(path, group)
        except Exception as exc:
            raise StoreError(
                f"{path}: its layout is damaged ({_short(exc)}); run the sweep again with --force"
            ) from None

    @property
    def attrs(self) -> dict[str, Any]:
        """The store's attributes (the sweep's description, as its Dataset's)."""
        return dict(self._group.attrs)

    def done_chunks(self) -> set[int]:
        """Indices of the chunks flagged done (a flag that does not decode: not done)."""
        return {i for i, flag in enumerate(self._flags()[0]) if flag}

    def _flags(self) -> tuple[NDArray[np.bool_], dict[int, str]]:
        """The done flags, and the chunks whose flag does not decode (read as not done)."""
        array = self._meta[_DONE]
        try:
            return np.asarray(array[:], dtype=bool), {}
        except Exception:
            flags = np.zeros(self.n_chunks, dtype=bool)
            bad: dict[int, str] = {}
            for i in range(self.n_chunks):
                try:
                    flags[i] = bool(array[i])
                except Exception as exc:
                    bad[i] = f"its done flag does not decode ({_short(exc)})"
            return flags, bad

    def _array(self, name: str) -> Any:
        return self._meta[name] if name in _OWN else self._group[name]

    def _key(self, name: str, file: int) -> str:
        """The key of zarr chunk file ``file`` (along the first dimension) of array ``name``."""
        array = self._array(name)
        coords = (file, *(0,) * (array.ndim - 1))
        where = f"{_META}/{name}" if name in _OWN else name
        return f"{where}/{array.metadata.encode_chunk_key(coords)}"

    def _files(self, chunk: int) -> range:
        """The data files that hold task chunk ``chunk``'s points."""
        a = chunk * self.chunk_size
        b = min(a + self.chunk_size, self.n_points)
        return range(a // self.per_file, (b - 1) // self.per_file + 1)

    def _chunks(self, file: int) -> range:
        """The task chunks with points in data file ``file``."""
        a = file * self.per_file
        b = min(a + self.per_file, self.n_points)
        return range(a // self.chunk_size, (b - 1) // self.chunk_size + 1)

    def _load(self) -> tuple[dict[str, NDArray[Any]], dict[int, str]]:
        """Every variable in point order (damaged or unwritten chunks as fill values), and
        the damage found.

        Damage is reported for chunks flagged done (or whose flag does not decode); the
        first reason found per chunk, naming the variable.
        """
        flags, damaged = self._flags()
        bounds = _bounds(self.n_points, self.chunk_size)
        digests = np.zeros((self.n_chunks, len(self._names)), dtype=np.uint64)
        try:
            digests[:] = self._meta[_DIGEST][:]
        except Exception:
            for i in range(self.n_chunks):
                try:
                    digests[i] = self._meta[_DIGEST][i]
                except Exception as exc:
                    if flags[i]:
                        damaged.setdefault(i, f"its digest does not decode ({_short(exc)})")
        values: dict[str, NDArray[Any]] = {}
        n_files = -(-self.grid_shape[0] // self.rows)
        for k, name in enumerate(self._names):
            array = self._group[name]
            try:
                data = np.asarray(array[...])
            except Exception:  # find the files that do not decode, read the others
                data = (
                    np.full(array.shape, array.fill_value, dtype=array.dtype)
                    if self._dtypes[name] != "str"
                    else np.full(array.shape, "", dtype=object)
                )
                for f in range(n_files):
                    rows = slice(f * self.rows, (f + 1) * self.rows)
                    try:
                        data[rows] = array[rows]
                    except Exception as exc:
                        for c in self._chunks(f):
                            if flags[c]:
                                damaged.setdefault(c, f"{name} does not decode ({_short(exc)})")
            data = _flat(data, self.grid_ndim)
            if self._dtypes[name] == "str":
                data = np.array(data.tolist(), dtype=str).reshape(data.shape)
            values[name] = data
            for c in np.flatnonzero(flags).tolist():
                if c in damaged:
                    continue
                a, b = bounds[c]
                if _digest(c, name, data[a:b]) == int(digests[c, k]):
                    continue
                if not all(self._exists(self._key(name, f)) for f in self._files(c)):
                    damaged[c] = f"{name}'s data is missing"
                elif digests[c, k] == 0:
                    damaged[c] = f"{name}'s digest is missing"
                else:
                    damaged[c] = f"{name} does not match its checksum"
        return values, damaged

    def _exists(self, key: str) -> bool:
        return (self.path / key).exists()

    def check(self) -> dict[int, str]:
        """Return the damaged chunks: index -> what is wrong (see the module docstring)."""
        return self._load()[1]

    def damaged_coordinates(self) -> dict[str, str]:
        """Return the coordinates whose values are missing, do not decode or do not match
        their digest: name -> what is wrong."""
        damaged: dict[str, str] = {}
        for name, expected in self._coords.items():
            try:
                values = np.asarray(self._group[name][...])
            except Exception as exc:
                damaged[name] = f"does not decode ({_short(exc)})"
                continue
            if _digest(-1, name, _flat(values)) != expected:
                damaged[name] = "does not match its checksum"
        return damaged

    def write_coordinates(self, grid: Grid) -> None:
        """Write the coordinates of ``grid`` again (a resumed run: the same sweep's values)."""
        for name, (_, values, _) in grid.coords.items():
            if name in self._coords:
                self._group[name][...] = np.asarray(values)

    def discard(self, chunks: Sequence[int]) -> set[int]:
        """Unflag ``chunks`` so that they are computed again; return every chunk to recompute.

        A file that does not decode is deleted (zarr could not write into it), so the
        other done chunks it held are unflagged and returned too.
        """
        if not chunks:
            return set()
        flags = self._flags()[0]
        lost = set(chunks)
        files = sorted({f for c in chunks for f in self._files(c)})
        for name in self._names:
            array = self._group[name]
            for f in files:
                try:
                    array[f * self.rows : (f + 1) * self.rows]
                except Exception:
                    (self.path / self._key(name, f)).unlink(missing_ok=True)
                    lost |= {c for c in self._chunks(f) if flags[c]}
        for name in _OWN:
            array = self._meta[name]
            for f in sorted({c // self.per_flag for c in chunks}):
                a = f * self.per_flag
                b = min(a + self.per_flag, self.n_chunks)
                try:
                    array[a:b]
                except Exception:
                    (self.path / self._key(name, f)).unlink(missing_ok=True)
                    lost |= {c for c in range(a, b) if flags[c]}
        for run in _runs(np.asarray(sorted(lost))):
            self._meta[_DONE][run[0] : run[-1] + 1] = False
        return lost

    def describe(self, chunk: int) -> str:
        """``chunk 3 (points 6-7)``: a chunk as a message names it."""
        a, b = _bounds(self.n_points, self.chunk_size)[chunk]
        return f"chunk {chunk} (points {a}-{b - 1})" if b - a > 1 else f"chunk {chunk} (point {a})"

    def write(self, chunk: int, values: Mapping[str, NDArray[Any]]) -> None:
        """Write one chunk's values, then flag it done (so a cut never leaves half)."""
        self.write_many([(chunk, values)])

    def write_many(self, chunks: Sequence[tuple[int, Mapping[str, NDArray[Any]]]]) -> None:
        """Write several chunks' values, their digests, then their done flags.

        One zarr write per array for the whole batch (zarr reads and rewrites each file
        it touches once, several at a time); flags go last, so a cut leaves no chunk
        flagged done without its values.
        """
        if not chunks:
            return
        order = sorted(chunks, key=lambda item: item[0])
        size, n = self.chunk_size, self.n_points
        bounds = {chunk: (chunk * size, min(chunk * size + size, n)) for chunk, _ in order}
        index = np.asarray([chunk for chunk, _ in order])
        points = np.concatenate([np.arange(*bounds[chunk]) for chunk in index.tolist()])
        digests = np.zeros((len(order), len(self._names)), dtype=np.uint64)
        for k, name in enumerate(self._names):
            parts = [_as_stored(self._dtypes[name], values[name]) for _, values in order]
            for j, (chunk, _) in enumerate(order):
                a, b = bounds[chunk]
                if len(parts[j]) != b - a:
                    raise StoreError(
                        f"{self.path}: {name} holds {len(parts[j])} values for points {a}-{b - 1}"
                    )
                digests[j, k] = _digest(chunk, name, parts[j])
            _write_points(self._group[name], self.grid_shape, points, np.concatenate(parts))
        # the small bookkeeping arrays: their span read, patched and written in one slice
        # (zarr's orthogonal indexing costs 3-5 times as much; this is the one writer)
        span = slice(int(index[0]), int(index[-1]) + 1)
        whole = index[-1] - index[0] + 1 == len(index)
        stored = digests if whole else np.asarray(self._meta[_DIGEST][span])
        stored[index - index[0]] = digests
        self._meta[_DIGEST][span] = stored
        flags = np.ones(len(index), dtype=bool) if whole else np.asarray(self._meta[_DONE][span])
        flags[index - index[0]] = True
        self._meta[_DONE][span] = flags

    def read(self) -> dict[str, tuple[NDArray[Any], dict[str, Any]]]:
        """Every variable in point order (C order over the grid) with its attributes (not
        yet computed: NaN / '').

        Raises
        ------
        StoreError
            A chunk flagged done, or a coordinate, is damaged: one line naming it (and
            how many others).
        """
        values, damaged = self._load()
        if damaged:
            first = min(damaged)
            more = f" (and {len(damaged) - 1} other chunks)" if len(damaged) > 1 else ""
            raise StoreError(
                f"{self.path}: {self.describe(first)} is damaged: {damaged[first]}{more}; "
                f"run the sweep again with --resume to recompute it"
            )
        coordinates = self.damaged_coordinates()
        if coordinates:
            name = min(coordinates)
            raise StoreError(
                f"{self.path}: the coordinate {name} is damaged: it {coordinates[name]}; "
                f"run the sweep again with --resume to write it again"
            )
        return {
            name: (
                values[name],
                {k: v for k, v in self._group[name].attrs.items() if k not in _XARRAY_ATTRS},
            )
            for name in self._names
        }

    def write_counts(self, status: NDArray[Any] | None = None) -> None:
        """Write ``points_failed`` and ``points_missing`` (from ``status``, read from the
        store if not given) into the store's attributes, and consolidate its metadata
        again, so that a plain ``xarray.open_zarr`` reads them as of now."""
        if status is None:
            try:
                status = np.asarray(self._group["status"][...])
            except Exception:  # damaged: the next resume or open says so
                return
        failed, missing = status_counts(status)
        self._group.attrs.update({"points_failed": failed, "points_missing": missing})
        _consolidate(self.path)


def _consolidate(path: Path) -> None:
    """Consolidate the store's metadata, as ``Dataset.to_zarr`` does by default (so that
    ``xarray.open_zarr`` opens it without a warning); zarr's note that consolidated
    metadata is not yet in the v3 specification is not the user's to read."""
    import zarr

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Consolidated metadata", category=UserWarning)
        zarr.consolidate_metadata(str(path))


def status_counts(status: NDArray[Any]) -> tuple[int, int]:
    """(failed, missing) points of a ``status`` array: failed is neither ``ok...`` nor ''."""
    text = np.array(np.asarray(status).tolist(), dtype=str)  # StringDType as zarr reads it
    ok = np.char.startswith(text, "ok")
    missing = text == ""
    return int(np.count_nonzero(~ok & ~missing)), int(np.count_nonzero(missing))


def _flat(values: NDArray[Any], grid_ndim: int = 0) -> NDArray[Any]:
    """``values`` with the grid's ``grid_ndim`` dimensions as one, in C order (0: all)."""
    values = np.asarray(values)
    if grid_ndim == 0:
        return values.reshape(-1)
    return values.reshape(-1, *values.shape[grid_ndim:])


def _write_points(
    array: Any, shape: tuple[int, ...], points: NDArray[np.int64], data: NDArray[Any]
) -> None:
    """Write the values of ``points`` (sorted indices, C order over the grid ``shape``).

    One run of whole rows of the first dimension goes in one slice; anything else by
    coordinates, in one call (zarr reads and rewrites each file it shares with other
    points once).
    """
    inner = math.prod(shape[1:])
    extra = data.shape[1:]
    a, b = int(points[0]), int(points[-1]) + 1
    if b - a == len(points) and a % inner == 0 and b % inner == 0:
        array[a // inner : b // inner] = data.reshape(-1, *shape[1:], *extra)
        return
    index = np.unravel_index(points, shape)
    if extra:  # a per-point vector: every value of each point
        n = math.prod(extra)
        rest = np.unravel_index(np.tile(np.arange(n), len(points)), extra)
        index = (*(np.repeat(i, n) for i in index), *rest)
    array.vindex[index] = data.reshape(-1)


def _runs(index: NDArray[Any]) -> list[list[int]]:
    """Sorted integers in runs of consecutive ones."""
    runs: list[list[int]] = []
    for i in sorted(int(x) for x in index):
        if runs and runs[-1][-1] + 1 == i:
            runs[-1].append(i)
        else:
            runs.append([i])
    return runs


def _group_of(path: Path) -> Any:
    """The zarr group of a sweep store of this format at ``path``, or one clear StoreError."""
    import zarr

    if not path.exists():
        raise StoreError(f"{path}: no such result store; check the path")
    if not (path / "zarr.json").is_file():  # a file, a folder of something else
        raise StoreError(f"{path}: not a clearjoint sweep store (no zarr.json); left as it is")
    try:
        group: Any = zarr.open_group(str(path), mode="r+")
        str(group.attrs[_FINGERPRINT])  # a KeyError: a group that is no sweep store
    except (KeyError, OSError, ValueError, TypeError) as exc:
        raise StoreError(
            f"{path}: not a clearjoint sweep store ({type(exc).__name__}: {exc}); "
            f"choose another --out"
        ) from None
    found = group.attrs.get(_FORMAT, 1)
    if found != STORE_FORMAT:
        what = _OLD_FORMATS.get(found, "not this clearjoint's layout")
        raise StoreError(
            f"{path}: a sweep store of an older clearjoint (format {found}: {what}; this one "
            f"reads format {STORE_FORMAT}, the labelled grid); run the sweep again with "
            f"--force, or choose another --out"
        )
    return group
