"""The figure of docs/steady.md: ``python docs/make_steady_figure.py [--points 150]``.

The 5-mass chain of examples/chain.toml stepped from 2 to 60 Hz, up and down, by the exact
motion (``clearjoint.structure.stepped_sine``) at two forces: 30 N (the chain of issue 24,
whose motion rattles) and a lower force (default 3 N) where orbits, period-k motions and
chaos share the range. Over each, harmonic balance's curve (H = 7, from each end of the
range, as far as it gets) and, at the lower force, the exact curve by shooting from the
lower end (``clearjoint.structure.frequency_response``). Too slow for the docs build
(minutes on 2 cores), so the picture is committed: docs/figures/steady_chain.png. It
prints what it found (kinds, jumps, where each curve stopped).
"""

from __future__ import annotations

import argparse
import math
import time
from collections import Counter
from pathlib import Path

import numpy as np

from clearjoint import harmonic
from clearjoint.parallel import dask_client
from clearjoint.structure import frequency_response, stepped_sine
from clearjoint.structure.study import load_structure_study

HERE = Path(__file__).resolve().parent


def _curves(system, force, low, high, shooting):
    out = []
    for a, b in ((low, high), (high, low)):
        try:
            curve = harmonic.frequency_response(
                system, force, 2 * math.pi * a, 2 * math.pi * b, harmonics=7, max_points=600
            )
            out.append(curve)
            print(f"  harmonic balance from {a} Hz: {curve!r}")
        except Exception as exc:  # a start that fails is part of the finding
            print(f"  harmonic balance from {a} Hz: {type(exc).__name__}: {str(exc)[:160]}")
    if shooting:
        try:
            curve = frequency_response(
                system, force, 2 * math.pi * low, 2 * math.pi * high, max_points=800
            )
            out.append(curve)
            print(f"  shooting from {low} Hz: {curve!r}")
        except Exception as exc:
            print(f"  shooting from {low} Hz: {type(exc).__name__}: {str(exc)[:160]}")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=150)
    parser.add_argument("--settle", type=int, default=200)
    parser.add_argument("--record", type=int, default=60)
    parser.add_argument("--low-force", type=float, default=3.0, help="N")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default=str(HERE / "figures" / "steady_chain.png"))
    args = parser.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    study = load_structure_study(HERE.parent / "examples" / "chain.toml")
    system = study.structure
    hz = np.linspace(2.0, 60.0, args.points)
    fig, axes = plt.subplots(2, 1, figsize=(8.0, 8.4), sharex=True)
    with dask_client(workers=args.workers) as client:
        for ax, scale, shooting in (
            (axes[0], 1.0, False),
            (axes[1], args.low_force / float(np.max(study.force)), True),
        ):
            force = study.force * scale
            t0 = time.perf_counter()
            diagram = stepped_sine(
                system,
                force,
                2 * math.pi * hz,
                direction="both",
                settle_periods=args.settle,
                record_periods=args.record,
                runner=client,
                chunks=4 * args.workers,
            )
            print(f"{np.max(force):g} N: {diagram!r} in {time.perf_counter() - t0:.0f} s")
            print(f"  kinds: {dict(Counter(diagram.kind.ravel().tolist()))}")
            for jump in diagram.jumps:
                print(f"  jump {jump}")
            curves = _curves(system, force, 2.0, 60.0, shooting)
            diagram.plot(ax, dof="n5x", curves=curves)
            ax.set_title(f"{np.max(force):g} N on n5x: the exact motion, stepped up and down")
            ax.set_xlabel("")
    axes[1].set_xlabel("frequency (Hz)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
