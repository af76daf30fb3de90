"""Run a sweep on Dask (or an executor, or here), chunk by chunk into a resumable zarr store.

Each chunk is a pure function of frozen values (the task, the base, the points'
values and their indices); a point's random numbers come from
``clearjoint.parallel.point_seed(sweep.seed, index)``, so the results are the same
bit for bit whatever the workers. A point whose task raises is NaN with the reason
in ``status``; the sweep goes on.
"""

from __future__ import annotations

import contextlib
import json
import math
import time
import warnings
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import OutputExistsError, ParameterError
from clearjoint.lock import LOCK_TIMEOUT_S, StoreLock
from clearjoint.parallel import (
    ChunkFailedError,
    ResultStore,
    Runner,
    Variable,
    chunk_bounds,
    dask_client,
    is_dask_client,
    jobqueue_client,
    point_seed,
    record_warnings,
    run_batches,
)
from clearjoint.store import Grid, StoreWarning, status_counts
from clearjoint.sweep.file import Sweep
from clearjoint.sweep.tasks import Task

__all__ = [
    "SERIAL",
    "open_sweep",
    "run_sweep",
    "run_sweep_file",
]

#: Pass as ``client`` to run every chunk in this process, one after the other.
SERIAL = "serial"

#: Seconds at least between two writes to the store on a Dask client (results in between
#: are held by the client, their futures let go): a few large writes, not one a chunk.
_WRITE_EVERY_S = 1.0

#: Seconds of waiting at least per second spent writing the store: writes of many chunks
#: cost about as much as writes of few (a zarr file is rewritten whole), so the pause
#: between two grows with what the last one took, keeping the client free for Dask.
_WRITE_SHARE = 4.0


class _Pace:
    """When the next batch of results is due to be written (see :data:`_WRITE_SHARE`)."""

    def __init__(self) -> None:
        self.last = -math.inf  # the first batch is written at once
        self.cost = 0.0

    def due(self) -> bool:
        return time.monotonic() - self.last >= max(_WRITE_EVERY_S, _WRITE_SHARE * self.cost)

    @contextlib.contextmanager
    def timed(self) -> Iterator[None]:
        start = time.monotonic()
        yield
        self.last = time.monotonic()
        self.cost = self.last - start


class _Writer:
    """Writes batches of results in a thread of its own, in order, one at a time.

    The first error it meets (a store in use by another client, a full disk) is raised
    by the next :meth:`put` or by :meth:`close`; batches after it are not written.
    """

    def __init__(self, write: Callable[[Any], None]) -> None:
        import queue
        import threading

        self._write = write
        self._queue: queue.Queue[Any] = queue.Queue()
        self._busy = threading.Event()
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._loop, name="clearjoint-store", daemon=True)
        self._thread.start()

    def _loop(self) -> None:
        while True:
            batch = self._queue.get()
            if batch is None:
                return
            try:
                if self._error is None:
                    self._write(batch)
            except BaseException as exc:  # raised in the caller's thread
                self._error = exc
            finally:
                self._busy.clear()

    def _raise(self) -> None:
        if self._error is not None:
            error, self._error = self._error, None
            raise error

    def idle(self) -> bool:
        """True when no batch is being written."""
        return not self._busy.is_set()

    def put(self, batch: Any) -> None:
        """Hand over a batch (raising a past write's error first)."""
        self._raise()
        if batch:
            self._busy.set()
            self._queue.put(batch)

    def close(self, *, quiet: bool = False) -> None:
        """Write what was handed over, stop the thread, raise a write's error (not if
        ``quiet``: the caller is ending with an error of its own)."""
        self._queue.put(None)
        self._thread.join()
        if not quiet:
            self._raise()


#: Longest reason kept in ``status`` for a failed point.
_REASON_CHARS = 300


