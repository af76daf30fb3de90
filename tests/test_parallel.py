"""Tests of clearjoint.parallel: where tasks run changes nothing, and the store keeps its chunks."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from clearjoint.errors import OutputExistsError, ParameterError
from clearjoint.parallel import (
    ResultStore,
    SchedulerError,
    StoreError,
    Variable,
    chunk_bounds,
    dask_client,
    point_seed,
    record_warnings,
    run_ordered,
    run_unordered,
)
from helpers import with_losses


def _noisy_chunk(bounds: tuple[int, int]) -> list[float]:
    """A pure task: one normal draw per point from that point's own seed."""
    start, stop = bounds
    return [float(np.random.default_rng(point_seed(42, i)).normal()) for i in range(start, stop)]


def _fails_on_two(x: int) -> int:
    if x == 2:
        raise ArithmeticError("no convergence at 2")
    return x * x


def test_point_seed_is_numpys_spawn_whatever_the_number_of_points() -> None:
    for n in (5, 17, 1000):
        children = np.random.SeedSequence(7).spawn(n)
        for i in (0, 3, 4):
            a = np.random.default_rng(children[i]).integers(0, 2**62, 4)
            b = np.random.default_rng(point_seed(7, i)).integers(0, 2**62, 4)
            np.testing.assert_array_equal(a, b)


def test_chunk_bounds_cover_every_point_once() -> None:
    bounds = chunk_bounds(10, 4)
    assert bounds == [(0, 4), (4, 8), (8, 10)]
    with pytest.raises(ParameterError, match="chunk_size"):
        chunk_bounds(10, 0)


def test_results_are_bit_for_bit_the_same_wherever_and_in_whatever_order() -> None:
    bounds = chunk_bounds(23, 4)
    serial = np.concatenate(run_ordered(_noisy_chunk, bounds))
    # chunked differently and run backwards: the same numbers for the same points
    other = chunk_bounds(23, 5)[::-1]
    backwards = np.concatenate(run_ordered(_noisy_chunk, other)[::-1])
    np.testing.assert_array_equal(serial, backwards)
    with ThreadPoolExecutor(2) as pool:
        np.testing.assert_array_equal(
            serial, np.concatenate(run_ordered(_noisy_chunk, bounds, pool))
        )
    for workers in (1, 2):
        with dask_client(workers=workers, processes=False) as client:
            on_dask = np.concatenate(run_ordered(_noisy_chunk, bounds, client))
        np.testing.assert_array_equal(serial, on_dask)


def test_a_failing_task_is_reported_and_the_others_still_finish() -> None:
    outcomes = {done.index: done for done in run_unordered(_fails_on_two, [0, 1, 2, 3])}
    assert {i: o.result for i, o in outcomes.items() if o.error is None} == {0: 0, 1: 1, 3: 9}
    assert isinstance(outcomes[2].error, ArithmeticError)
    with pytest.raises(ArithmeticError, match="at 2"):
        run_ordered(_fails_on_two, [0, 1, 2, 3])
    with pytest.raises(ParameterError, match="runner must be"):
        list(run_unordered(_fails_on_two, [0], runner="pool"))


def test_an_unreachable_scheduler_is_one_clear_error_within_ten_seconds() -> None:
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    start = time.perf_counter()
    with (
        pytest.raises(SchedulerError, match=rf"tcp://127.0.0.1:{port}.*--scheduler") as info,
        dask_client(f"tcp://127.0.0.1:{port}"),
    ):
        pass
    assert time.perf_counter() - start < 10.0
    assert "\n" not in str(info.value)


def _free_port() -> int:
    with socket.socket() as s:  # a port nobody listens on once this socket is closed
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


#: An address nothing listens on, and one that does not route (RFC 5737 TEST-NET-1: a
#: connection there is refused by the network or never answered, never accepted).
UNREACHABLE = {"free port": "tcp://127.0.0.1:{port}", "no route": "tcp://192.0.2.1:8786"}


