"""Sweep throughput serial and on a Dask LocalCluster, and a SIGKILL-midway restart.

Run on demand: ``python benchmarks/bench_sweep.py`` (about 4 minutes on 2 busy cores;
``--throughput-only`` skips the restart test).
Targets (issue 13): a LocalCluster of 2 workers at least 1.8x serial for tasks of
about 50 ms; a sweep killed midway and resumed equal, bit for bit, to one run whole.

1. Points per second for tasks of ~1 ms and ~50 ms of CPU (a spin on
   ``time.thread_time``, so each point costs the same CPU of its own thread
   whatever else the machine runs), serial in this process and on a LocalCluster of 1 and 2
   workers: the same sweeps, in the same run. Before any clock starts, every worker (and
   this process, for the serial runs) is warmed: it has imported the sweep machinery and
   numpy, unpickled the task and run a chunk of it, so no import or first-call cost is
   timed; the cluster's start-up is printed apart. Chunks hold 0.25-0.5 s of work
   (docs/sweep.md), at least 8 per worker, so the per-chunk overhead (a few ms of
   scheduling and one result) is about 1 % and the last chunk leaves a worker idle
   for at most one chunk. Each rate is the best of ``--repeats`` runs (default 2).
   On a machine shared with other jobs the 2-worker ratio is capped by the
   cores actually free: the load average is printed beside it, and so is a
   control, the same 50 ms points on a plain ProcessPoolExecutor of 2 processes.
2. ``clearjoint sweep`` on a 40-point steady-state sweep in its own process group,
   SIGKILLed (client, scheduler and workers at once) once some chunks are in the
   store, then ``--resume``d; every variable is compared with an uninterrupted run.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Mapping
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from clearjoint.parallel import ResultStore, dask_client
from clearjoint.sweep import SERIAL, Axis, Sweep, Task, run_sweep

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _spin(
    base: object, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    """A task of ``task.cost_s`` seconds of CPU that returns a seeded draw."""
    end = time.thread_time() + values["task.cost_s"]
    while time.thread_time() < end:
        pass
    return {"value": float(np.random.default_rng(seed).normal())}


def _spin_point(index: int) -> float:
    """One 50 ms point without Dask or the sweep machinery (the control)."""
    return _spin(None, {"task.cost_s": 0.050}, np.random.SeedSequence(1, spawn_key=(index,)))[
        "value"
    ]


SPIN = Task(
    name="spin",
    base="none",
    parameters={},
    options={},
    outputs={"value": ""},
    evaluate=_spin,
    description="burn CPU for task.cost_s seconds",
)


def spin_sweep(points: int, cost_s: float, chunk_size: int) -> Sweep:
    return Sweep(
        task=SPIN,
        base=None,
        fixed=(("task.cost_s", cost_s),),
        axes=(Axis("task.index", tuple(float(i) for i in range(points)), ""),),
        draws=(),
        samples=0,
        seed=1,
        outputs=("value",),
        chunk_size=chunk_size,
        source="bench",
    )


def _rate(sweep: Sweep, client: object, repeats: int) -> tuple[float, object]:
    """The best points-per-second of ``repeats`` runs, and the values of the last."""
    best = 0.0
    values: object = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = run_sweep(sweep, client=client)
        best = max(best, sweep.n_points / (time.perf_counter() - t0))
        values = result.value.values
    return best, values


def _warm() -> str:
    """Run on every worker before the clock: the imports and a first chunk of the task."""
    from clearjoint.sweep.run import _Chunk, _evaluate_chunk

    sweep = spin_sweep(2, 0.0, 2)
    chunk = _Chunk(SPIN, None, ("task.index",), np.zeros((2, 1)), 0, 1, ("value",), sweep.fixed)
    _evaluate_chunk(chunk)
    return "warm"


#: (seconds of CPU per point, points, points per chunk): chunks of 0.25-0.5 s of work,
#: 16-20 chunks, so each of 2 workers gets 8-10 of them.
CASES = [(0.001, 4000, 250), (0.050, 200, 10)]


def throughput(repeats: int, cases: list[tuple[float, int, int]] = CASES) -> None:
    sweeps = [spin_sweep(points, cost, chunk) for cost, points, chunk in cases]
    rates: dict[tuple[int, str], float] = {}
    values: dict[tuple[int, str], object] = {}
    _warm()
    run_sweep(spin_sweep(4, 0.0, 2), client=SERIAL)  # this process too: the serial runs
    for k, sweep in enumerate(sweeps):
        rates[k, "serial"], values[k, "serial"] = _rate(sweep, SERIAL, repeats)
    started = {}
    for workers in (1, 2):  # one cluster at a time: an idle one would take CPU too
        t0 = time.perf_counter()
        with dask_client(workers=workers) as client:
            client.wait_for_workers(workers)
            started[workers] = time.perf_counter() - t0
            warm = client.run(_warm)  # every worker, before any clock
            assert len(warm) == workers, warm
            run_sweep(spin_sweep(4 * workers, 0.0, 1), client=client)  # the path end to end
            for k, sweep in enumerate(sweeps):
                rates[k, str(workers)], values[k, str(workers)] = _rate(sweep, client, repeats)
    print(f"points per second (higher is better; best of {repeats}); tasks spin on CPU time")
    print(
        f"{'task':>8} {'chunk':>6} {'serial':>10} {'1 worker':>10} {'2 workers':>10} "
        f"{'1w/serial':>10} {'2w/serial':>10}"
    )
    for k, (cost, _, chunk) in enumerate(cases):
        for where in ("1", "2"):  # the same seeded numbers wherever they ran
            np.testing.assert_array_equal(values[k, where], values[k, "serial"])
        serial, one, two = rates[k, "serial"], rates[k, "1"], rates[k, "2"]
        print(
            f"{cost * 1e3:6.0f}ms {chunk:6d} {serial:10.1f} {one:10.1f} {two:10.1f} "
            f"{one / serial:9.2f}x {two / serial:9.2f}x"
        )
    print("target (issue 13): 2 workers >= 1.8x serial for the 50 ms tasks")
    print(f"cluster start-up: 1 worker {started[1]:.1f} s, 2 workers {started[2]:.1f} s")
    # the control: what two plain processes gain over one on this machine right now
    points = 60
    t0 = time.perf_counter()
    for i in range(points):
        _spin_point(i)
    serial = time.perf_counter() - t0
    with ProcessPoolExecutor(2) as pool:
        list(pool.map(_spin_point, range(4)))  # started and warm
        t0 = time.perf_counter()
        list(pool.map(_spin_point, range(points)))
        two = time.perf_counter() - t0
    print(
        f"control, 50 ms tasks without Dask: serial {points / serial:.1f}/s, "
        f"ProcessPoolExecutor(2) {points / two:.1f}/s, {serial / two:.2f}x"
    )
    print(f"load average while measuring: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    autogroup = Path("/proc/sys/kernel/sched_autogroup_enabled")
    if autogroup.exists() and autogroup.read_text().strip() == "1":
        print("kernel autogroup on: this session's processes share one session's CPU")


def _sleep(
    base: object, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    """A task that waits ``task.cost_s`` seconds (a simulated cluster's busy worker)."""
    time.sleep(values["task.cost_s"])
    return {"value": float(np.random.default_rng(seed).normal())}


SLEEP = Task(
    name="sleep",
    base="none",
    parameters={},
    options={},
    outputs={"value": ""},
    evaluate=_sleep,
    description="wait task.cost_s seconds",
)


def _noop(index: int) -> int:
    """Nothing: what Dask alone costs a task."""
    return index


def _timed_store_run(sweep: Sweep, client: object) -> tuple[float, float]:
    """Wall seconds and this process's CPU seconds of one run into a fresh zarr store."""
    with tempfile.TemporaryDirectory() as folder:
        c0, t0 = time.process_time(), time.perf_counter()
        run_sweep(sweep, client=client, out=Path(folder) / "bench.zarr")
        return time.perf_counter() - t0, time.process_time() - c0


@contextlib.contextmanager
def _external_cluster(workers: int, threads: int) -> Iterator[str]:
    """A scheduler and ``workers`` worker processes of ``threads`` threads each, started as
    processes of their own (``dask scheduler``, ``dask worker``), as on a real cluster
    whose scheduler does not share the client's process: yield its address."""
    import json

    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).resolve().parent), *sys.path])
    )
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "env": env}
    with tempfile.TemporaryDirectory() as folder:
        file = str(Path(folder) / "scheduler.json")
        common = ["--scheduler-file", file, "--no-dashboard", "--host", "127.0.0.1"]
        started = [
            subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_scheduler", *common], **quiet
            )
        ]
        try:
            deadline = time.monotonic() + 60.0
            while not Path(file).exists() and time.monotonic() < deadline:
                time.sleep(0.1)
            time.sleep(0.5)  # written whole
            started.append(
                subprocess.Popen(
                    [
                        sys.executable,
                        "-m",
                        "distributed.cli.dask_worker",
                        *common,
                        "--nworkers",
                        str(workers),
                        "--nthreads",
                        str(threads),
                    ],
                    **quiet,
                )
            )
            yield str(json.loads(Path(file).read_text())["address"])
        finally:
            for process in reversed(started):
                process.terminate()
                process.wait()


