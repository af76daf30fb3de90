"""The exact steady response of a chain: the stepped-sine diagram's cost, and its verdicts checked.

Run on demand::

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_steady.py [--masses 5] [--points 300]
        [--settle 200] [--record 100] [--workers 2] [--plot map.png] [--check 20]

The chain of issue 24 (0.5 kg masses, clearance joints +-0.1 mm, contact 4e5 N/m, k0 2e4
N/m, 2 N s/m across each link, 30 N on the last mass), stepped from 2 to 60 Hz up and down
on a local Dask cluster of ``--workers`` single-threaded workers (the frequencies cut into
4 contiguous runs per worker and direction). Printed: the wall clock of the whole diagram,
the kinds of motion found, the jumps, and the periods and gap-edge events simulated. With
``--check K``, K of the frequencies called "periodic" or "period-k" are re-solved by
``clearjoint.structure.periodic_orbit`` from their last Poincaré sample (closure 1e-10),
and their multipliers are required inside the unit circle: the verdicts re-checked by
the orbit solver on its own. ``--masses 10,20`` measures the longer chains too.
"""

from __future__ import annotations

import argparse
import math
import time
from collections import Counter

import numpy as np

import clearjoint as cj
from clearjoint.parallel import dask_client
from clearjoint.structure import chain, periodic_orbit, stepped_sine


def _chain(n: int) -> tuple[object, np.ndarray]:
    law = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4)
    force = np.zeros(n)
    force[-1] = 30.0
    return chain([0.5] * n, [math.inf] * n, [law] * n, [2.0] * n), force


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--masses", default="5", help="chain lengths, comma-separated")
    parser.add_argument("--points", type=int, default=300)
    parser.add_argument("--settle", type=int, default=200)
    parser.add_argument("--record", type=int, default=100)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--plot", help="draw the (first) diagram into this file")
    parser.add_argument("--check", type=int, default=20, help="periodic verdicts re-solved")
    args = parser.parse_args()
    hz = np.linspace(2.0, 60.0, args.points)
    with dask_client(workers=args.workers) as client:
        for k, n in enumerate(int(x) for x in args.masses.split(",")):
            s, force = _chain(n)
            # warm every worker (numba's cache, imports) before the clock starts
            stepped_sine(
                s,
                force,
                [2 * math.pi * 30.0],
                settle_periods=2,
                record_periods=4,
                runner=client,
                chunks=args.workers,
            )
            t0 = time.perf_counter()
            diagram = stepped_sine(
                s,
                force,
                2 * math.pi * hz,
                direction="both",
                settle_periods=args.settle,
                record_periods=args.record,
                runner=client,
                chunks=4 * args.workers,
            )
            wall = time.perf_counter() - t0
            periods = (
                2 * args.points * (args.settle + args.record) + 2 * 4 * args.workers * args.settle
            )
            print(
                f"{n}-mass chain, {args.points} frequencies 2-60 Hz up and down, "
                f"{args.settle} + {args.record} periods each, {args.workers} workers:"
            )
            print(
                f"  wall {wall:.1f} s ({wall / 60:.2f} min); {periods} periods simulated; "
                f"{int(diagram.events.sum())} gap-edge events in the recorded periods"
            )
            print(f"  kinds: {dict(Counter(diagram.kind.ravel().tolist()))}")
            print(f"  jumps: {len(diagram.jumps)}")
            for jump in diagram.jumps[:8]:
                print(
                    f"    {jump['direction']}: {jump['from_hz']:.3f} -> {jump['to_hz']:.3f} Hz, "
                    f"{1e3 * jump['from_amplitude_m']:.3f} -> "
                    f"{1e3 * jump['to_amplitude_m']:.3f} mm"
                )
            if args.check:
                d, i = np.nonzero(np.isin(diagram.kind, ("periodic", "period-k")))
                chosen = np.linspace(0, d.size - 1, min(args.check, d.size)).round().astype(int)
                worst = 0.0
                for c in np.unique(chosen) if d.size else []:
                    a, b = int(d[c]), int(i[c])
                    sample = diagram.poincare[a, b, -1]
                    orbit = periodic_orbit(
                        s,
                        force,
                        2 * math.pi * hz[b],
                        period_multiple=max(1, int(diagram.period[a, b])),
                        initial=(sample[:n], sample[n:]),
                    )
                    if not (orbit.closure <= 1e-10 and orbit.stable):
                        raise SystemExit(f"verdict not reproduced at {hz[b]:.4f} Hz: {orbit!r}")
                    worst = max(worst, orbit.largest_multiplier)
                print(
                    f"  {min(args.check, d.size)} periodic verdicts re-solved by periodic_orbit: "
                    f"all closed to 1e-10 and stable (largest |mu| {worst:.4f})"
                )
            if args.plot and k == 0:
                import matplotlib

                matplotlib.use("Agg")
                import matplotlib.pyplot as plt

                ax = diagram.plot()
                ax.set_title(f"{n}-mass chain, 30 N: stepped sine, exact motion")
                ax.figure.savefig(args.plot, dpi=120, bbox_inches="tight")
                plt.close(ax.figure)


if __name__ == "__main__":
    main()
