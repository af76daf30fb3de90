"""Samples per second of ``clearjoint identify`` end to end on the command line.

Run on demand::

    python benchmarks/bench_identify.py [--brfd DIR] [--records DIR] [--old-src SRC] [--jobs N]
        [--old-jobs N] [--repeats R]

It times the command (process start, reading, identification, writing results.csv) over
the default rig campaign (written to a temporary folder unless ``--records`` names one)
and over the BRFD folder, best of ``--repeats``, in wall-clock seconds and in CPU seconds
(user + system of the command's processes, which contention inflates less). With
``--old-src`` (for example the ``src`` folder of another checkout) the same command runs
with that code too, in the same loop, and the ratio is printed: on a shared machine only
ratios measured side by side mean anything; the load average is printed before and after.
``--old-jobs`` gives the old code's ``--jobs`` (for code that has the option). For each
set it also prints the CPU seconds of reading and of identifying in this process, and the
identification's own share of the command's CPU seconds (the estimators change; the rest
is reading, start-up and orchestration);
``--critical-path`` estimates, for a machine with a free core per process, the wall time
of ``--jobs N`` from CPU seconds, which contention inflates far less than wall time: this
process's CPU seconds to the end of ``main``, against its CPU seconds when it forked plus a
worker's own (the larger of the two; the interpreter's start before ``main`` and its exit
after are not in it), best of ``--repeats``, old and new code interleaved.
``--parsers`` compares JSON readers of the BRFD files side by side (CPU seconds, best of
``--repeats``; each must give the same doubles as Python's json module, bit for bit).
``--compare`` (with ``--old-src``) runs both codes' command once on each set and compares
their results.csv: byte for byte, else every number within 1e-12 relative and every text
(flags, reasons) equal; it prints the verdict per set and exits 1 on a difference.
Target (issue 15): 1e6 samples per second.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

from clearjoint.records import read_record
from clearjoint.records.brfd import _brfd_json
from clearjoint.rig import load_campaign, run_campaign

TARGET = 1e6
HERE = Path(__file__).resolve()


def samples(files: list[Path]) -> int:
    total = 0
    for path in files:
        if path.suffix == ".nc":
            with h5py.File(path, "r") as handle:
                total += int(handle["time"].shape[0])
        else:
            total += read_record(path).time.size
    return total


def run(
    files: list[Path], src: str | None, jobs: int, out: Path, old_jobs: int = 1
) -> tuple[float, float]:
    """Wall-clock and CPU seconds (user + system, of the command's processes) of one run.

    Python's compiled bytecode is kept (in a folder of its own, ``PYTHONPYCACHEPREFIX``,
    so that no checkout is written to) even where ``PYTHONDONTWRITEBYTECODE`` is set, as
    for an installed package: compiling clearjoint's sources anew costs about 0.08 s of
    every run. The first run of each code fills that folder and is not timed.
    """
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPYCACHEPREFIX"] = str(out.parent / "pycache")
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    if src:
        env["PYTHONPATH"] = src
    script = Path(sys.executable).parent / "clearjoint"  # the command a user types
    launcher = [str(script)] if script.exists() else [sys.executable, "-m", "clearjoint"]
    command = [*launcher, "identify", *map(str, files)]
    command += ["--out", str(out), "--quiet", "--force"]
    jobs = old_jobs if src else jobs
    if jobs > 1:
        command += ["--jobs", str(jobs)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, env=env, check=True, capture_output=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def split(files: list[Path]) -> tuple[float, float]:
    """CPU seconds of reading and of identifying ``files`` in this process (no start-up)."""
    from clearjoint.errors import ClearjointError
    from clearjoint.identify import identify

    start = time.process_time()
    records = [read_record(path) for path in files]
    read = time.process_time() - start
    start = time.process_time()
    for record in records:  # a record refused with its reason costs its time as well
        with contextlib.suppress(ClearjointError):
            identify(record)
    return read, time.process_time() - start


_BRACKETS = bytes.maketrans(b"[]", b"  ")


def _numpy_text(raw: bytes) -> np.ndarray:
    """The previous reader: the matrix text's brackets blanked, numpy's C parser."""
    start = raw.find(b"[[")
    body = raw[start : raw.find(b"]]", start) + 2]
    rows = body.count(b"[") - 1
    return np.fromstring(body.translate(_BRACKETS), sep=",").reshape(rows, -1)


def _orjson_fromiter(raw: bytes) -> np.ndarray:
    """The reader before simdjson: orjson's lists (collector off), numpy.fromiter over them."""
    import gc

    import orjson

    from clearjoint.records.brfd import _json_matrix

    gc.disable()
    try:
        return _json_matrix("", raw, orjson)[1]
    finally:
        gc.enable()


