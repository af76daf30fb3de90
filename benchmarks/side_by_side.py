"""The existing benchmarks of two checkouts, side by side: CPU time of each, alternated.

Issue 23 (a refactor) must lose no speed: "the existing benchmarks within 5 % of before,
side by side". This runs each benchmark script of OLD with OLD's code and the same script
of NEW with NEW's code (``PYTHONPATH=CHECKOUT/src``, each checkout's own benchmarks/, so
each speaks its own API), alternating OLD, NEW, OLD, NEW ... so that a change in the
machine's load falls on both, and reports the best CPU time (user + system of the child
process, which a busy second core disturbs less than wall time) of each and NEW / OLD.

The first run of each side compiles numba's kernels into that checkout's cache and is not
counted (``--warm`` runs, default 1). The cases are short settings of the scripts in this
folder; ``--list`` prints them.

    python3.11 benchmarks/side_by_side.py OLD NEW [--repeats 3] [--only periodic,identify]

OLD and NEW are checkout folders (each with src/ and benchmarks/). Timings depend on the
machine: quote them with the command and the load.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

#: name -> (script, arguments): short cases of the existing benchmarks
CASES: dict[str, tuple[str, list[str]]] = {
    "periodic": ("bench_periodic.py", ["--skip-sweep-both"]),
    "structure": (
        "bench_structure.py",
        ["--mast-periods", "40", "--ivp-periods", "1", "--bays", "5,10", "--scaling-periods", "2"],
    ),
    "harmonic": ("bench_harmonic.py", []),
    "identify": ("bench_identify.py", ["--repeats", "1"]),
}


def _child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_once(checkout: Path, script: str, arguments: list[str]) -> tuple[float, float]:
    """Run one benchmark script of ``checkout`` on its own code; return (CPU s, wall s)."""
    env = dict(os.environ, PYTHONPATH=str(checkout / "src"))
    before, start = _child_cpu(), time.perf_counter()
    done = subprocess.run(
        [sys.executable, str(checkout / "benchmarks" / script), *arguments],
        env=env,
        cwd=checkout,
        capture_output=True,
        text=True,
        check=False,
    )
    wall = time.perf_counter() - start
    if done.returncode != 0:
        tail = "\n".join(done.stderr.strip().splitlines()[-5:])
        raise SystemExit(f"{checkout}/benchmarks/{script} failed:\n{tail}")
    return _child_cpu() - before, wall


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path, nargs="?")
    parser.add_argument("new", type=Path, nargs="?")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per side")
    parser.add_argument("--warm", type=int, default=1, help="untimed runs per side first")
    parser.add_argument("--only", help="comma-separated case names")
    parser.add_argument("--list", action="store_true", help="print the cases and stop")
    args = parser.parse_args(argv)
    if args.list or args.old is None or args.new is None:
        for name, (script, arguments) in CASES.items():
            print(f"{name:10s} {script} {' '.join(arguments)}")
        return 0
    names = args.only.split(",") if args.only else list(CASES)
    unknown = sorted(set(names) - set(CASES))
    if unknown:
        parser.error(f"unknown case {unknown[0]!r}; --list shows them")
    print(f"OLD {args.old.resolve()}\nNEW {args.new.resolve()}")
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print(f"{'case':10s} {'OLD cpu s':>10s} {'NEW cpu s':>10s} {'NEW/OLD':>8s}  (wall s OLD, NEW)")
    for name in names:
        script, arguments = CASES[name]
        for _ in range(args.warm):
            run_once(args.old, script, arguments)
            run_once(args.new, script, arguments)
        old, new = [], []
        for _ in range(args.repeats):
            old.append(run_once(args.old, script, arguments))
            new.append(run_once(args.new, script, arguments))
        o, n = min(old), min(new)
        print(f"{name:10s} {o[0]:10.2f} {n[0]:10.2f} {n[0] / o[0]:8.3f}  ({o[1]:.1f}, {n[1]:.1f})")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
