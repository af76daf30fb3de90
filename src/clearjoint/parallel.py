"""Chunks of pure tasks on an executor or a Dask client, and their results in a zarr store.

No physics here: this module runs a pure function over a list of frozen arguments
wherever the caller says (in this process, on a ``concurrent.futures`` executor,
or on a ``dask.distributed`` client) and hands each result back as it finishes.
The virtual rig, the dissipation agreement map and the sweeps all run on it.

Reproducibility does not depend on where a task runs: a point's random numbers
come from :func:`point_seed`, ``SeedSequence(seed).spawn(n)[index]`` made from the
point's index alone, and every task is a pure function of its frozen argument.

:class:`ResultStore` (clearjoint.store, re-exported here) keeps a sweep's results on
disk, checked chunk by chunk, so a run stopped at any moment resumes by computing only
the chunks not done or damaged.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import socket
import sys
import threading
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, TypeVar, cast

import numpy as np

from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.store import ResultStore as ResultStore  # re-exported: their old home
from clearjoint.store import StoreError as StoreError
from clearjoint.store import Variable as Variable

if TYPE_CHECKING:
    from distributed import Client

__all__ = [
    "CONNECT_TIMEOUT_S",
    "DASK_WINDOW",
    "DEFAULT_SCHEDULER_PORT",
    "JOB_QUEUES",
    "MAX_GROUP",
    "PROBE_TIMEOUT_S",
    "TASKS_PER_THREAD",
    "ChunkFailedError",
    "Finished",
    "Runner",
    "SchedulerError",
    "auto_group",
    "chunk_bounds",
    "dask_client",
    "is_dask_client",
    "jobqueue_client",
    "point_seed",
    "probe_scheduler",
    "process_pool",
    "record_warnings",
    "run_batches",
    "run_ordered",
    "run_unordered",
    "usable_cores",
]

A = TypeVar("A")
R = TypeVar("R")

#: What runs the tasks: None (this process), an executor, or a dask.distributed Client.
Runner = Any

#: Seconds to wait for a scheduler before giving up (the issue asks for an answer within 10 s).
CONNECT_TIMEOUT_S = 4

#: Seconds a plain TCP connection to a scheduler may take before it is called unreachable.
PROBE_TIMEOUT_S = 3.0

#: Dask's default scheduler port, taken when an address names none.
DEFAULT_SCHEDULER_PORT = 8786


class SchedulerError(ClearjointError, ConnectionError):
    """The Dask scheduler cannot be reached; the message names the address."""


class ChunkFailedError(ClearjointError, RuntimeError):
    """Some chunks did not finish (a worker died, a bug); the others are saved."""


def point_seed(seed: int, index: int) -> np.random.SeedSequence:
    """Return the seed of point ``index``: ``SeedSequence(seed).spawn(n)[index]`` for any n.

    Built from the index alone, so it is the same whatever the chunking, the
    number of workers or the order they finish in.
    """
    return np.random.SeedSequence(seed, spawn_key=(index,))


def chunk_bounds(n_points: int, chunk_size: int) -> list[tuple[int, int]]:
    """Return the (start, stop) of each chunk of ``chunk_size`` points (the last may be short)."""
    if chunk_size < 1:
        raise ParameterError(f"chunk_size must be >= 1, got {chunk_size}")
    return [(a, min(a + chunk_size, n_points)) for a in range(0, n_points, chunk_size)]


#: Each thread's list of the warnings it records (see :func:`record_warnings`), if any.
_RECORDING = threading.local()
_RECORDING_LOCK = threading.Lock()
_recorders = 0  # threads inside record_warnings, in this process
_shown_before: Any = None  # warnings.showwarning as it was when the first one entered
_filtered: list[Any] = []  # the filter lists _ALWAYS was put into (removed from each)
_ALWAYS = ("always", None, Warning, None, 0)


def _show_or_record(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """warnings.showwarning while a thread records: its own warnings to its own list."""
    record = getattr(_RECORDING, "record", None)
    if record is None:
        _shown_before(message, category, filename, lineno, file, line)
        return
    record.append(warnings.WarningMessage(message, category, filename, lineno, file, line))


@contextlib.contextmanager
def record_warnings() -> Iterator[list[warnings.WarningMessage]]:
    """Record every warning this thread raises meanwhile, and only this thread's.

    ``warnings.catch_warnings(record=True)`` swaps the process's filters and its
    ``showwarning``: in a Dask worker with several threads, one point's warnings then
    land in another point's status or in none (measured: 249 and 280 of 400 one-point
    chunks wrong on 16 threads, two runs). Here ``showwarning`` sends each warning to
    the list of the thread that raised it; while any thread records, an "always" filter
    stands first, so that a warning met again is recorded again (other threads' repeats
    are then shown again too), and both are put back when the last recording thread
    leaves.
    """
    global _recorders, _shown_before
    with _RECORDING_LOCK:
        if _recorders == 0:
            # another thread's catch_warnings, left after the last recording thread,
            # may have put _show_or_record back: never call it from itself
            if warnings.showwarning is not _show_or_record:
                _shown_before = warnings.showwarning
            warnings.showwarning = _show_or_record
            filters = cast(list[Any], warnings.filters)
            filters.insert(0, _ALWAYS)
            _filtered.append(filters)
            _filters_changed()
        _recorders += 1
    outer = getattr(_RECORDING, "record", None)
    record: list[warnings.WarningMessage] = []
    _RECORDING.record = record
    try:
        yield record
    finally:
        _RECORDING.record = outer
        with _RECORDING_LOCK:
            _recorders -= 1
            if _recorders == 0:
                if warnings.showwarning is _show_or_record:
                    warnings.showwarning = _shown_before
                # from the list it was put into too: another thread's catch_warnings
                # entered meanwhile puts that list back when it leaves
                for filters in (*_filtered, cast(list[Any], warnings.filters)):
                    filters[:] = [f for f in filters if f is not _ALWAYS]
                _filtered.clear()
                _filters_changed()


def _filters_changed() -> None:
    """Tell the warnings machinery its filter list changed (as simplefilter does)."""
    changed = getattr(warnings, "_filters_mutated", None)
    if changed is not None:
        changed()


@dataclass(frozen=True)
class Finished(Generic[R]):
    """One task's outcome: its index in the argument list, and its result or its error."""

    index: int
    result: R | None
    error: BaseException | None = None