def _previous_reader(raw: bytes) -> np.ndarray:
    """The reader before numpy.fromiter: the collector off while orjson parses only."""
    import gc

    import orjson

    gc.disable()
    try:
        content = orjson.loads(raw)
    finally:
        gc.enable()
    return np.array(content["data"], dtype=np.float64)


def parsers(files: list[Path], repeats: int) -> None:
    """CPU seconds of each JSON reader over ``files`` (bytes already read), side by side."""
    import orjson

    raws = [path.read_bytes() for path in files]
    ways = {
        "json + numpy.array": lambda raw: np.array(json.loads(raw)["data"], dtype=np.float64),
        "numpy.fromstring of the text": _numpy_text,
        "orjson + numpy.array": lambda raw: np.array(orjson.loads(raw)["data"], dtype=np.float64),
        "orjson (no gc) + numpy.array": _previous_reader,
        "orjson (no gc) + numpy.fromiter": _orjson_fromiter,
        "the reader (simdjson, checked)": lambda raw: _brfd_json("", raw)[1],
    }
    reference = [ways["json + numpy.array"](raw) for raw in raws]
    megabytes = sum(map(len, raws)) / 1e6
    for name, way in ways.items():
        best = float("inf")
        for _ in range(repeats):
            start = time.process_time()
            matrices = [way(raw) for raw in raws]
            best = min(best, time.process_time() - start)
        same = all(np.array_equal(a, b) for a, b in zip(matrices, reference, strict=True))
        print(
            f"{name:30s} {best:6.3f} CPU s, {megabytes / best:5.0f} MB/s over {len(raws)} "
            f"files; same doubles as json: {same}"
        )


_TRACE = """
import os, resource, sys, time
fork, forks = os.fork, []
def timed_fork():
    forks.append(time.process_time())
    return fork()
os.fork = timed_fork
from clearjoint.cli import main
code = main()
end = time.process_time()
children = resource.getrusage(resource.RUSAGE_CHILDREN)
worker = (children.ru_utime + children.ru_stime) / max(len(forks), 1)
sys.stderr.write(f"\\nCRITICAL {end} {forks[0] if forks else end} {worker}\\n")
sys.exit(code)
"""


def critical_path(
    files: list[Path], src: str | None, jobs: int, out: Path
) -> tuple[float, float, float]:
    """CPU seconds of this process to the end of ``main``, at its first fork, and of one
    worker (the mean over the workers), for ``clearjoint identify FILES --jobs JOBS``."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPYCACHEPREFIX"] = str(out.parent / "pycache")
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    if src:
        env["PYTHONPATH"] = src
    command = [sys.executable, "-c", _TRACE, "identify", *map(str, files)]
    command += ["--out", str(out), "--quiet", "--force", "--jobs", str(jobs)]
    done = subprocess.run(command, env=env, check=True, capture_output=True, text=True)
    line = [x for x in done.stderr.splitlines() if x.startswith("CRITICAL ")][-1]
    end, forked, worker = map(float, line.split()[1:])
    return end, forked, worker


def _critical(sets: dict[str, list[Path]], args: argparse.Namespace, out: Path) -> None:
    codes = {"new": (None, args.jobs)}
    if args.old_src:
        codes["old"] = (args.old_src, args.old_jobs)
    for name, files in sets.items():
        best: dict[str, tuple[float, float, float, float]] = {}
        for _ in range(args.repeats):
            for label, (src, jobs) in codes.items():
                end, forked, worker = critical_path(files, src, jobs, out)
                estimate = max(end, forked + worker) if forked < end else end
                if label not in best or estimate < best[label][0]:
                    best[label] = (estimate, end, forked, worker)
        for label, (estimate, end, forked, worker) in best.items():
            print(
                f"{name:22s} {label} code (jobs={codes[label][1]}): {estimate:.3f} CPU s on the "
                f"critical path (this process {end:.3f}, forked at {forked:.3f}, a worker "
                f"{worker:.3f})"
            )
        if "old" in best:
            print(f"{name:22s} ratio old/new {best['old'][0] / best['new'][0]:.2f}x")


def _csv_rows(path: Path) -> list[list[str]]:
    import csv

    with path.open(newline="", encoding="utf-8") as handle:
        return list(csv.reader(handle))


def _same_results(new: Path, old: Path) -> str:
    """'identical' (byte for byte), 'within 1e-12 (largest relative difference D)', or
    what differs first."""
    if new.read_bytes() == old.read_bytes():
        return "identical byte for byte"
    a, b = _csv_rows(new), _csv_rows(old)
    if len(a) != len(b) or a[0] != b[0]:
        return f"DIFFERENT: {len(a)} rows against {len(b)}, or other columns"
    worst = 0.0
    for row, (ra, rb) in enumerate(zip(a[1:], b[1:], strict=True), start=2):
        for name, x, y in zip(a[0], ra, rb, strict=True):
            if x == y:
                continue
            try:
                fx, fy = float(x), float(y)
            except ValueError:
                return f"DIFFERENT at line {row}, column {name}: {x!r} against {y!r}"
            scale = max(abs(fx), abs(fy))
            if not (fx == fy or (scale > 0 and abs(fx - fy) <= 1e-12 * scale)):
                return f"DIFFERENT at line {row}, column {name}: {x} against {y}"
            worst = max(worst, abs(fx - fy) / scale)
    return f"within 1e-12 relative (largest difference {worst:.2g})"


def compare(sets: dict[str, list[Path]], old_src: str, folder: Path) -> bool:
    """Both codes' results.csv over each set, compared; True when all agree."""
    agree = True
    for name, files in sets.items():
        new_out, old_out = folder / "new.csv", folder / "old.csv"
        run(files, None, 1, new_out)
        run(files, old_src, 1, old_out)
        verdict = _same_results(new_out, old_out)
        agree &= not verdict.startswith("DIFFERENT")
        print(
            f"{name:22s} {len(files):3d} files: results.csv, this code against {old_src}: {verdict}"
        )
    return agree