@dataclass(frozen=True)
class _Chunk:
    """Everything one chunk needs, frozen and picklable."""

    task: Task
    base: Any
    names: tuple[str, ...]
    values: NDArray[np.float64]  # (n, len(names))
    first: int
    seed: int
    outputs: tuple[str, ...]
    fixed: tuple[tuple[str, float], ...]


def _evaluate_chunk(chunk: _Chunk) -> dict[str, NDArray[Any]]:
    """Run the task at every point of the chunk: outputs (n,) and ``status`` (n,) of str.

    ``status`` is "ok", "ok; <first warning>" (values kept), or "<Error>: <message>"
    for a point whose task raised (its outputs NaN).
    """
    n = chunk.values.shape[0]
    out = {name: np.full(n, np.nan) for name in chunk.outputs}
    status = np.full(n, "ok", dtype=object)
    fixed = dict(chunk.fixed)
    for row in range(n):
        values = {**fixed, **dict(zip(chunk.names, map(float, chunk.values[row]), strict=True))}
        try:
            with record_warnings() as caught:  # this thread's alone (threaded workers)
                result = chunk.task.evaluate(
                    chunk.base, values, point_seed(chunk.seed, chunk.first + row)
                )
        except Exception as exc:  # a failed point is recorded, never a crashed sweep
            status[row] = f"{type(exc).__name__}: {exc}"[:_REASON_CHARS]
            continue
        if caught:  # kept beside the values: "ok; SomeWarning: ..."
            first = caught[0]
            status[row] = f"ok; {first.category.__name__}: {first.message}"[:_REASON_CHARS]
        for name in chunk.outputs:
            out[name][row] = result[name]
    return {**out, "status": np.asarray(status.astype(str))}


def _evaluate_chunk_lists(chunk: _Chunk) -> dict[str, list[Any]]:
    """:func:`_evaluate_chunk` with each array as a list, as it travels back to the client.

    Pickling a list of floats costs a fraction of pickling a small numpy array (measured
    by benchmarks/bench_sweep.py --store-targets: a Dask task of 25 one-point chunks
    pickled in 0.43 ms as arrays, 6 us as lists); :func:`_from_lists` restores the arrays
    exactly (a float64 goes to a Python float and back unchanged, NaN included).
    """
    return {name: values.tolist() for name, values in _evaluate_chunk(chunk).items()}


def _from_lists(result: Mapping[str, list[Any]]) -> dict[str, NDArray[Any]]:
    """The arrays of :func:`_evaluate_chunk` from :func:`_evaluate_chunk_lists`'s lists."""
    return {
        name: np.asarray(values, dtype=str) if name == "status" else np.asarray(values, float)
        for name, values in result.items()
    }


def _point_values(sweep: Sweep, drawn: Mapping[str, NDArray[np.float64]], a: int, b: int) -> Any:
    index = np.unravel_index(np.arange(a, b), sweep.shape)
    columns = []
    offset = 1 if sweep.samples else 0
    for d in sweep.draws:
        columns.append(drawn[d.name][index[0]])
    for k, axis in enumerate(sweep.axes):
        columns.append(np.asarray(axis.values)[index[k + offset]])
    if not columns:
        return np.zeros((b - a, 0))
    return np.column_stack(columns)


def _column_names(sweep: Sweep) -> tuple[str, ...]:
    """The name of each column of :func:`_point_values`: a per-joint draw gives ``name[j]``."""
    names: list[str] = []
    for d in sweep.draws:
        names += [f"{d.name}[{j}]" for j in range(d.per_joint)] if d.per_joint else [d.name]
    return (*names, *(a.name for a in sweep.axes))


def _attrs(sweep: Sweep) -> dict[str, Any]:
    """The Dataset's attributes (and the store's): what the sweep was, and how many points."""
    return {
        "title": f"clearjoint sweep: {sweep.task.name}",
        "task": sweep.task.name,
        "sweep_file": sweep.source,
        "base": str(getattr(sweep.base, "source", "")),
        "seed": sweep.seed,
        "fixed": json.dumps(dict(sweep.fixed)),
        "clearjoint_sweep_fingerprint": sweep.fingerprint,
        "points": sweep.n_points,
    }


