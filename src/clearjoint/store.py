"""A sweep's results on disk: a zarr group written chunk by chunk, that checks itself.

No physics here. The store holds one array per variable along ``point`` (a zarr
chunk per task chunk), a ``chunk_done`` flag per chunk written after its values,
and a ``chunk_digest`` per chunk and variable: a 64-bit BLAKE2b of the chunk's
index, the variable's name and its values, written with them. Every array chunk
also carries zarr's own crc32c codec (the zarr v3 ``crc32c`` codec, checked by
zarr as the chunk is decoded).

A chunk flagged done is *damaged* when one of its variables' data is missing, does
not decode (a checksum of its bytes that fails, a truncated or emptied file), or
does not match its digest (a flipped bit that still decodes, a neighbour chunk's
file copied over it, a deleted chunk read back as fill values). :meth:`ResultStore.read`
refuses a damaged store with one line naming the chunk; :meth:`ResultStore.check`
lists the damage so that a resumed run recomputes those chunks.

A store records the fingerprint of the sweep that made it (resuming from another
sweep is refused) and its format (:data:`STORE_FORMAT`): a store of an older format
is refused with one line.
"""

from __future__ import annotations

import hashlib
import shutil
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import ClearjointError, OutputExistsError

__all__ = [
    "STORE_FORMAT",
    "ResultStore",
    "StoreError",
    "StoreWarning",
    "Variable",
]

#: The store layout this clearjoint writes: 2 adds crc32c and the chunk digests.
STORE_FORMAT = 2

#: Points per zarr chunk file, at least: small task chunks share a file (whole task
#: chunks per file), so a batch of them is a few files, not a few per task chunk.
POINTS_PER_FILE = 256

_FINGERPRINT = "clearjoint_sweep_fingerprint"
_FORMAT = "clearjoint_store_format"
_DONE = "chunk_done"
_DIGEST = "chunk_digest"
_OWN = (_DONE, _DIGEST)


class StoreError(ClearjointError, ValueError):
    """A result store cannot be used: another sweep's, not a sweep store, damaged, or in use."""


class StoreWarning(UserWarning):
    """Said once by a run that repairs a store or takes over a stale lock, then goes on."""


