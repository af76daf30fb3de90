"""Evaluations per second of the exact dynamic stiffness, general case (issue: >= 1e7 /s, one core).

Run on demand: ``python benchmarks/bench_stiffness.py``. The joint has k0 > 0,
k_c != k_t and an off-centre gap, so every branch of the period formula runs.
Times are the best of several repeats of 10^6 evaluations in one call.
"""

from __future__ import annotations

import os
import time

# one core, as the target says (set before numpy starts its thread pools)
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

from clearjoint import Joint  # noqa: E402
from clearjoint.stiffness import dynamic_stiffness  # noqa: E402

TARGET = 1e7


def main(n: int = 1_000_000, repeats: int = 7) -> float:
    joint = Joint(
        mass=2.0,
        clearance=0.106e-3,
        compression_stiffness=8e7,
        tension_stiffness=5e7,
        gap_stiffness=1e6,
        gap_offset=0.01e-3,
    )
    amplitudes = np.random.default_rng(1).uniform(0.0, 1e-3, n)
    dynamic_stiffness(joint, amplitudes)  # warm the allocator
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        dynamic_stiffness(joint, amplitudes)
        best = min(best, time.perf_counter() - start)
    rate = n / best
    verdict = "meets" if rate >= TARGET else "MISSES"
    print(f"dynamic_stiffness, general case: {n} evaluations in {best * 1e3:.1f} ms")
    print(f"{rate:.3g} evaluations per second ({verdict} the target of {TARGET:.0e})")
    return rate


if __name__ == "__main__":
    main()