def _median(values: list[float]) -> float:
    return float(np.median(values))


def _worker_threads_env() -> dict[str, str | None]:
    """What a worker process's BLAS / OpenMP / numba thread counts are set to."""
    keys = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
    return {k: os.environ.get(k) for k in keys}


def store_targets(scale: float = 1.0, rounds: int = 3, parts: tuple[int, ...] = (1, 2, 3)) -> None:
    """Issue 27's targets side by side in one run: client overhead, 2 workers, 200 threads
    (``parts``: which of the three, e.g. ``(3,)`` for the 200 threads alone, on a machine
    the first two parts' clusters have not just left).

    A *task* here is what the issue counts: one chunk of the sweep (``chunk_size`` points;
    at ``chunk_size = 1``, one point). The client groups short chunks into fewer Dask tasks
    (clearjoint.parallel.auto_group): both counts are printed. Every figure is the median
    of ``rounds`` runs, the configurations alternating within a round, so that a change
    of the machine's load falls on all of them alike.
    """
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (shared)")
    print(f"each figure: the median of {rounds} rounds")
    if 1 in parts:
        _overhead(scale, rounds)
    if 2 in parts:
        _two_workers(scale, rounds)
    if 3 in parts:
        _many_threads(scale, rounds)
    print(f"load average after: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


def _overhead(scale: float, rounds: int) -> None:
    """Part 1: the client's overhead a task, examples/tolerance.toml at chunk_size = 1."""
    from dataclasses import replace

    from clearjoint.parallel import auto_group
    from clearjoint.sweep.run import _Chunk, _column_names, _evaluate_chunk, _point_values

    # 1. overhead a task: examples/tolerance.toml at chunk_size = 1 against a plain loop
    sweep = replace(Sweep.from_toml(EXAMPLES / "tolerance.toml"), chunk_size=1)
    if scale < 1:
        sweep = replace(sweep, samples=max(2, int(sweep.samples * scale)))
    drawn = sweep.drawn()
    names = _column_names(sweep)
    every = _Chunk(
        sweep.task,
        sweep.base,
        names,
        _point_values(sweep, drawn, 0, sweep.n_points),
        0,
        sweep.seed,
        sweep.outputs,
        sweep.fixed,
    )
    _evaluate_chunk(replace(every, values=every.values[:4]))  # compiled and warm
    n = sweep.n_points
    loops: list[float] = []
    walls: dict[int, list[float]] = {1: [], 2: []}
    cpus: dict[int, list[float]] = {1: [], 2: []}
    bare: dict[int, list[float]] = {1: [], 2: []}
    with dask_client(workers=1) as one, dask_client(workers=2) as two:
        clients = {1: one, 2: two}
        for workers, client in clients.items():
            client.wait_for_workers(workers)
            _timed_store_run(replace(sweep, samples=2 * workers), client)  # warm
        env = two.run(_worker_threads_env)
        for _ in range(rounds):
            t0 = time.perf_counter()
            _evaluate_chunk(every)
            loops.append(time.perf_counter() - t0)
            for workers, client in clients.items():
                wall, cpu = _timed_store_run(sweep, client)
                walls[workers].append(wall)
                cpus[workers].append(cpu)
                t0 = time.perf_counter()  # Dask alone: one no-op Dask task per chunk
                client.gather(client.map(_noop, range(n), pure=False))
                bare[workers].append(time.perf_counter() - t0)
    loop = _median(loops)
    print(f"   worker processes' thread settings: {sorted(set(map(str, env.values())))}")
    print(f"1. {n} tasks (chunks of 1 point) of tolerance.toml: plain loop {loop:.2f} s")
    for workers in (1, 2):
        wall = _median(walls[workers])
        over = (wall - loop / workers) / n
        group = auto_group(n, workers)
        print(
            f"   {workers} worker(s), with the store: {wall:.2f} s, {n / wall:.0f} tasks/s, "
            f"as {-(-n // group)} Dask tasks of {group} chunks; overhead "
            f"{over * 1e3:.2f} ms a task (wall - loop/{workers}), client CPU "
            f"{_median(cpus[workers]) / n * 1e3:.2f} ms a task; target <= 2 ms"
        )
        print(
            f"   {workers} worker(s), Dask alone ({n} no-op Dask tasks, map + gather): "
            f"{_median(bare[workers]) / n * 1e3:.2f} ms a Dask task"
        )


def _two_workers(scale: float, rounds: int) -> None:
    """Part 2: a CPU-bound study on 2 workers against 1, with a process pool as control."""
    # 2. a CPU-bound study, chunks of 0.5 s: 2 workers against 1, with a control
    spin = spin_sweep(max(40, int(200 * scale)), 0.050, 10)
    times: dict[str, list[float]] = {"1 worker": [], "2 workers": [], "pool 1": [], "pool 2": []}
    with contextlib.ExitStack() as stack:
        runners: dict[str, object] = {
            "1 worker": stack.enter_context(dask_client(workers=1)),
            "2 workers": stack.enter_context(dask_client(workers=2)),
            "pool 1": stack.enter_context(ProcessPoolExecutor(1)),
            "pool 2": stack.enter_context(ProcessPoolExecutor(2)),
        }
        for key, runner in runners.items():
            if key.endswith(("worker", "workers")):
                runner.wait_for_workers(1 if key == "1 worker" else 2)  # type: ignore[attr-defined]
                runner.run(_warm)  # type: ignore[attr-defined]
            run_sweep(spin_sweep(4, 0.0, 1), client=runner)  # warm, end to end
        loads = []
        for _ in range(rounds):
            for key, runner in runners.items():
                times[key].append(_timed_store_run(spin, runner)[0])
            loads.append(os.getloadavg()[0])
    ratio = [a / b for a, b in zip(times["1 worker"], times["2 workers"], strict=True)]
    control = [a / b for a, b in zip(times["pool 1"], times["pool 2"], strict=True)]
    chunks = -(-spin.n_points // spin.chunk_size)
    print(
        f"2. {chunks} tasks of 0.5 s CPU (10 points of 50 ms), with the store: 1 worker "
        f"{_median(times['1 worker']):.2f} s, 2 workers {_median(times['2 workers']):.2f} s; "
        f"2 workers / 1: median {_median(ratio):.2f}x (rounds: "
        f"{', '.join(f'{r:.2f}' for r in ratio)}); target >= 1.7x"
    )
    print(
        f"   control, the same sweep on a ProcessPoolExecutor (no Dask): 2 processes / 1: "
        f"median {_median(control):.2f}x (rounds: {', '.join(f'{r:.2f}' for r in control)}); "
        f"load average after each round: {', '.join(f'{x:.1f}' for x in loads)}"
    )


def _many_threads(scale: float, rounds: int) -> None:
    """Part 3: a simulated cluster of 200 threads (see the comment below)."""
    from dataclasses import replace

    # 3. a simulated cluster of 200 threads on 50 ms sleeps, chunk_size = 1; three times: a
    # LocalCluster as Dask starts it; the same with its workers' statistical profiler off
    # (it walks every thread's stack each 10 ms: here 100 threads share a worker process
    # and its CPU, where a real cluster of 200 workers profiles one thread each, on cores of
    # their own); and a scheduler and workers started as processes of their own, since a
    # LocalCluster's scheduler runs on the client's own IO-loop thread
    import dask
    import distributed  # noqa: F401  (its config defaults in place before it is set)

    from clearjoint.parallel import auto_group

    sleeps = replace(spin_sweep(int(10_000 * scale), 0.050, 1), task=SLEEP)
    m = sleeps.n_points
    group = auto_group(m, 200)
    for profiled, external in ((True, False), (False, False), (True, True)):
        with contextlib.ExitStack() as stack:
            stack.enter_context(dask.config.set({"distributed.worker.profile.enabled": profiled}))
            address = stack.enter_context(_external_cluster(2, 100)) if external else None
            client = stack.enter_context(dask_client(address, workers=2, threads=100))
            client.wait_for_workers(2)
            _timed_store_run(replace(sleeps, axes=(Axis("task.index", (0.0, 1.0), ""),)), client)
            stored, cpu, plain = [], [], []
            for _ in range(rounds):
                wall, used = _timed_store_run(sleeps, client)
                stored.append(wall)
                cpu.append(used)
                t0 = time.perf_counter()
                run_sweep(sleeps, client=client)
                plain.append(time.perf_counter() - t0)
        where = (
            "a scheduler and 2 worker processes of their own, as on a real cluster"
            if external
            else "a LocalCluster: its scheduler in this process, workers' profiler "
            + ("on, as Dask starts them" if profiled else "off")
        )
        print(
            f"3. {m} tasks (chunks of 1 point) of a 50 ms sleep on 2 workers x 100 threads "
            f"({where}), as "
            f"{-(-m // group)} Dask tasks of {group}: with the store "
            f"{m / _median(stored):.0f} tasks/s (client CPU {_median(cpu) / m * 1e3:.2f} ms "
            f"a task), without it {m / _median(plain):.0f} tasks/s; target >= 2,000/s "
            f"(4,000/s: 200 threads never idle)"
        )


RESTART_SWEEP = """
base = "{study}"
seed = 3
chunk_size = 2
[task]
name = "steady_state"
outputs = ["amplitude_m", "energy_input_j", "period_multiple"]
samples_per_period = 32
[axes.joint]
clearance = {{ start = "0.02mm", stop = "0.2mm", num = 5 }}
[axes.excitation]
force_amplitude = {{ start = "200N", stop = "2kN", num = 8 }}
"""


def _sweep_command(sweep: Path, out: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "clearjoint", "sweep", str(sweep), "--out", str(out), *extra]


def restart() -> None:
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        sweep = tmp / "sweep.toml"
        sweep.write_text(RESTART_SWEEP.format(study=EXAMPLES / "study.toml"), encoding="utf-8")
        whole, cut = tmp / "whole.zarr", tmp / "cut.zarr"
        quiet = ("--quiet", "--workers", "2")
        subprocess.run(_sweep_command(sweep, whole, *quiet), check=True, capture_output=True)
        run = subprocess.Popen(
            _sweep_command(sweep, cut, *quiet),
            start_new_session=True,  # its own process group: client, scheduler and workers
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        total = 20  # chunks
        done = 0
        while run.poll() is None:
            time.sleep(0.2)
            try:
                done = len(ResultStore.open(cut).done_chunks())
            except Exception:  # the store is being created
                continue
            if done >= total // 3:
                os.killpg(run.pid, signal.SIGKILL)
                run.wait()
                break
        left = len(ResultStore.open(cut).done_chunks())
        print(f"SIGKILL after {left} of {total} chunks (exit {run.returncode})")
        subprocess.run(_sweep_command(sweep, cut, *quiet, "--resume"), check=True)
        a, b = ResultStore.open(whole).read(), ResultStore.open(cut).read()
        same = all(np.array_equal(a[k][0], b[k][0], equal_nan=a[k][0].dtype.kind == "f") for k in a)
        failed = [str(s) for s in a["status"][0] if not str(s).startswith("ok")]
        print(f"points failed in both runs (NaN, reason in status): {failed}")
        print(f"resumed store equal to the uninterrupted run, bit for bit: {same}")
        if not same:
            raise SystemExit(1)


if __name__ == "__main__":  # LocalCluster workers are spawned processes: keep this guard
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2, help="runs per rate (best kept)")
    parser.add_argument("--throughput-only", action="store_true", help="skip the restart test")
    parser.add_argument(
        "--store-targets",
        action="store_true",
        help="only issue 27's targets (client overhead, 2 workers, 200 threads)",
    )
    parser.add_argument(
        "--smoke", action="store_true", help="tiny sizes: checks it runs, no figures"
    )
    parser.add_argument(
        "--rounds", type=int, default=3, help="--store-targets: rounds per figure (median kept)"
    )
    parser.add_argument(
        "--parts",
        default="1,2,3",
        help="--store-targets: which targets, e.g. 3 for the 200 threads alone (1,2,3)",
    )
    options = parser.parse_args()
    if options.store_targets:
        parts = tuple(x.strip() for x in options.parts.split(","))
        if not set(parts) <= {"1", "2", "3"}:
            parser.error(f"--parts takes 1, 2 and 3, comma-separated; got {options.parts!r}")
        store_targets(
            0.05 if options.smoke else 1.0,
            1 if options.smoke else options.rounds,
            tuple(int(x) for x in parts),
        )
        raise SystemExit(0)
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    sizes = [(cost, points // 20, chunk // 10) for cost, points, chunk in CASES]
    throughput(options.repeats, sizes if options.smoke else CASES)
    if not options.throughput_only:
        restart()