def _grid(sweep: Sweep) -> Grid:
    """The sweep's labelled grid: ``sample`` (with draws) and one dimension per axis, each
    with its values; drawn values as coordinates over ``sample`` (and ``joint``)."""
    coords: dict[str, tuple[tuple[str, ...], Any, dict[str, Any]]] = {}
    if sweep.samples:
        coords["sample"] = (("sample",), np.arange(sweep.samples), {})
    for axis in sweep.axes:
        coords[axis.name] = ((axis.name,), np.asarray(axis.values), {"units": axis.unit})
    files = list(getattr(sweep.base, "files", []))
    if files:  # a record set: its files beside the record index
        coords["record"] = (("record",), np.arange(len(files)), {})
        coords["file"] = (("record",), np.asarray(files, dtype=str), {})
    for d, values in zip(sweep.draws, sweep.drawn().values(), strict=True):
        dims = ("sample", "joint")[: values.ndim]
        coords[d.name] = (dims, values, {"units": d.unit, "distribution": d.distribution})
    return Grid(sweep.dims, sweep.shape, coords)


def _variables(sweep: Sweep) -> list[Variable]:
    out = [Variable(name, "f8", {"units": sweep.task.outputs[name]}) for name in sweep.outputs]
    out.append(Variable("status", "str", {"description": "ok, or why the point failed"}))
    return out


@contextlib.contextmanager
def _runner(client: Any, workers: int | None) -> Iterator[Runner]:
    if client is None:
        with dask_client(workers=workers) as local:
            yield local
    elif isinstance(client, str) and client == SERIAL:
        yield None
    else:
        yield client


def run_sweep(
    sweep: Sweep,
    *,
    client: Any = None,
    out: str | Path | None = None,
    resume: bool = False,
    force: bool = False,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    retries: int = 0,
    lock_timeout: float = LOCK_TIMEOUT_S,
) -> Any:
    """Run the sweep and return its results as an xarray.Dataset.

    Parameters
    ----------
    sweep : Sweep
    client : distributed.Client, concurrent.futures.Executor, "serial" or None
        Where the chunks run. None starts a dask.distributed LocalCluster of
        ``workers`` processes (default: one per core) for this run.
    out : path, optional
        A zarr store written chunk by chunk as chunks finish.
    resume : bool
        Continue the store at ``out``: compute only the chunks it lacks. The store
        must come from the same sweep (its fingerprint).
    force : bool
        Replace an existing store at ``out`` (without it, and without ``resume``, an
        existing store is an error).
    workers : int, optional
        Workers of the LocalCluster started when ``client`` is None.
    progress : callable, optional
        ``progress(points_done, points_total)`` after each batch of chunks is stored
        (and once at the start).
    retries : int
        Times a chunk is run again on a Dask client after its worker is lost or it
        raises (default 0: such a chunk is reported, the others kept).
    lock_timeout : float
        Seconds without a heartbeat after which another client's lock on ``out`` is
        stale and taken over (see :mod:`clearjoint.lock`); a fresh one is refused.

    Returns
    -------
    xarray.Dataset
        One dimension per grid axis (after ``sample`` for Monte Carlo), each output
        and ``status`` (``"ok"`` or why the point failed) over them, drawn values
        as coordinates over ``sample``; units in each variable's ``units`` attribute.

    Raises
    ------
    OutputExistsError
        ``out`` exists and neither ``resume`` nor ``force`` is given.
    StoreError
        ``resume`` against a store made by a different sweep or of an older format;
        ``out`` in use by another client (its lock); a store damaged after this run
        wrote it.
    ChunkFailedError
        A chunk did not finish (a worker died); every other chunk is in the store.
    """
    if out is None:
        return _run(sweep, None, None, client, workers, progress, retries)
    with StoreLock(out, timeout=lock_timeout) as lock:
        store = _open_or_create(sweep, Path(out), resume=resume, force=force)
        return _run(sweep, store, lock, client, workers, progress, retries)


