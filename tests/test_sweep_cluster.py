"""Tests of a sweep on a real LocalCluster (issue 27): a killed worker, Ctrl-C, the dashboard.

Each task here writes its point's index to a log of its worker process, so how often a
point was computed is counted outside the code under test.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Mapping
from pathlib import Path

import cloudpickle
import numpy as np
import pytest

from clearjoint.parallel import ResultStore, dask_client
from clearjoint.sweep import SERIAL, Axis, Sweep, Task, run_sweep
from test_sweep_store import STUDY

cloudpickle.register_pickle_by_value(sys.modules[__name__])  # workers need not import tests/


def _logged(base: object, values: Mapping[str, float], seed: np.random.SeedSequence) -> dict:
    """Wait 40 ms, write this point's index to this process's log, return a seeded draw."""
    time.sleep(0.04)
    with open(Path(str(base)) / f"{os.getpid()}.log", "a", encoding="utf-8") as log:
        log.write(f"{int(values['task.index'])}\n")
    return {"value": float(np.random.default_rng(seed).normal())}


LOGGED = Task(
    name="logged",
    base="none",
    parameters={},
    options={},
    outputs={"value": ""},
    evaluate=_logged,
    description="log each evaluation",
)


def _sweep(logs: Path, points: int) -> Sweep:
    return Sweep(
        task=LOGGED,
        base=str(logs),
        fixed=(),
        axes=(Axis("task.index", tuple(float(i) for i in range(points)), ""),),
        draws=(),
        samples=0,
        seed=5,
        outputs=("value",),
        chunk_size=1,
        source="test",
    )


def _computed(logs: Path) -> Counter[int]:
    return Counter(int(line) for log in logs.glob("*.log") for line in log.read_text().split())


def test_a_killed_worker_loses_nothing_that_was_stored(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    logs.mkdir()
    sweep = _sweep(logs, 100)
    out = tmp_path / "r.zarr"
    stored_at_kill: set[int] = set()
    with dask_client(workers=2) as client:
        client.wait_for_workers(2)
        pids = client.run(os.getpid)
        victim = next(iter(pids.values()))

        def kill_once(done: int, total: int) -> None:
            if done and not stored_at_kill and done < total:
                stored_at_kill.update(ResultStore.open(out).done_chunks())
                os.kill(victim, signal.SIGKILL)

        results = run_sweep(sweep, client=client, out=out, progress=kill_once, retries=1)
    assert stored_at_kill, "the worker was never killed: the sweep ended in its first write"
    assert len(stored_at_kill) < sweep.n_points
    counts = _computed(logs)
    assert sorted(counts) == list(range(sweep.n_points))  # every point computed
    again = {i for i in stored_at_kill if counts[i] > 1}
    assert not again, f"points stored before the kill computed again: {sorted(again)}"
    # the same numbers as one process computes them
    serial_logs = tmp_path / "serial"
    serial_logs.mkdir()
    reference = run_sweep(_sweep(serial_logs, sweep.n_points), client=SERIAL)
    np.testing.assert_array_equal(results.value.values, reference.value.values)
    assert list(results.status.values) == ["ok"] * sweep.n_points


def test_a_local_dashboard_listens_on_this_machine_only() -> None:
    with dask_client(workers=1) as client:
        link = client.dashboard_link
        assert "127.0.0.1" in link
        info = client.scheduler_info()
        assert info["address"].startswith("tcp://127.0.0.1:")
        assert all(w.startswith("tcp://127.0.0.1:") for w in info["workers"])


def test_a_subclass_of_the_dask_client_is_taken_as_a_client(tmp_path: Path) -> None:
    from distributed import Client, LocalCluster

    class MyClient(Client):  # as site packages and dask-jobqueue users write them
        pass

    logs = tmp_path / "logs"
    logs.mkdir()
    with (
        LocalCluster(n_workers=1, processes=False, dashboard_address=":0") as cluster,
        MyClient(cluster) as client,
    ):
        results = run_sweep(_sweep(logs, 4), client=client)
    assert list(results.status.values) == ["ok"] * 4


SLOW_SWEEP = """
base = "study.toml"
chunk_size = 1
[task]
name = "steady_state"
outputs = ["amplitude_m"]
samples_per_period = 64
[axes.excitation]
force_amplitude = {{ start = "200N", stop = "2kN", num = {num} }}
"""


def test_ctrl_c_on_a_local_cluster_is_one_line_and_exit_130(tmp_path: Path) -> None:
    (tmp_path / "study.toml").write_text(STUDY, encoding="utf-8")
    path = tmp_path / "sweep.toml"
    path.write_text(SLOW_SWEEP.format(num=4000), encoding="utf-8")
    out = tmp_path / "r.zarr"
    src = str(Path(__file__).resolve().parents[1] / "src")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}
    command = [sys.executable, "-m", "clearjoint", "sweep", str(path), "--out", str(out)]
    run = subprocess.Popen(
        [*command, "--workers", "1", "--progress-every", "0.2s"],
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,  # its own process group, as a terminal's foreground job
    )
    assert run.stderr is not None
    line = run.stderr.readline()
    while line.startswith("clearjoint sweep: 0 of"):  # before the first chunks are stored
        line = run.stderr.readline()
    assert "points stored" in line, line
    os.killpg(run.pid, signal.SIGINT)  # Ctrl-C: the whole group, workers too
    rest = run.stderr.read()
    run.stderr.close()
    assert run.wait(timeout=60) == 130
    lines = [line for line in rest.splitlines() if "points stored" not in line]
    assert len(lines) == 1, rest
    assert "interrupted" in lines[0]
    assert "--resume" in lines[0]
    assert ResultStore.open(out).done_chunks()  # what was finished is kept
    assert not Path(f"{out}.lock").exists()


def test_a_batch_cluster_without_its_configuration_is_one_line_and_no_store(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import dask

    from clearjoint.cli import main

    (tmp_path / "study.toml").write_text(STUDY, encoding="utf-8")
    path = tmp_path / "sweep.toml"
    path.write_text(SLOW_SWEEP.format(num=4), encoding="utf-8")
    out = tmp_path / "r.zarr"
    command = ["sweep", str(path), "--out", str(out), "--cluster", "slurm"]
    with dask.config.set({"jobqueue.slurm.cores": None, "jobqueue.slurm.memory": None}):
        assert main(command) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "jobqueue.yaml" in err
    assert not out.exists()
    assert not Path(f"{out}.lock").exists()
    monkeypatch.setitem(sys.modules, "dask_jobqueue", None)  # as if not installed
    assert main(command) == 2
    assert "pip install 'clearjoint[cluster]'" in capsys.readouterr().err
    assert main([*command, "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert "leave out --scheduler" in capsys.readouterr().err
