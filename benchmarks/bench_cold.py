"""A documented command's first run (empty compiled-code cache) against its later runs.

Run on demand: ``python benchmarks/bench_cold.py [--rounds N] [--jit] [-- COMMAND...]``; by default
the command is ``clearjoint frf examples/frf.toml --from 10Hz --to 360Hz`` (issue 28: at most
3x its warm run). Each round runs the command twice as a user does, side by side in this
one run: cold, with NUMBA_CACHE_DIR a fresh empty folder (numba compiles every kernel and
stores it there), then warm, with the same folder (every kernel loads). The kernels
compiled at install (``clearjoint.compiled``) are used when present, unless ``--jit``
(then numba compiles them on the cold run, as before they existed). Wall times, and
their ratio cold / warm, are printed per round and as medians. Other sessions may load the
machine: compare the ratio, measured in one run, not the seconds.

``--where`` then runs the command once more in this process, cold (a fresh cache folder),
and prints where the compile time goes: each kernel compiled from Python (with what it
compiles inside it: its callees, linked and optimised again into its own code), the
seconds it took and the line that called it.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ["frf", "examples/frf.toml", "--from", "10Hz", "--to", "360Hz"]


def _timed(command: list[str], cache: Path, out: Path, jit: bool) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    if jit:
        env["CLEARJOINT_COMPILED"] = "0"
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "clearjoint", *command, "--out", str(out), "--force", "--quiet"],
        cwd=ROOT,
        env=env,
        check=True,
        stdout=subprocess.DEVNULL,
    )
    return time.perf_counter() - start


def where(command: list[str]) -> None:
    """Run ``command`` cold in this process; print where its compile time goes.

    Two tables. First each kernel compiled from Python, with its seconds (the kernels it
    calls compiled inside it) and the line that called it. Then every function numba
    compiled, callees included, with its own seconds (its callees' compiles taken out) split
    into numba's own Python work (bytecode analysis, type inference, lowering to LLVM IR)
    and LLVM's (optimising and emitting machine code: numba's "numba:llvm_lock" event).
    """
    import runpy
    import traceback

    from numba.core import event

    stack: list[list[Any]] = []  # [name, start, seconds in callees, seconds in LLVM]
    tops: list[tuple[float, str, str]] = []
    own: dict[str, list[float]] = {}  # name -> [own seconds, of which LLVM, compiles]

    class Timer(event.Listener):  # type: ignore[misc]
        def on_start(self, ev: Any) -> None:
            caller = ""
            if not stack:  # the Python line that asked for the kernel
                for frame in reversed(traceback.extract_stack()):
                    if "clearjoint" in frame.filename and "numba" not in frame.filename:
                        caller = f"{frame.filename.split('src/')[-1]}:{frame.lineno}"
                        break
            name = ev.data["dispatcher"].py_func.__qualname__
            stack.append([name, time.perf_counter(), 0.0, 0.0, caller])

        def on_end(self, ev: Any) -> None:
            name, start, inner, llvm, caller = stack.pop()
            seconds = time.perf_counter() - start
            row = own.setdefault(name, [0.0, 0.0, 0])
            row[0] += seconds - inner
            row[1] += llvm
            row[2] += 1
            if stack:
                stack[-1][2] += seconds
            else:
                tops.append((seconds, name, caller))

    class Llvm(event.Listener):  # type: ignore[misc]
        def on_start(self, ev: Any) -> None:
            self.start = time.perf_counter()

        def on_end(self, ev: Any) -> None:
            if stack:
                stack[-1][3] += time.perf_counter() - self.start

    event.register("numba:compile", Timer())
    event.register("numba:llvm_lock", Llvm())
    start = time.perf_counter()
    old = sys.argv
    sys.argv = ["clearjoint", *command, "--quiet"]
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # the command's own output
            runpy.run_module("clearjoint", run_name="__main__")
    except SystemExit:
        pass
    finally:
        sys.argv = old
    total = time.perf_counter() - start
    compiled = sum(t for t, _, _ in tops)
    print(f"cold run in this process: {total:.1f} s, of which compiling {compiled:.1f} s:")
    for seconds, name, caller in sorted(tops, reverse=True):
        print(f"  {seconds:5.1f} s  {name}  (called at {caller})")
    if not own:
        print("nothing compiled")
        return
    llvm = sum(row[1] for row in own.values())
    times = sorted(row[0] for row in own.values())
    print(
        f"{sum(int(row[2]) for row in own.values())} compiles of {len(own)} functions; "
        f"numba's Python work {compiled - llvm:.1f} s, LLVM {llvm:.1f} s; "
        f"a function's own compile: median {statistics.median(times):.2f} s, "
        f"smallest {times[0]:.2f} s"
    )
    print("  own s  (LLVM s)  compiles  function")
    for name, (seconds, in_llvm, count) in sorted(own.items(), key=lambda i: -i[1][0]):
        print(f"  {seconds:5.2f}  ({in_llvm:4.2f})  {int(count):8d}  {name}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=1, help="cold + warm pairs (default 1)")
    parser.add_argument(
        "--where", action="store_true", help="then show where a cold run's compile time goes"
    )
    parser.add_argument(
        "--jit",
        action="store_true",
        help="leave the kernels compiled at install unused (CLEARJOINT_COMPILED=0): numba "
        "compiles them on the cold run, as before they existed",
    )
    parser.add_argument("command", nargs="*", help="clearjoint arguments (default: the frf)")
    args = parser.parse_args()
    command = args.command or DEFAULT
    from clearjoint import compiled  # imports no numba: --where sets its cache folder later

    built = sorted(Path(compiled.__file__).parent.glob(compiled.module_name() + ".*"))
    if args.jit:
        print("kernels compiled at install: not used (--jit)")
    else:
        print(
            "kernels compiled at install: "
            + (f"used ({built[0].name})" if built else "absent (python -m clearjoint.compiled)")
        )
    ratios, colds, warms = [], [], []
    with tempfile.TemporaryDirectory(prefix="bench-cold-") as folder:
        for round_ in range(args.rounds):
            cache = Path(folder) / f"cache-{round_}"
            cache.mkdir()
            out = Path(folder) / "out.nc"
            cold = _timed(command, cache, out, args.jit)
            warm = _timed(command, cache, out, args.jit)
            colds.append(cold)
            warms.append(warm)
            ratios.append(cold / warm)
            print(
                f"round {round_ + 1}: cold {cold:.1f} s, warm {warm:.1f} s, ratio {cold / warm:.1f}"
            )
    print(
        f"clearjoint {' '.join(command)}: median cold {statistics.median(colds):.1f} s, "
        f"warm {statistics.median(warms):.1f} s, cold / warm {statistics.median(ratios):.1f} "
        "(target: at most 3)"
    )
    if args.where:
        with tempfile.TemporaryDirectory(prefix="bench-cold-where-") as folder:
            os.environ["NUMBA_CACHE_DIR"] = folder  # before numba is imported here
            out = Path(folder) / "out.nc"
            where([*command, "--out", str(out), "--force"])


if __name__ == "__main__":
    main()