def _open_or_create(sweep: Sweep, path: Path, *, resume: bool, force: bool) -> ResultStore:
    """The sweep's store at ``path`` (its lock held): resumed and repaired, or made anew."""
    if resume and path.exists():
        store = ResultStore.open(path, fingerprint=sweep.fingerprint)
        _repair(store, sweep)
        return store
    return ResultStore.create(
        path,
        fingerprint=sweep.fingerprint,
        n_points=sweep.n_points,
        chunk_size=sweep.chunk_size,
        variables=_variables(sweep),
        attrs=_attrs(sweep),
        force=force,
        grid=_grid(sweep),
    )


def _run(
    sweep: Sweep,
    store: ResultStore | None,
    lock: StoreLock | None,
    client: Any,
    workers: int | None,
    progress: Callable[[int, int], None] | None,
    retries: int,
) -> Any:
    """Run the chunks not done in ``store`` (all without one), writing them batch by batch."""
    bounds = chunk_bounds(sweep.n_points, sweep.chunk_size)
    todo = list(range(len(bounds)))
    if store is not None:
        done = store.done_chunks()
        todo = [i for i in todo if i not in done]
    names = _column_names(sweep)
    points = _point_values(sweep, sweep.drawn(), 0, sweep.n_points)  # once: O(n), not O(n^2)
    chunks = [
        _Chunk(
            task=sweep.task,
            base=sweep.base,
            names=names,
            values=points[bounds[i][0] : bounds[i][1]],
            first=bounds[i][0],
            seed=sweep.seed,
            outputs=sweep.outputs,
            fixed=sweep.fixed,
        )
        for i in todo
    ]
    finished = sweep.n_points - sum(bounds[i][1] - bounds[i][0] for i in todo)
    if progress:
        progress(finished, sweep.n_points)
    in_memory: dict[int, dict[str, NDArray[Any]]] = {}
    failures: list[str] = []
    counted = False  # the store's attributes count the points as stored
    with contextlib.ExitStack() as stack:
        if store is not None:  # its attributes count the points however the run ends
            stack.callback(lambda: None if counted else store.write_counts())
        if chunks:
            runner = stack.enter_context(_runner(client, workers))
            batches = run_batches(
                _evaluate_chunk_lists,
                chunks,
                runner,
                retries=retries,
                every=_WRITE_EVERY_S,
                group=None,  # short chunks share a Dask task (parallel.auto_group)
            )
            pending: list[tuple[int, dict[str, NDArray[Any]]]] = []
            pace = _Pace()

            def store_batch(written: list[tuple[int, dict[str, NDArray[Any]]]]) -> None:
                nonlocal finished
                if store is not None and lock is not None:
                    lock.check()
                    with pace.timed():
                        store.write_many(written)
                else:
                    in_memory.update(written)
                finished += sum(bounds[c][1] - bounds[c][0] for c, _ in written)
                if progress and written:
                    progress(finished, sweep.n_points)

            def take() -> list[tuple[int, dict[str, NDArray[Any]]]]:
                written = list(pending)
                pending.clear()
                return written

            # on a Dask client the store is written by a thread of its own, so that the
            # client goes on fetching results (and the scheduler, in this process for a
            # LocalCluster, on scheduling) while zarr writes
            writer = _Writer(store_batch) if store is not None and is_dask_client(runner) else None
            try:
                for batch in batches:
                    for outcome in batch:
                        chunk = todo[outcome.index]
                        if outcome.error is not None or outcome.result is None:
                            error = outcome.error
                            failures.append(f"chunk {chunk}: {type(error).__name__}: {error}")
                            continue
                        pending.append((chunk, _from_lists(outcome.result)))
                    if writer is not None:
                        if pace.due() and writer.idle():
                            writer.put(take())
                    elif store is None or pace.due():
                        store_batch(take())
                if writer is not None:
                    writer.put(take())
                else:
                    store_batch(take())
            except BaseException as exc:
                if isinstance(exc, KeyboardInterrupt) and pending:  # what has come back is
                    if writer is None:  # kept: stored before stopping
                        store_batch(take())
                    else:
                        writer.put(take())
                if writer is not None:  # what was handed over is written, then the error
                    writer.close(quiet=True)  # the run ends with, never one of the writer's
                raise
            if writer is not None:
                writer.close()
        if store is not None and not failures:  # checked once, and counted from that read
            flat = store.read()
            store.write_counts(flat["status"][0])
            counted = True
    if failures:
        where = (
            f"; the others are in {store.path}: finish with --resume" if store is not None else ""
        )
        raise ChunkFailedError(
            f"{len(failures)} of {len(bounds)} chunks did not finish ({failures[0]}){where}"
        )
    if store is not None:
        # the values just checked, on the grid: what xarray.open_zarr reads (tested)
        return _dataset(_grid(sweep), flat, store.attrs)
    flat = {
        var.name: (
            np.concatenate([in_memory[i][var.name] for i in range(len(bounds))]),
            dict(var.attrs),
        )
        for var in _variables(sweep)
    }
    return _dataset(_grid(sweep), flat, _attrs(sweep))


