"""
The README study's whole frequency-response curve, 20 to 900 Hz
===============================================================

examples/study.toml (2 kg, gap 0.106 mm, contact 8e7 / 5e7 N/m, k0 = 0, F0 = 1000 N,
zeta 0.01, restitution 0.8, friction 0.2 x 300 N everywhere) followed by continuation of
the exact period-1 orbit with the default options, as
``clearjoint frf examples/study.toml --from 20Hz --to 900Hz --out frf.nc`` does. Below
about 178 Hz the superharmonic resonances (1/n of the main one) fold and double; the main
resonance peaks near 690 Hz and folds at 704.8 Hz; its unstable branch comes back down to
487 Hz, where its orbit touches both gap edges and meets the widest of the orbits that
stay inside the gap. From there on (dotted) the orbit never touches an edge: with k0 = 0
it is one of a continuum (any mean position that keeps it off the edges), and the curve
shows the one centred in the gap (MODEL.md sec. 5.1).
"""

import math
import time
from pathlib import Path

import matplotlib.pyplot as plt

from clearjoint.periodic import frequency_response
from clearjoint.simulate.study import load_study

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

EXAMPLES = Path("..")  # the gallery runs from examples/gallery/
study = load_study(EXAMPLES / "study.toml")
hz = 2.0 * math.pi
start = time.perf_counter()
curve = frequency_response(
    study.joint,
    study.force_amplitude,
    20.0 * hz,
    900.0 * hz,
    losses=study.motion_losses,  # the study's losses but the pin (no ledger on a curve)
)
print(curve)
print(f"{time.perf_counter() - start:.1f} s")

fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.2))
for ax, (lo, hi) in zip(axes, ((20.0, 900.0), (440.0, 740.0)), strict=True):
    curve.plot(ax)
    ax.set_xlim(lo, hi)
axes[0].set_title("examples/study.toml, 20-900 Hz (1000 N)")
axes[1].set_title("the main resonance and where its branch ends")
axes[1].get_legend().remove()
fig.tight_layout()
DOCS_FIGURES["periodic_study_curve.png"] = fig