def is_dask_client(runner: Any) -> bool:
    """True for a distributed.Client or any subclass of it (never imports distributed)."""
    distributed = sys.modules.get("distributed")
    return distributed is not None and isinstance(runner, distributed.Client)


#: Most tasks a Dask client keeps submitted at once (more are submitted as these end).
DASK_WINDOW = 20_000

#: With ``group=None``: Dask tasks per worker thread at least, when arguments are grouped
#: (enough for the threads to share the work evenly as tasks end at different times).
TASKS_PER_THREAD = 4

#: With ``group=None``: arguments per Dask task at most.
MAX_GROUP = 64


def auto_group(n_arguments: int, threads: int) -> int:
    """Arguments per Dask task: ``n // (TASKS_PER_THREAD * threads)``, within 1..MAX_GROUP.

    Dask costs a few milliseconds a task on the client and the scheduler (more on a
    loaded machine); grouping many short tasks divides that cost, while every thread
    still gets :data:`TASKS_PER_THREAD` tasks or more to balance the load.
    """
    return max(1, min(MAX_GROUP, n_arguments // (TASKS_PER_THREAD * max(1, threads))))


def _call_each(function: Callable[[A], R], part: Sequence[A]) -> list[tuple[bool, Any]]:
    """One Dask task of several arguments: ``(True, result)`` or ``(False, error)`` each,
    so that an argument that raises leaves the others' results whole."""
    out: list[tuple[bool, Any]] = []
    for argument in part:
        try:
            out.append((True, function(argument)))
        except Exception as exc:
            out.append((False, exc))
    return out


def run_batches(
    function: Callable[[A], R],
    arguments: Sequence[A],
    runner: Runner = None,
    *,
    retries: int = 0,
    window: int = DASK_WINDOW,
    every: float = 0.0,
    group: int | None = 1,
) -> Iterator[list[Finished[R]]]:
    """Yield the tasks' :class:`Finished` outcomes in batches, as they end.

    As :func:`run_unordered`, but on a Dask client every task that has ended since the
    last batch comes at once (the client fetches results in the background meanwhile),
    tasks are submitted ``window`` at a time in one message each (``client.map``), and
    the client lets go of a task's future once its batch is yielded: the scheduler then
    forgets its result, so a worker lost later has nothing of it to recompute.

    Parameters
    ----------
    function, arguments, runner
        As for :func:`run_unordered`.
    retries : int
        On a Dask client: times a task is run again after its worker is lost or it
        raises (``client.map(retries=...)``). Ignored elsewhere.
    window : int
        On a Dask client: most Dask tasks submitted and not yet yielded.
    every : float
        On a Dask client: seconds at least between two batches (the results that
        came meanwhile are fetched and held), so that a caller writing each batch
        writes few large ones; the last batch comes as soon as the last task ends.
    group : int or None
        On a Dask client: consecutive arguments run in one Dask task (default 1);
        None chooses by :func:`auto_group` from the client's worker threads. Each
        argument keeps its own outcome (one that raises fails alone), but a worker
        lost fails (or, with ``retries``, runs again) its whole task.
    """
    if retries < 0:
        raise ParameterError(f"retries must be >= 0 (--retries), got {retries}")
    if window < 1:
        raise ParameterError(f"window must be >= 1, got {window}")
    if group is not None and group < 1:
        raise ParameterError(f"group must be >= 1, got {group}")
    if not is_dask_client(runner):
        for outcome in run_unordered(function, arguments, runner):
            yield [outcome]
        return
    from functools import partial

    from distributed import as_completed as dask_as_completed

    if group is None:
        group = auto_group(len(arguments), sum(runner.nthreads().values()))
    starts = range(0, len(arguments), group)  # the first argument of each Dask task
    grouped = group > 1
    task = partial(_call_each, function) if grouped else function
    where: dict[str, int] = {}  # key -> Dask task, of the futures submitted and not yet yielded
    submitted = 0  # Dask tasks

    def submit(count: int) -> list[Any]:
        nonlocal submitted
        first = starts[submitted : submitted + count]
        if grouped:
            part: Sequence[Any] = [arguments[a : a + group] for a in first]
        else:
            part = arguments[first[0] : first[-1] + 1] if len(first) else []
        futures = runner.map(task, part, pure=False, retries=retries or None)
        for i, future in enumerate(futures):
            where[future.key] = submitted + i
        submitted += len(part)
        return list(futures)

    def outcomes(index: int, result: Any, error: BaseException | None) -> list[Finished[R]]:
        """The outcome of each argument of Dask task ``index``."""
        first = starts[index]
        if not grouped:
            return [Finished(first, result, error)]
        if error is not None:
            count = min(group, len(arguments) - first)
            return [Finished(first + i, None, error) for i in range(count)]
        return [
            Finished(first + i, value if ok else None, None if ok else value)
            for i, (ok, value) in enumerate(result)
        ]

    queue = dask_as_completed(submit(min(window, len(starts))))  # type: ignore[no-untyped-call]
    collected: list[Finished[R]] = []
    last = time.monotonic()
    try:
        while where:
            if not collected:
                batch = queue.next_batch(block=True)  # type: ignore[no-untyped-call]
            elif queue.has_ready():  # type: ignore[no-untyped-call]
                batch = queue.next_batch(block=False)  # type: ignore[no-untyped-call]
            else:
                time.sleep(0.005)
                batch = []
            finished = [f for f in batch if f.status == "finished"]
            keys = {f.key for f in finished}  # (a status read once: it may change meanwhile)
            failed = [f for f in batch if f.key not in keys]  # lost, cancelled or raised
            results = runner.gather(finished) if finished else []  # one message a batch
            for f, result in zip(finished, results, strict=True):
                collected += outcomes(where.pop(f.key), result, None)
            for f in failed:
                collected += outcomes(where.pop(f.key), None, _failure(f))
            # the futures: let go once their results are here (no name left holding one,
            # or the scheduler keeps its result and recomputes it if its worker dies)
            del batch, finished, failed, results
            if submitted < len(starts) and len(where) < window // 2 + 1:
                queue.update(submit(window - len(where)))  # type: ignore[no-untyped-call]
            if collected and (not where or time.monotonic() - last >= every):
                yield collected
                collected = []
                last = time.monotonic()
    finally:  # on Ctrl-C or an early stop: nothing left running for us
        with queue.lock:
            left = list(queue.futures)
        if left:
            with contextlib.suppress(Exception):
                runner.cancel(left)
        queue.clear()  # type: ignore[no-untyped-call]


def _failure(future: Any) -> BaseException:
    """Why a Dask future did not finish: its exception, or that it was cancelled."""
    try:
        error = future.exception(timeout=CONNECT_TIMEOUT_S)
    except BaseException as exc:  # CancelledError is a BaseException
        return exc
    return error if isinstance(error, BaseException) else RuntimeError(f"task {future.status}")


def run_unordered(
    function: Callable[[A], R], arguments: Sequence[A], runner: Runner = None
) -> Iterator[Finished[R]]:
    """Yield each task's :class:`Finished` outcome as it ends, in whatever order.

    Parameters
    ----------
    function : callable
        A pure function of one picklable argument (module level, so workers find it).
    arguments : sequence
        One argument per task.
    runner : None, concurrent.futures.Executor or distributed.Client
        Where to run: None runs the tasks here, one after the other, in order.

    Yields
    ------
    Finished
        A task's error is yielded, not raised, so that the caller can keep the
        results of every other task before deciding what to do.
    """
    if runner is None:
        for index, argument in enumerate(arguments):
            try:
                yield Finished(index, function(argument))
            except Exception as exc:
                yield Finished(index, None, exc)
        return
    if is_dask_client(runner):
        for batch in run_batches(function, arguments, runner):
            yield from batch
        return
    if not isinstance(runner, Executor):
        raise ParameterError(
            f"runner must be None, a concurrent.futures Executor or a dask.distributed Client, "
            f"got {type(runner).__name__}"
        )
    pool_futures: dict[Future[R], int] = {
        runner.submit(function, a): i for i, a in enumerate(arguments)
    }
    try:
        for future in as_completed(pool_futures):
            yield _outcome(pool_futures[future], future)
    finally:
        for future in pool_futures:
            future.cancel()


def _outcome(index: int, future: Any) -> Finished[Any]:
    try:
        return Finished(index, future.result())
    except Exception as exc:
        return Finished(index, None, exc)


def run_ordered(
    function: Callable[[A], R],
    arguments: Sequence[A],
    runner: Runner = None,
    *,
    progress: Callable[[int, int], None] | None = None,
) -> list[R]:
    """Return ``[function(a) for a in arguments]`` computed on ``runner``; raise the first error.

    ``progress(done, total)`` is called after each task.
    """
    results: dict[int, R] = {}
    for done in run_unordered(function, arguments, runner):
        if done.error is not None:
            raise done.error
        results[done.index] = done.result  # type: ignore[assignment]
        if progress:
            progress(len(results), len(arguments))
    return [results[i] for i in range(len(arguments))]


def usable_cores() -> int:
    """The cores this process may run on: its CPU affinity where the system reports one (a
    container, a batch job or ``taskset`` may leave it fewer than ``os.cpu_count()``, the
    machine's), else ``os.cpu_count()``. The default number of processes, workers and
    threads everywhere in clearjoint. A CPU quota without an affinity (cgroup ``cpu.max``)
    is not seen."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # not on this system (macOS, Windows)
        return os.cpu_count() or 1


@contextlib.contextmanager
def process_pool(jobs: int | None) -> Iterator[Executor | None]:
    """Yield a process pool of ``jobs`` workers (None: every core), or None for one job."""
    if jobs is not None and jobs < 1:
        raise ParameterError(f"jobs must be >= 1 (--jobs), got {jobs}")
    workers = jobs or usable_cores()
    if workers == 1:
        yield None
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_ignore_interrupts)
    try:
        yield pool
    except BaseException:  # Ctrl-C (or an error): stop now, not after the tasks running
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            process.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()


def _ignore_interrupts() -> None:
    """A pool worker's start: Ctrl-C is the parent's to handle (it stops the workers), so a
    worker prints no traceback of its own."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _unreachable(address: str, reason: str) -> SchedulerError:
    return SchedulerError(
        f"cannot reach the Dask scheduler at {address!r} ({reason}); start one with "
        f"`dask scheduler`, check the address, or leave out --scheduler to run locally"
    )


def probe_scheduler(address: str, timeout: float = PROBE_TIMEOUT_S) -> None:
    """Check that something accepts a TCP connection at a scheduler's address, quickly.

    A plain socket with a short timeout, before dask.distributed is imported (that
    import alone can take seconds on a loaded machine), so that an unreachable
    scheduler is one line within seconds. Addresses are ``tcp://host:port``,
    ``tls://host:port`` or ``host[:port]`` (port 8786 by default); other protocols
    (``inproc://``, ``ucx://``, ``ws://``) are left to Dask.

    Parameters
    ----------
    address : str
        The scheduler's address.
    timeout : float
        Seconds to wait for the connection.

    Raises
    ------
    SchedulerError
        The address cannot be read, its host not found, or nothing answers at it
        within ``timeout`` (refused, no route, or silence).
    """
    from urllib.parse import urlsplit

    text = address.strip()
    scheme = text.split("://", 1)[0].lower() if "://" in text else "tcp"
    if scheme not in ("tcp", "tls"):
        return
    try:
        parts = urlsplit(text if "://" in text else f"tcp://{text}")
        host, port = parts.hostname, parts.port or DEFAULT_SCHEDULER_PORT
    except ValueError as exc:
        raise _unreachable(address, f"not an address: {exc}") from None
    if not host:
        raise _unreachable(address, "no host in it; e.g. tcp://host:8786")
    try:
        with socket.create_connection((host, port), timeout=timeout):
            pass
    except TimeoutError:
        raise _unreachable(address, f"no answer within {timeout:g} s") from None
    except OSError as exc:
        raise _unreachable(address, exc.strerror or type(exc).__name__) from None


@contextlib.contextmanager
def dask_client(
    address: str | None = None,
    *,
    workers: int | None = None,
    processes: bool = True,
    threads: int = 1,
) -> Iterator[Client]:
    """Yield a Dask client: to the scheduler at ``address``, or to a new LocalCluster.

    Parameters
    ----------
    address : str, optional
        A running scheduler, e.g. ``tcp://host:8786``. None starts a LocalCluster
        of ``workers`` single-threaded workers (default: one per core), closed on exit.
    workers : int, optional
        Workers of the LocalCluster (ignored with ``address``).
    processes : bool
        Workers as processes (default) or as threads of this process (for tests).
    threads : int
        Threads of each LocalCluster worker (default 1: tasks hold the GIL).

    The LocalCluster's dashboard listens on 127.0.0.1 only, on any free port
    (``client.dashboard_link``); reach it from another machine through an SSH tunnel.

    Raises
    ------
    SchedulerError
        Nothing accepts a connection at ``address`` within :data:`PROBE_TIMEOUT_S`
        seconds (tried with a plain socket before Dask is imported), or the scheduler
        did not answer within :data:`CONNECT_TIMEOUT_S` seconds.
    """
    if workers is not None and workers < 1:
        raise ParameterError(f"workers must be >= 1 (--workers), got {workers}")
    if address is not None:
        probe_scheduler(address)
    from distributed import Client, LocalCluster

    _drop_sync_cancel_noise()
    if address is not None:
        try:
            client = Client(address, timeout=f"{CONNECT_TIMEOUT_S}s")  # type: ignore[no-untyped-call]
        except (OSError, TimeoutError, ValueError) as exc:
            reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise _unreachable(address, reason) from None
        with client:
            yield client
        return
    n = workers or usable_cores()
    # the worker processes ignore Ctrl-C (a terminal sends it to the whole process group):
    # this process says it in one line and closes them, with no traceback of theirs
    with _interrupt_ignored_by_children():
        cluster = LocalCluster(  # type: ignore[no-untyped-call]
            n_workers=n,
            threads_per_worker=threads,
            processes=processes,
            **({"host": "127.0.0.1"} if processes else {}),  # this machine only (threads: inproc)
            dashboard_address="127.0.0.1:0",  # any free port: never a clash with a running one
            silence_logs=logging.ERROR,
        )
    with cluster, Client(cluster) as client:  # type: ignore[no-untyped-call]
        if processes:  # and so do the workers the nannies start again after a crash
            client.register_plugin(_ignore_interrupt_plugin())
        yield client


class _SyncCancelNoise(logging.Filter):
    """Drops tornado's report of distributed's ``sync`` cancel callback failing.

    When Ctrl-C reaches the client inside ``distributed.utils.sync`` before that function
    has its future, the cancel callback it leaves on the event loop raises a NameError
    (``cannot access free variable 'future'``, distributed 2026.8) and tornado logs it with
    its traceback, after the command's own one line; nothing is cancelled there that the
    command does not close itself. Seen about one run in ten of
    ``tests/test_sweep_cluster.py::test_ctrl_c_on_a_local_cluster_is_one_line_and_exit_130``
    on a loaded machine. Every other record passes.
    """

    def filter(self, record: logging.LogRecord) -> bool:
        return "sync.<locals>.cancel" not in record.getMessage()


def _drop_sync_cancel_noise() -> None:
    """Install :class:`_SyncCancelNoise` on tornado's application logger, once."""
    logger = logging.getLogger("tornado.application")
    if not any(isinstance(f, _SyncCancelNoise) for f in logger.filters):
        logger.addFilter(_SyncCancelNoise())


@contextlib.contextmanager
def _interrupt_ignored_by_children() -> Iterator[None]:
    """SIGINT ignored while processes start (they inherit it), then as it was."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _ignore_interrupt_plugin() -> Any:
    """A Dask worker plugin that makes its worker process ignore SIGINT."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class IgnoreInterrupt(WorkerPlugin):
        name = "clearjoint-ignore-interrupt"

        def setup(self, worker: Any) -> None:
            import signal
            import threading

            if threading.current_thread() is threading.main_thread():
                signal.signal(signal.SIGINT, signal.SIG_IGN)

    return IgnoreInterrupt()


#: The batch systems ``--cluster`` starts Dask workers on, and dask-jobqueue's class for each.
JOB_QUEUES = {"slurm": "SLURMCluster", "pbs": "PBSCluster", "sge": "SGECluster"}


@contextlib.contextmanager
def jobqueue_client(kind: str, *, jobs: int | None = None) -> Iterator[Client]:
    """Yield a Dask client to workers started as ``jobs`` batch jobs (dask-jobqueue).

    Each job's cores, memory, queue, account and walltime come from the Dask
    configuration (``~/.config/dask/jobqueue.yaml``, section ``jobqueue.<kind>``; see
    docs/sweep.md); this process is the scheduler and the client, so run it where
    the compute nodes can reach it (a login node, or a job of its own).

    Parameters
    ----------
    kind : {"slurm", "pbs", "sge"}
        The batch system.
    jobs : int, optional
        Jobs to submit (default 1); each starts the workers its configuration says.

    Raises
    ------
    ParameterError
        An unknown ``kind``, dask-jobqueue not installed, or its configuration lacks
        what a job needs (cores, memory): one line saying where to put it.
    """
    if kind not in JOB_QUEUES:
        raise ParameterError(f"--cluster must be one of {sorted(JOB_QUEUES)}, got {kind!r}")
    if jobs is not None and jobs < 1:
        raise ParameterError(f"jobs must be >= 1 (--workers with --cluster), got {jobs}")
    try:
        import dask_jobqueue
    except ImportError:
        raise ParameterError(
            f"--cluster {kind} needs dask-jobqueue: pip install 'clearjoint[cluster]'"
        ) from None
    import dask
    from distributed import Client

    missing = [
        k for k in ("cores", "memory") if dask.config.get(f"jobqueue.{kind}.{k}", None) is None
    ]
    if missing:  # said before a cluster object exists (its __init__ would half-make one)
        raise ParameterError(
            f"--cluster {kind}: dask-jobqueue needs {' and '.join(missing)} per job: set "
            f"them in ~/.config/dask/jobqueue.yaml under jobqueue.{kind} (see docs/sweep.md)"
        )
    cluster = getattr(dask_jobqueue, JOB_QUEUES[kind])()
    with cluster, Client(cluster) as client:  # type: ignore[no-untyped-call]
        cluster.scale(jobs=jobs or 1)
        yield client


@contextlib.contextmanager
def optional_client(
    scheduler: str | None = None, workers: int | None = None
) -> Iterator[Client | None]:
    """Yield a Dask client to ``scheduler``, or to a LocalCluster of ``workers``, or None.

    None (neither given) leaves the work to the caller's own process pool. Both given is
    refused: ``workers`` sizes a local cluster only. An unreachable scheduler is said
    within seconds (see :func:`dask_client`).
    """
    if scheduler and workers is not None:
        raise ParameterError("--workers sizes a local cluster; leave it out with --scheduler")
    if scheduler:
        with dask_client(scheduler) as client:
            yield client
    elif workers is not None:
        with dask_client(workers=workers) as client:
            yield client
    else:
        yield None
