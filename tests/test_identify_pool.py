"""The forked workers behind identify_files(jobs=N): every task once, errors and deaths seen."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest

from clearjoint.identify import identify_files
from clearjoint.identify._pool import run_forked

SHIPPED = Path(__file__).resolve().parent / "data" / "brfd"
PARENT = os.getpid()


def _square_where(n: int) -> tuple[int, int]:
    time.sleep(0.002)  # long enough that every process takes some
    return n * n, os.getpid()


def test_every_task_runs_once_in_several_processes() -> None:
    tasks = list(range(60))
    seen: dict[int, tuple[int, int]] = {}

    def done(i: int, result: tuple[int, int]) -> None:
        assert i not in seen  # once only
        seen[i] = result

    order = sorted(tasks, key=lambda i: -i)
    run_forked(_square_where, tasks, order, 3, done)
    assert sorted(seen) == tasks
    assert all(seen[i][0] == i * i for i in tasks)
    pids = {pid for _, pid in seen.values()}
    assert os.getpid() in pids  # this process took some
    assert len(pids) > 1  # and so did a worker
    with pytest.raises(ChildProcessError):  # every worker has been waited for
        os.waitpid(-1, os.WNOHANG)


def test_more_processes_than_tasks_and_a_partial_order() -> None:
    seen: list[int] = []
    run_forked(_square_where, [0, 1, 2, 3], [3, 1], 8, lambda i, _r: seen.append(i))
    assert sorted(seen) == [1, 3]  # only the indices of the order


def _fails_in_a_worker(n: int) -> int:
    time.sleep(0.002)
    if os.getpid() != PARENT:
        raise ZeroDivisionError(f"task {n} in a worker")
    return n


def test_an_exception_in_a_worker_is_raised_here() -> None:
    with pytest.raises(ZeroDivisionError, match="in a worker"):
        run_forked(_fails_in_a_worker, list(range(20)), list(range(20)), 2, lambda i, r: None)


def _dies_in_a_worker(n: int) -> int:
    time.sleep(0.002)
    if os.getpid() != PARENT:
        os._exit(3)  # killed, as by the out-of-memory killer: sends nothing
    return n


def test_a_dead_workers_tasks_are_missing_not_wrong() -> None:
    seen: dict[int, int] = {}
    run_forked(_dies_in_a_worker, list(range(20)), list(range(20)), 2, seen.__setitem__)
    assert 0 < len(seen) < 20  # the worker took some and died with them
    assert all(seen[i] == i for i in seen)


@pytest.mark.skipif(len(list(SHIPPED.glob("*.json"))) < 2, reason="needs two shipped records")
def test_identify_files_runs_the_files_a_dead_worker_took(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from clearjoint.identify import core

    files = [str(p) for p in sorted(SHIPPED.glob("*.json"))]
    serial, _ = identify_files(files)
    real = core._identify_path

    def dying(task: tuple[str, bool, float]) -> object:
        if os.getpid() != PARENT:
            os._exit(3)
        return real(task)

    monkeypatch.setattr(core, "_identify_path", dying)
    parallel, _ = identify_files(files, jobs=2)
    assert [i.source for _, i in parallel] == [i.source for _, i in serial]
    for (_, a), (_, b) in zip(serial, parallel, strict=True):
        np.testing.assert_equal(a.row(), b.row())


def test_without_memfd_the_claims_live_in_a_temporary_file(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delattr(os, "memfd_create", raising=False)  # as on macOS
    seen: dict[int, tuple[int, int]] = {}
    run_forked(_square_where, list(range(30)), list(range(30)), 2, seen.__setitem__)
    assert sorted(seen) == list(range(30))
    assert all(seen[i][0] == i * i for i in seen)