def _repair(store: ResultStore, sweep: Sweep) -> None:
    """Unflag the store's damaged chunks, so that they are computed again, and write its
    damaged coordinates again; say so in one line each."""
    coordinates = store.damaged_coordinates()
    if coordinates:
        store.write_coordinates(_grid(sweep))
        name = min(coordinates)
        warnings.warn(
            StoreWarning(
                f"{store.path}: writing {len(coordinates)} damaged coordinates again "
                f"(first: {name}: it {coordinates[name]})"
            ),
            stacklevel=3,
        )
    damaged = store.check()
    if not damaged:
        return
    again = store.discard(sorted(damaged))
    bounds = chunk_bounds(store.n_points, store.chunk_size)
    points = sum(bounds[i][1] - bounds[i][0] for i in again)
    first = min(damaged)
    warnings.warn(
        StoreWarning(
            f"{store.path}: recomputing {points} points of {len(again)} damaged chunks "
            f"(first: {store.describe(first)}: {damaged[first]})"
        ),
        stacklevel=3,
    )


def run_sweep_file(
    path: str | Path,
    out: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    resume: bool = False,
    force: bool = False,
    progress: Callable[[Sweep], Callable[[int, int], None] | None] | None = None,
    retries: int = 0,
    lock_timeout: float = LOCK_TIMEOUT_S,
    cluster: str | None = None,
) -> tuple[Any, int]:
    """Return the results of the sweep file ``path`` run into the zarr store ``out``.

    The command line's run (``clearjoint sweep``): on the running Dask ``scheduler``,
    probed before the sweep file is read so an unreachable one is said first, or on a
    LocalCluster of ``workers`` started after it is read so a bad file is said before
    a cluster starts. See :func:`run_sweep` for ``resume`` and ``force``.

    Parameters
    ----------
    path : path
        Sweep file (TOML).
    out : path
        Zarr store to write, ending in ``.zarr``.
    scheduler : str, optional
        Address of a running scheduler, e.g. ``tcp://host:8786``.
    workers : int, optional
        Worker processes of the local cluster (default: one per core); not with
        ``scheduler``.
    resume, force : bool
        As for :func:`run_sweep`.
    retries, lock_timeout
        As for :func:`run_sweep`.
    cluster : {"slurm", "pbs", "sge"}, optional
        Start the workers as batch jobs (``workers`` of them, default 1) through
        dask-jobqueue (:func:`clearjoint.parallel.jobqueue_client`); not with ``scheduler``.
    progress : callable, optional
        Called with the loaded Sweep; returns the ``progress(done, total)`` callback
        of :func:`run_sweep` (or None).

    Returns
    -------
    results : xarray.Dataset
        As :func:`run_sweep` returns them.
    kept : int
        Points found already done in the store (with ``resume``).
    """
    if Path(out).suffix != ".zarr":
        raise ParameterError(f"--out must end in .zarr, got {str(out)!r}")
    if scheduler and workers is not None:
        raise ParameterError("--workers sizes a local cluster; leave it out with --scheduler")
    if scheduler and cluster:
        raise ParameterError("--cluster starts its own scheduler; leave out --scheduler")
    if Path(out).exists() and not (resume or force):
        raise OutputExistsError(
            f"will not overwrite {out}; pass --resume to finish it, --force to start "
            "again, or choose another --out"
        )
    already: list[int] = []  # points found in the store on resume

    with contextlib.ExitStack() as stack:
        if scheduler:  # an unreachable scheduler is said first, within seconds
            client = stack.enter_context(dask_client(scheduler))
        sweep = Sweep.from_toml(path)
        # a store in use is said before a cluster starts; the store is made once one has
        # started (a cluster that cannot start leaves no empty store behind)
        lock = stack.enter_context(StoreLock(out, timeout=lock_timeout))
        if cluster:
            client = stack.enter_context(jobqueue_client(cluster, jobs=workers))
        elif not scheduler:  # a bad sweep file is said before a cluster starts
            client = stack.enter_context(dask_client(workers=workers))
        store = _open_or_create(sweep, Path(out), resume=resume, force=force)
        report = progress(sweep) if progress is not None else None

        def on_progress(done: int, total: int) -> None:
            if not already:
                already.append(done)
            if report is not None:
                report(done, total)

        results = _run(sweep, store, lock, client, None, on_progress, retries)
    return results, already[0] if already else 0


