"""Draw the figures of docs/sweep.md from the shipped sweep files.

Run on demand: ``python docs/make_sweep_figures.py`` (a LocalCluster of 2 workers;
about a minute on 2 cores). Writes docs/figures/sweep_*.png.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from clearjoint.sweep import Sweep, run_sweep
from clearjoint.sweep.plot import plot_sweep

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"
FIGURES = HERE / "figures"


def main() -> None:
    FIGURES.mkdir(exist_ok=True)
    peak = run_sweep(Sweep.from_toml(EXAMPLES / "sweep.toml"), workers=2)
    ax = plot_sweep(peak, "peak_amplitude_m")
    ax.set_title("peak of the stepped-sine response, examples/sweep.toml")
    ax.figure.savefig(FIGURES / "sweep_peak_amplitude_map.png", dpi=110)
    plt.close(ax.figure)

    scatter = run_sweep(Sweep.from_toml(EXAMPLES / "tolerance.toml"), workers=2)
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2), layout="constrained")
    plot_sweep(scatter, "natural_frequency_hz", ax=axes[0])
    plot_sweep(scatter, "equivalent_damping_ratio", ax=axes[1])
    for ax in axes:
        ax.set_title(ax.get_title().replace("free_cycle: ", "") + ", 1000 clearances")
    fig.savefig(FIGURES / "sweep_tolerance_histograms.png", dpi=110)
    plt.close(fig)


if __name__ == "__main__":  # LocalCluster workers are spawned processes: keep this guard
    main()
