"""
A parameter study and a tolerance study
=======================================

Two sweep files of ``clearjoint sweep``: the peak of the joint's stepped-sine
frequency-response curve over clearance x force (``examples/sweep.toml``), and the
natural frequency and damping of the joint when its clearance scatters as
normal(0.1 mm, 0.02 mm) truncated at 0, 1000 samples at two amplitudes
(``examples/tolerance.toml``). Here they run in this process, one point after the
other; ``clearjoint sweep FILE --out results.zarr`` runs them on a Dask cluster.
"""

from pathlib import Path

import matplotlib.pyplot as plt

from clearjoint.sweep import SERIAL, Sweep, run_sweep
from clearjoint.sweep.plot import plot_sweep

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
EXAMPLES = Path("..")  # the gallery runs from examples/gallery/

peak = run_sweep(Sweep.from_toml(EXAMPLES / "sweep.toml"), client=SERIAL)
fig, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
plot_sweep(peak, "peak_amplitude_m", ax=ax)
ax.set_title("peak of the stepped-sine response, examples/sweep.toml")
DOCS_FIGURES["sweep_peak_amplitude_map.png"] = fig

# %%
scatter = run_sweep(Sweep.from_toml(EXAMPLES / "tolerance.toml"), client=SERIAL)
fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2), layout="constrained")
plot_sweep(scatter, "natural_frequency_hz", ax=axes[0])
plot_sweep(scatter, "equivalent_damping_ratio", ax=axes[1])
for ax in axes:
    ax.set_title(ax.get_title().replace("free_cycle: ", "") + ", 1000 clearances")
DOCS_FIGURES["sweep_tolerance_histograms.png"] = fig
