"""Forked workers over a list of tasks, each claimed by whichever process is free.

Not physics: the orchestration behind ``identify_files(..., jobs=N)`` (no MODEL.md
equation). This process and ``N - 1`` workers forked from it (warm: they inherit every
module already imported, frozen for their garbage collector, which then does not walk
them) take the tasks one at a time in a given order (largest first), so that a process
that drew quick tasks takes more of them; a worker sends its results back through a pipe
when the order is exhausted and leaves by ``os._exit`` (nothing to tear down). A worker
that dies sends nothing: the caller finds its tasks without a result and runs them itself.
An exception a task raises in a worker is raised here.
"""

from __future__ import annotations

import contextlib
import fcntl
import gc
import os
import pickle
import signal
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

_NEXT = 8  # bytes of the shared position in the order


class _Claims:
    """Positions in a shared order, handed out one at a time to this process and its forks.

    The next position is the first 8 bytes of an unlinked temporary file, read and advanced
    under a POSIX record lock (``fcntl.lockf``: held per process, so it excludes a forked
    child from its parent, and the kernel releases it if its holder dies).
    """

    def __init__(self, order: Sequence[int], fd: int) -> None:
        self.order = list(order)
        self.fd = fd
        os.pwrite(fd, bytes(_NEXT), 0)

    def next(self) -> int | None:
        """The next task index, or None when every one is taken."""
        fd = self.fd
        fcntl.lockf(fd, fcntl.LOCK_EX)
        try:
            k = int.from_bytes(os.pread(fd, _NEXT, 0), "little")
            os.pwrite(fd, (k + 1).to_bytes(_NEXT, "little"), 0)
        finally:
            fcntl.lockf(fd, fcntl.LOCK_UN)
        return self.order[k] if k < len(self.order) else None


def _work(
    function: Callable[[Any], Any], tasks: Sequence[Any], claims: _Claims, fd: int
) -> NoReturn:
    """A worker's life: claim, run, send ``(results, error)`` down ``fd``, leave."""
    status = 1
    try:
        results: list[tuple[int, Any]] = []
        error: BaseException | None = None
        try:
            while (i := claims.next()) is not None:
                results.append((i, function(tasks[i])))
        except BaseException as exc:  # sent to the parent, which raises it
            error = exc
        try:
            payload = pickle.dumps((results, error), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as exc:  # an exception that does not pickle: say what it was
            failure = RuntimeError(f"a worker failed: {error!r} ({exc})")
            payload = pickle.dumps(([], failure), protocol=pickle.HIGHEST_PROTOCOL)
        with open(fd, "wb") as pipe:
            pipe.write(payload)
        status = 0
    finally:
        os._exit(status)  # never back into the parent's code; no teardown


def run_forked(
    function: Callable[[Any], Any],
    tasks: Sequence[Any],
    order: Sequence[int],
    jobs: int,
    done: Callable[[int, Any], None],
) -> None:
    """Call ``function(tasks[i])`` for each ``i`` of ``order`` over ``jobs`` processes.

    Parameters
    ----------
    function : callable
        Of one task; its result must pickle.
    tasks : sequence
        The tasks, indexed by ``order``.
    order : sequence of int
        The indices of the tasks to run, in the order they are claimed (largest first
        balances the processes best).
    jobs : int
        Processes: this one and ``jobs - 1`` forked workers (fewer if there are fewer
        tasks).
    done : callable
        ``done(i, result)``, called in this process: at once for a task it ran itself,
        when a worker has finished for that worker's tasks. A task of a worker that died
        is never passed to ``done``.
    """
    if hasattr(os, "memfd_create"):  # Linux: a file in memory, no tempfile module to import
        fd = os.memfd_create("clearjoint-claims")
        try:
            _run(function, tasks, _Claims(order, fd), jobs, done)
        finally:
            os.close(fd)
        return
    import tempfile

    with tempfile.TemporaryFile() as shared:
        _run(function, tasks, _Claims(order, shared.fileno()), jobs, done)


def _run(
    function: Callable[[Any], Any],
    tasks: Sequence[Any],
    claims: _Claims,
    jobs: int,
    done: Callable[[int, Any], None],
) -> None:
    workers: list[tuple[int, int]] = []
    try:
        gc.freeze()  # the workers' collections then skip every object they inherit
        try:
            for _ in range(min(jobs, len(claims.order)) - 1):
                read, write = os.pipe()
                pid = os.fork()
                if pid == 0:
                    os.close(read)
                    _work(function, tasks, claims, write)
                os.close(write)
                workers.append((pid, read))
        finally:
            gc.unfreeze()  # here, everything as it was
        while (i := claims.next()) is not None:
            done(i, function(tasks[i]))
        while workers:
            pid, read = workers[0]
            with open(read, "rb", closefd=False) as pipe:
                payload = pipe.read()  # to the end: the worker has left
            os.close(read)
            os.waitpid(pid, 0)
            workers.pop(0)
            try:
                results, error = pickle.loads(payload)
            except Exception:  # nothing or a part: the worker died; its tasks are missing
                continue
            for i, result in results:
                done(i, result)
            if error is not None:
                raise error
    finally:
        for pid, read in workers:  # left early (an error here): stop the rest
            with contextlib.suppress(OSError):
                os.close(read)
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGTERM)
                os.waitpid(pid, 0)