@pytest.mark.parametrize("kind", sorted(UNREACHABLE))
def test_the_command_line_says_an_unreachable_scheduler_in_one_line_within_ten_seconds(
    kind: str, tmp_path: Path
) -> None:
    address = UNREACHABLE[kind].format(port=_free_port())
    sweep = Path(__file__).parents[1] / "examples" / "sweep.toml"
    command = [sys.executable, "-m", "clearjoint", "sweep", str(sweep)]
    command += ["--out", str(tmp_path / "x.zarr"), "--scheduler", address]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, timeout=60, check=False)
    elapsed = time.perf_counter() - start
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert address in lines[0]
    assert "--scheduler" in lines[0]
    assert elapsed < 10.0, f"{elapsed:.1f} s end to end"
    assert not (tmp_path / "x.zarr").exists()


def test_an_unreachable_scheduler_is_found_before_dask_is_imported() -> None:
    # importing dask.distributed alone took 4.8 s on the loaded machine: the probe is a socket
    code = (
        "import sys\n"
        "from clearjoint.parallel import SchedulerError, dask_client\n"
        "try:\n"
        f"    with dask_client('tcp://127.0.0.1:{_free_port()}'):\n"
        "        pass\n"
        "except SchedulerError as exc:\n"
        "    print('refused', 'distributed' in sys.modules)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.stdout.strip() == "refused False", done.stdout + done.stderr


def test_a_scheduler_address_that_cannot_be_read_is_one_clear_error() -> None:
    from clearjoint.parallel import probe_scheduler

    with pytest.raises(SchedulerError, match="not an address"):
        probe_scheduler("tcp://127.0.0.1:99999999")
    with pytest.raises(SchedulerError, match="no host"):
        probe_scheduler("tcp://:8786")
    probe_scheduler("inproc://here")  # other protocols are left to Dask


def test_a_scheduler_that_never_answers_is_given_up_after_the_probe_timeout(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # a silent network (a firewall dropping packets) is a connect that times out
    from clearjoint import parallel

    def silent(address: tuple[str, int], timeout: float) -> None:
        assert address == ("10.0.0.9", 8786)
        assert timeout == parallel.PROBE_TIMEOUT_S
        raise TimeoutError("timed out")

    monkeypatch.setattr(parallel.socket, "create_connection", silent)
    with pytest.raises(SchedulerError, match=r"'10.0.0.9' \(no answer within 3 s\)"):
        parallel.probe_scheduler("10.0.0.9")


def _store(path: Path, fingerprint: str = "abc", force: bool = False) -> ResultStore:
    return ResultStore.create(
        path,
        fingerprint=fingerprint,
        n_points=10,
        chunk_size=4,
        variables=[Variable("x", "f8", {"units": "m"}), Variable("status", "str", {})],
        attrs={"title": "test"},
        force=force,
    )


def test_the_store_keeps_finished_chunks_and_refuses_what_it_should(tmp_path: Path) -> None:
    path = tmp_path / "r.zarr"
    store = _store(path)
    assert store.done_chunks() == set()
    store.write(2, {"x": np.array([8.0, 9.0]), "status": np.array(["ok", "bad"])})
    store.write(0, {"x": np.arange(4.0), "status": np.array(["ok"] * 4)})
    again = ResultStore.open(path, fingerprint="abc")
    assert again.done_chunks() == {0, 2}
    assert again.n_points == 10
    values = again.read()
    np.testing.assert_array_equal(values["x"][0][[0, 1, 2, 3, 8, 9]], [0, 1, 2, 3, 8, 9])
    assert np.isnan(values["x"][0][4:8]).all()  # not computed yet
    assert values["x"][1]["units"] == "m"
    assert list(values["status"][0][[0, 8, 9, 5]]) == ["ok", "ok", "bad", ""]
    assert again.attrs["title"] == "test"
    assert "2/3 chunks" in repr(again)
    with pytest.raises(OutputExistsError, match="resume=True"):
        _store(path)
    with pytest.raises(StoreError, match="different sweep file"):
        ResultStore.open(path, fingerprint="xyz")
    with pytest.raises(StoreError, match="no such result store"):
        ResultStore.open(tmp_path / "none.zarr")
    (tmp_path / "plain").mkdir()
    with pytest.raises(StoreError, match="not a clearjoint sweep store"):
        ResultStore.open(tmp_path / "plain")
    with pytest.raises(StoreError, match="not a clearjoint sweep store"):
        _store(tmp_path / "plain", force=True)  # force never deletes what is not a store
    assert (tmp_path / "plain").is_dir()
    (tmp_path / "file.zarr").write_text("mine", encoding="utf-8")
    with pytest.raises(StoreError, match="not a clearjoint sweep store"):
        _store(tmp_path / "file.zarr", force=True)
    assert (tmp_path / "file.zarr").read_text(encoding="utf-8") == "mine"
    fresh = _store(path, force=True)
    assert fresh.done_chunks() == set()


CAMPAIGN = """
seed = 7
periods = 12
[grid]
frequencies = ["40Hz"]
force_amplitudes = ["1200N"]
[[structures]]
name = "joint-1"
clearance = "0.106mm"
[[structures]]
name = "beam"
jointed = false
"""


def test_the_rig_gives_the_same_records_here_and_on_a_dask_client(tmp_path: Path) -> None:
    from clearjoint.records import read_record
    from clearjoint.rig import load_campaign, run_campaign

    (tmp_path / "c.toml").write_text(CAMPAIGN, encoding="utf-8")
    campaign = load_campaign(tmp_path / "c.toml")
    here = run_campaign(campaign, tmp_path / "here", jobs=1)
    with dask_client(workers=2, processes=False) as client:
        there = run_campaign(campaign, tmp_path / "there", executor=client)
    assert here.read_text() == there.read_text()
    for name in ("joint-1_40Hz_1200N.nc", "beam_40Hz_1200N.nc"):
        a, b = read_record(here.parent / name), read_record(there.parent / name)
        np.testing.assert_array_equal(a.displacement, b.displacement)
        np.testing.assert_array_equal(a.acceleration, b.acceleration)


def test_the_agreement_map_is_the_same_row_by_row_on_an_executor() -> None:
    from clearjoint.dissipation import agreement_map, compare
    from clearjoint.joint import Joint

    joint = Joint(mass=2.0, clearance=1e-4, compression_stiffness=8e7)
    omegas, forces = [2 * np.pi * 300, 2 * np.pi * 500], [300.0, 800.0]
    kwargs = {"restitution": 0.8, "damping_ratio": 0.02}
    serial = agreement_map(joint, omegas, forces, **with_losses(kwargs))
    with ThreadPoolExecutor(2) as pool:
        pooled = agreement_map(joint, omegas, forces, executor=pool, **with_losses(kwargs))
    np.testing.assert_array_equal(serial.penetration, pooled.penetration)
    for key, gap in serial.gap.items():
        np.testing.assert_array_equal(gap, pooled.gap[key])
    # each row starts from rest at the lowest force: compare() there directly
    first = compare(
        joint, 300.0, omegas[1], samples_per_period=128, max_periods=2000, **with_losses(kwargs)
    )
    assert serial.penetration[1, 0] == first.penetration


def _warns_on_odd(i: int) -> tuple[int, list[str]]:
    """Warn (twice, from one line) on odd i, sleeping so that threads interleave."""
    with record_warnings() as caught:
        time.sleep(0.002)
        for _ in range(2 if i % 2 else 0):
            warnings.warn(f"odd point {i}", RuntimeWarning, stacklevel=1)
            time.sleep(0.001)
    return i, [str(w.message) for w in caught]


def test_each_thread_records_its_own_warnings_and_every_repeat() -> None:
    # catch_warnings(record=True), as the sweep used, gave 249 and 280 of 400 such points
    # (two runs) a wrong or empty list on 16 threads: the filters and showwarning are the
    # process's
    shown_before, filters_before = warnings.showwarning, list(warnings.filters)
    with ThreadPoolExecutor(16) as pool:
        results = list(pool.map(_warns_on_odd, range(400)))
    for i, caught in results:
        assert caught == ([f"odd point {i}"] * 2 if i % 2 else [])
    # everything put back once no thread records
    assert warnings.showwarning is shown_before
    assert warnings.filters == filters_before


def test_warnings_outside_a_recording_thread_are_shown_as_before() -> None:
    with warnings.catch_warnings(record=True) as outside:
        warnings.simplefilter("always")
        with record_warnings() as inside:
            warnings.warn("recorded", UserWarning, stacklevel=1)
        warnings.warn("shown", UserWarning, stacklevel=1)
    assert [str(w.message) for w in inside] == ["recorded"]
    assert [str(w.message) for w in outside] == ["shown"]


def test_a_catch_warnings_in_another_thread_leaves_no_always_filter_and_no_loop() -> None:
    # another thread (the store's writer, a library) enters catch_warnings while a point
    # records and leaves it after: its exit puts back the filter list and showwarning it
    # saved, both with record_warnings' changes in. These must not stay (an "always"
    # filter for the rest of the process, over the user's "error" or "default"), nor
    # make the next recording's showwarning call itself (RecursionError on any warning
    # outside a recording thread)
    shown_before, filters_before = warnings.showwarning, list(warnings.filters)
    entered, recorded, left = threading.Event(), threading.Event(), threading.Event()

    def other() -> None:
        recorded.wait()
        with warnings.catch_warnings():
            entered.set()
            left.wait()

    thread = threading.Thread(target=other)
    thread.start()
    with record_warnings():
        recorded.set()
        entered.wait()
    left.set()
    thread.join()
    assert warnings.filters == filters_before
    left_shown = warnings.showwarning  # as that other thread's exit left it
    with warnings.catch_warnings(record=True) as outside:
        warnings.showwarning = left_shown
        with record_warnings() as caught:  # a second run
            warnings.warn("recorded", UserWarning, stacklevel=1)
            result: list[BaseException] = []
            thread = threading.Thread(target=_warn_into, args=(result,))
            thread.start()
            thread.join()
    assert not result, result
    assert [str(w.message) for w in caught] == ["recorded"]
    assert [str(w.message) for w in outside] == ["shown"]
    assert warnings.filters == filters_before
    warnings.showwarning = shown_before


def _warn_into(errors: list[BaseException]) -> None:
    try:
        warnings.warn("shown", UserWarning, stacklevel=1)
    except BaseException as exc:  # RecursionError when showwarning calls itself
        errors.append(exc)


def test_only_distributeds_sync_cancel_noise_is_dropped_from_tornados_log() -> None:
    """After a Ctrl-C inside distributed's ``sync``, tornado logs that function's cancel
    callback failing (a NameError of distributed's); that record is dropped, no other."""
    import logging

    from clearjoint import parallel

    parallel._drop_sync_cancel_noise()
    parallel._drop_sync_cancel_noise()  # once only
    logger = logging.getLogger("tornado.application")
    filters = [f for f in logger.filters if isinstance(f, parallel._SyncCancelNoise)]
    assert len(filters) == 1

    def record(message: str) -> logging.LogRecord:
        return logging.LogRecord("tornado.application", logging.ERROR, "x", 1, message, (), None)

    noise = "Exception in callback functools.partial(<function sync.<locals>.cancel at 0x7f>)"
    assert not filters[0].filter(record(noise))
    assert filters[0].filter(record("Exception in callback functools.partial(<function f>)"))


def test_the_default_counts_the_cores_this_process_may_run_on(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A process restricted to one core (a container's cpuset, taskset, a batch job) gets
    one job by default, not one per core of the machine; where the system has no affinity
    call, the machine's count."""
    import os

    from clearjoint import parallel

    monkeypatch.setattr(os, "cpu_count", lambda: 64)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {3}, raising=False)
    assert parallel.usable_cores() == 1
    with parallel.process_pool(None) as pool:
        assert pool is None  # one job: run in this process
    monkeypatch.delattr(os, "sched_getaffinity", raising=False)
    assert parallel.usable_cores() == 64