def _load() -> str:
    return " ".join(f"{value:.2f}" for value in os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--brfd", default=str(HERE.parents[2] / "shared" / "data" / "brfd"))
    parser.add_argument("--records", help="folder of rig records (default: run the campaign)")
    parser.add_argument("--old-src", help="src folder of the code to compare with")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument(
        "--old-jobs", type=int, default=1, help="--jobs for the old code (if it has the option)"
    )
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--parsers", action="store_true", help="only compare JSON readers on the BRFD files"
    )
    parser.add_argument(
        "--compare",
        action="store_true",
        help="only compare both codes' results.csv over each set (needs --old-src)",
    )
    parser.add_argument(
        "--critical-path",
        action="store_true",
        help="only estimate --jobs N's wall time on free cores from CPU seconds per process",
    )
    args = parser.parse_args()
    if args.parsers:
        parsers(sorted(Path(args.brfd).glob("*.json")), args.repeats)
        return
    with tempfile.TemporaryDirectory() as folder:
        if args.records:
            rig = Path(args.records)
        else:
            manifest = run_campaign(load_campaign(), Path(folder) / "rig", jobs=1)
            rig = manifest.parent
        sets = {"default rig campaign": sorted(rig.glob("*.nc"))}
        brfd = Path(args.brfd)
        if brfd.exists():
            sets["BRFD folder"] = sorted(brfd.glob("*.json"))
        out = Path(folder) / "results.csv"
        if args.compare:
            if not args.old_src:
                parser.error("--compare needs --old-src")
            sys.exit(0 if compare(sets, args.old_src, Path(folder)) else 1)
        print("load average (1, 5, 15 min) before: " + _load())
        if args.critical_path:
            _critical(sets, args, out)
            print("load average (1, 5, 15 min) after: " + _load())
            return
        for name, files in sets.items():
            n = samples(files)
            best = {"new": (float("inf"), 0.0), "old": (float("inf"), 0.0)}
            run(files[:1], None, 1, out)  # fills the bytecode folder; not timed
            if args.old_src:
                run(files[:1], args.old_src, 1, out)
            for _ in range(args.repeats):
                best["new"] = min(best["new"], run(files, None, args.jobs, out))
                if args.old_src:
                    old = run(files, args.old_src, 1, out, args.old_jobs)
                    best["old"] = min(best["old"], old)
            wall, cpu = best["new"]
            rate = n / wall
            verdict = "meets" if rate >= TARGET else "below"
            line = (
                f"{name:22s} {len(files):3d} files {n:8d} samples: {wall:6.2f} s wall, "
                f"{rate:.3g} samples/s ({verdict} {TARGET:.0e}; jobs={args.jobs}); "
                f"{cpu:6.2f} CPU s, {n / cpu:.3g} samples per CPU s"
            )
            if args.old_src:
                old_wall, old_cpu = best["old"]
                line += (
                    f"; old code (jobs={args.old_jobs}) {old_wall:6.2f} s wall, "
                    f"{old_cpu:6.2f} CPU s: ratio "
                    f"{old_wall / wall:.2f}x wall, {old_cpu / cpu:.2f}x CPU"
                )
            print(line)
            read, identifying = split(files)
            print(
                f"{name:22s} in this process: reading {read:.2f} CPU s, identifying "
                f"{identifying:.2f} CPU s; the identification's own share of the command's "
                f"{cpu:.2f} CPU s: {identifying / cpu:.0%}"
            )
        print("load average (1, 5, 15 min) after: " + _load())


if __name__ == "__main__":
    main()
