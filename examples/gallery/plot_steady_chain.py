"""
The exact steady response of a rattling chain, against harmonic balance
=======================================================================

The 5-mass chain of ``examples/chain.toml`` (0.5 kg masses, clearance joints +-0.1 mm,
contact 4e5 N/m, free-play spring 2e4 N/m, 2 N s/m across each link) forced at its last
mass, stepped from 2 to 60 Hz up and down by the exact motion
(``clearjoint.structure.stepped_sine``): the Poincaré samples of the last mass, coloured by
the kind of motion. Over each, harmonic balance's curve (H = 7) from each end of the range
as far as it gets, stable solid, unstable dashed (a structure's point is stable only where
the exact motion confirms it), and at 1 N the exact curve by shooting
(``clearjoint.structure.frequency_response``). A coarse grid (30 frequencies, 100 settling
and 40 recorded periods), so the docs build draws it in a minute or two;
``python benchmarks/bench_steady.py --plot map.png`` draws the full 300-frequency diagram.
"""

import math
from collections import Counter
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from clearjoint import harmonic
from clearjoint.errors import ClearjointError
from clearjoint.structure import frequency_response, stepped_sine
from clearjoint.structure.study import load_structure_study

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

HERE = Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd()
study = load_structure_study(HERE.parent / "chain.toml")
hz = np.linspace(2.0, 60.0, 30)


def curves(force, shooting):
    """Harmonic balance from each end, and the exact curve from the low end."""
    out = []
    for a, b in ((2.0, 60.0), (60.0, 2.0)):
        try:
            curve = harmonic.frequency_response(
                study.structure, force, 2 * math.pi * a, 2 * math.pi * b, max_points=300
            )
            print(f"  harmonic balance from {a:g} Hz: {curve!r}")
            out.append(curve)
        except ClearjointError as exc:
            print(f"  harmonic balance from {a:g} Hz: {str(exc)[:120]}")
    if shooting:
        try:
            curve = frequency_response(
                study.structure, force, 2 * math.pi * 2.0, 2 * math.pi * 60.0, max_points=400
            )
            print(f"  shooting from 2 Hz: {curve!r}")
            out.append(curve)
        except ClearjointError as exc:
            print(f"  shooting from 2 Hz: {str(exc)[:120]}")
    return out


fig, axes = plt.subplots(2, 1, figsize=(8.0, 8.4), sharex=True)
for ax, newtons, shooting in ((axes[0], 30.0, False), (axes[1], 1.0, True)):
    force = study.force * (newtons / float(np.max(study.force)))
    diagram = stepped_sine(
        study.structure,
        force,
        2 * math.pi * hz,
        direction="both",
        settle_periods=100,
        record_periods=40,
    )
    print(f"{newtons:g} N: {diagram!r}")
    print(f"  kinds: {dict(Counter(diagram.kind.ravel().tolist()))}")
    diagram.plot(ax, dof="n5x", curves=curves(force, shooting))
    ax.set_title(f"{newtons:g} N on the last mass: exact motion stepped up (dots) and down (x)")
    ax.set_xlabel("")
axes[1].set_xlabel("frequency (Hz)")
fig.tight_layout()
DOCS_FIGURES["steady_chain.png"] = fig