@dataclass(frozen=True)
class Variable:
    """One array of a store: its name, numpy dtype ('f8', 'i8' or 'str') and attributes.

    ``shape`` is what each point holds beyond the ``point`` dimension: () for one
    value, (n,) for n values (a per-joint draw: dimension ``joint``).
    """

    name: str
    dtype: str
    attrs: Mapping[str, Any]
    shape: tuple[int, ...] = ()


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

    def __init__(self, path: Path, group: Any, chunk_size: int, n_points: int) -> None:
        self.path = path
        self._group = group
        self.chunk_size = chunk_size
        self.n_points = n_points
        self._names = [str(n) for n in group[_DIGEST].attrs["variables"]]
        self.per_file = int(group[_DONE].chunks[0])  # task chunks per zarr chunk file
        self._dtypes = {
            n: ("str" if group[n].dtype.kind in "OTUS" else group[n].dtype.str[1:])
            for n in self._names
        }

    def __repr__(self) -> str:
        done = len(self.done_chunks())
        total = len(_bounds(self.n_points, self.chunk_size))
        return f"ResultStore({str(self.path)!r}, {self.n_points} points, {done}/{total} chunks)"

    @property
    def n_chunks(self) -> int:
        """The number of chunks."""
        return len(_bounds(self.n_points, self.chunk_size))

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
    ) -> ResultStore:
        """Create an empty store; an existing one is replaced only with ``force``.

        Raises
        ------
        OutputExistsError
            ``path`` exists and ``force`` is False.
        StoreError
            ``path`` exists and is not a sweep store (it is never deleted, even with force).
        """
        import zarr
        from zarr.codecs import Crc32cCodec, ZstdCodec

        path = Path(path)
        if path.exists():
            if not force:
                raise OutputExistsError(
                    f"will not overwrite {path}; pass resume=True to finish it, force=True "
                    f"to start again, or choose another out"
                )
            _group_of(path)  # a StoreError unless it is a sweep store: never delete anything else
            shutil.rmtree(path)
        group: Any = zarr.open_group(str(path), mode="w-", zarr_format=3)
        n_chunks = len(_bounds(n_points, chunk_size))
        per_file = min(max(1, -(-POINTS_PER_FILE // chunk_size)), n_chunks)
        codecs = (ZstdCodec(), Crc32cCodec())
        for var in variables:
            kind: Any = str if var.dtype == "str" else var.dtype
            fill: Any = "" if var.dtype == "str" else (np.nan if var.dtype == "f8" else 0)
            array = group.create_array(
                var.name,
                shape=(n_points, *var.shape),
                chunks=(chunk_size * per_file, *var.shape),
                dtype=kind,
                fill_value=fill,
                compressors=codecs,
                dimension_names=["point", *("joint",) * len(var.shape)],
            )
            array.attrs.update(dict(var.attrs))
        digest = group.create_array(
            _DIGEST,
            shape=(n_chunks, len(variables)),
            chunks=(per_file, len(variables)),
            dtype="uint64",
            fill_value=0,
            compressors=codecs,
            dimension_names=["chunk", "variable"],
        )
        digest.attrs["variables"] = [v.name for v in variables]
        group.create_array(
            _DONE,
            shape=(n_chunks,),
            dtype="bool",
            fill_value=False,
            compressors=codecs,
            chunks=(per_file,),
            dimension_names=["chunk"],
        )
        # the fingerprint last: a store cut while being made is no sweep store
        group.attrs.update(
            {
                **dict(attrs),
                "chunk_size": chunk_size,
                _FORMAT: STORE_FORMAT,
                _FINGERPRINT: fingerprint,
            }
        )
        return cls(path, group, chunk_size, n_points)

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
        chunk_size = int(group.attrs["chunk_size"])
        try:
            names = list(group[_DIGEST].attrs["variables"])
            n_points = int(group[names[0]].shape[0])
        except Exception as exc:
            raise StoreError(
                f"{path}: its layout is damaged ({_short(exc)}); run the sweep again with --force"
            ) from None
        return cls(path, group, chunk_size, n_points)

    @property
    def attrs(self) -> dict[str, Any]:
        """The store's attributes (the sweep's description)."""
        return dict(self._group.attrs)

    def done_chunks(self) -> set[int]:
        """Indices of the chunks flagged done (a flag that does not decode: not done)."""
        return {i for i, flag in enumerate(self._flags()[0]) if flag}

    def _flags(self) -> tuple[NDArray[np.bool_], dict[int, str]]:
        """The done flags, and the chunks whose flag does not decode (read as not done)."""
        array = self._group[_DONE]
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

    def _chunk_key(self, name: str, chunk: int) -> str:
        """The key of the zarr chunk file of array ``name`` that holds task chunk ``chunk``."""
        array = self._group[name]
        coords = (chunk // self.per_file, *(0,) * (array.ndim - 1))
        return f"{name}/{array.metadata.encode_chunk_key(coords)}"

    def _load(self) -> tuple[dict[str, NDArray[Any]], dict[int, str]]:
        """Every variable (damaged or unwritten chunks as fill values) and the damage found.

        Damage is reported for chunks flagged done (or whose flag does not decode); the
        first reason found per chunk, naming the variable.
        """
        flags, damaged = self._flags()
        bounds = _bounds(self.n_points, self.chunk_size)
        digests = np.zeros((self.n_chunks, len(self._names)), dtype=np.uint64)
        try:
            digests[:] = self._group[_DIGEST][:]
        except Exception:
            for i in range(self.n_chunks):
                try:
                    digests[i] = self._group[_DIGEST][i]
                except Exception as exc:
                    if flags[i]:
                        damaged.setdefault(i, f"its digest does not decode ({_short(exc)})")
        values: dict[str, NDArray[Any]] = {}
        for k, name in enumerate(self._names):
            array = self._group[name]
            try:
                data = np.asarray(array[:])
            except Exception:  # find the chunks that do not decode, read the others
                data = np.asarray(
                    np.full(array.shape, array.fill_value, dtype=array.dtype.str)
                    if self._dtypes[name] != "str"
                    else np.full(array.shape, "", dtype=object)
                )
                for i, (a, b) in enumerate(bounds):
                    try:
                        data[a:b] = array[a:b]
                    except Exception as exc:
                        if flags[i]:
                            damaged.setdefault(i, f"{name} does not decode ({_short(exc)})")
            if self._dtypes[name] == "str":
                data = np.array(data.tolist(), dtype=str).reshape(array.shape)
            values[name] = data
            for c in np.flatnonzero(flags).tolist():
                if c in damaged:
                    continue
                a, b = bounds[c]
                if _digest(c, name, data[a:b]) == int(digests[c, k]):
                    continue
                if not self._exists(self._chunk_key(name, c)):
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

    def discard(self, chunks: Sequence[int]) -> set[int]:
        """Unflag ``chunks`` so that they are computed again; return every chunk to recompute.

        A file that does not decode is deleted (zarr could not write into it), so the
        other done chunks it held are unflagged and returned too.
        """
        if not chunks:
            return set()
        flags = self._flags()[0]
        lost = set(chunks)
        files = sorted({c // self.per_file for c in chunks})
        for name in (*self._names, *_OWN):
            array = self._group[name]
            scale = self.chunk_size if name in self._names else 1
            for f in files:
                a = f * self.per_file
                b = min(a + self.per_file, self.n_chunks)
                try:
                    array[a * scale : min(b * scale, array.shape[0])]
                except Exception:
                    (self.path / self._chunk_key(name, a)).unlink(missing_ok=True)
                    lost |= {c for c in range(a, b) if flags[c]}
        for run in _runs(np.asarray(sorted(lost))):
            self._group[_DONE][run[0] : run[-1] + 1] = False
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

        Chunks next to each other are written in one slice of each array (zarr writes
        their chunk files concurrently); flags go last, so a cut leaves no chunk flagged
        done without its values.
        """
        if not chunks:
            return
        order = sorted(chunks, key=lambda item: item[0])
        bounds = _bounds(self.n_points, self.chunk_size)
        runs: list[list[tuple[int, Mapping[str, NDArray[Any]]]]] = []
        for item in order:
            if runs and runs[-1][-1][0] + 1 == item[0]:
                runs[-1].append(item)
            else:
                runs.append([item])
        digests = np.zeros((len(order), len(self._names)), dtype=np.uint64)
        row = 0
        for run in runs:
            a = bounds[run[0][0]][0]
            b = bounds[run[-1][0]][1]
            for k, name in enumerate(self._names):
                parts = [_as_stored(self._dtypes[name], values[name]) for _, values in run]
                for j, (chunk, _) in enumerate(run):
                    digests[row + j, k] = _digest(chunk, name, parts[j])
                data = np.concatenate(parts)
                if len(data) != b - a:
                    raise StoreError(
                        f"{self.path}: {name} holds {len(data)} values for points {a}-{b - 1}"
                    )
                self._group[name][a:b] = data
            row += len(run)
        index = np.asarray([chunk for chunk, _ in order])
        for run_index in _runs(index):
            rows = np.flatnonzero(np.isin(index, run_index))
            self._group[_DIGEST][run_index[0] : run_index[-1] + 1] = digests[rows]
        for run_index in _runs(index):
            self._group[_DONE][run_index[0] : run_index[-1] + 1] = True

    def read(self) -> dict[str, tuple[NDArray[Any], dict[str, Any]]]:
        """Every variable along ``point`` with its attributes (not yet computed: NaN / '').

        Raises
        ------
        StoreError
            A chunk flagged done is damaged: one line naming it (and how many others).
        """
        values, damaged = self._load()
        if damaged:
            first = min(damaged)
            more = f" (and {len(damaged) - 1} other chunks)" if len(damaged) > 1 else ""
            raise StoreError(
                f"{self.path}: {self.describe(first)} is damaged: {damaged[first]}{more}; "
                f"run the sweep again with --resume to recompute it"
            )
        return {name: (values[name], dict(self._group[name].attrs)) for name in self._names}


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
        int(group.attrs["chunk_size"])
    except (KeyError, OSError, ValueError, TypeError) as exc:
        raise StoreError(
            f"{path}: not a clearjoint sweep store ({type(exc).__name__}: {exc}); "
            f"choose another --out"
        ) from None
    if group.attrs.get(_FORMAT) != STORE_FORMAT:
        raise StoreError(
            f"{path}: a sweep store of an older clearjoint (format "
            f"{group.attrs.get(_FORMAT, 1)}, no checksums; this one reads format "
            f"{STORE_FORMAT}); run the sweep again with --force, or choose another --out"
        )
    return group