def _dataset(
    grid: Grid, flat: Mapping[str, tuple[NDArray[Any], dict[str, Any]]], attrs: Mapping[str, Any]
) -> Any:
    """The results as an xarray.Dataset: each variable over the grid, its coordinates, and
    the counts of failed and missing points (as the store holds them)."""
    import xarray as xr

    variables = {
        name: (grid.dims, values.reshape(grid.shape), var_attrs)
        for name, (values, var_attrs) in flat.items()
    }
    failed, missing = status_counts(flat["status"][0])
    return xr.Dataset(
        variables,
        coords={name: (dims, values, dict(a)) for name, (dims, values, a) in grid.coords.items()},
        attrs={**attrs, "points_failed": failed, "points_missing": missing},
    )


def _read_store(store: ResultStore) -> Any:
    """The store's Dataset as ``xarray.open_zarr`` reads it, once the store is checked.

    ``status`` as fixed-width strings (zarr gives numpy's StringDType) and the counts of
    failed and missing points from ``status`` (the attributes hold them as of the end of
    the last run).
    """
    import xarray as xr

    store.read()  # a StoreError naming the first damaged chunk or coordinate
    with xr.open_zarr(store.path) as opened:
        data = opened.load()
    status = np.array(data["status"].values.tolist(), dtype=str)
    data["status"] = (data["status"].dims, status, data["status"].attrs)
    failed, missing = status_counts(status)
    data.attrs.update(points_failed=failed, points_missing=missing)
    return data


def open_sweep(path: str | Path) -> Any:
    """Return the results in a sweep's zarr store as an xarray.Dataset (as :func:`run_sweep`).

    The store is checked first (a damaged chunk is one StoreError line), then read as
    ``xarray.open_zarr(path)`` reads it. Points of chunks not yet computed are NaN with
    an empty ``status`` (``points_missing`` in the attributes counts them).
    """
    return _read_store(ResultStore.open(path))
