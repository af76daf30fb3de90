"""
Identification's bias against noise level
=========================================

Records of an independent simulator, identified at growing noise levels: the error of the
clearance, contact stiffness, friction force and energy per cycle (mean of three noise
seeds), with and without an acceleration channel, at 40 and 100 Hz. Run it with
``python examples/gallery/plot_identify_noise.py``: it prints the table quoted in
docs/identify.md and draws docs/figures/identify_noise_bias.png.

The records come from tests/independent_joint.py of the repository (a scipy solve_ivp
model with a smoothed Coulomb friction, not the rig, not clearjoint.simulate), written in
clearjoint's CSV format with Gaussian noise of the given fraction of each channel's
standard deviation on every channel, with and without an acceleration channel; three noise
seeds per level.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

try:
    ROOT = Path(__file__).resolve().parents[2]
except NameError:  # sphinx-gallery runs the script from its own folder, without __file__
    ROOT = Path.cwd().resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the independent simulator lives with the tests

from clearjoint.identify import identify  # noqa: E402
from clearjoint.records import read_record  # noqa: E402
from independent_joint import TrueJoint, steady_truth, write_record  # noqa: E402

KEYS = {
    "clearance_m": "clearance",
    "compression_stiffness_n_per_m": "k_c",
    "tension_stiffness_n_per_m": "k_t",
    "friction_force_n": "friction",
    "energy_per_cycle_j": "energy",
}
LEVELS = (0.0, 0.0025, 0.005, 0.01, 0.02)
SEEDS = (1, 2, 3)


def noise_study():
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for frequency in (40.0, 100.0):
            joint = TrueJoint(frequency_hz=frequency)
            truth = steady_truth(joint)
            for acceleration in (True, False):
                for level in LEVELS:
                    errors = {k: [] for k in KEYS}
                    for seed in SEEDS:
                        path = write_record(
                            joint,
                            Path(folder) / "r.csv",
                            noise=level,
                            acceleration=acceleration,
                            seed=seed,
                        )
                        s = identify(read_record(path)).summary
                        for k in KEYS:
                            errors[k].append(s[k] / truth[k] - 1.0)
                    rows.append((frequency, acceleration, level, errors))
    print("| f (Hz) | acceleration | noise | " + " | ".join(KEYS.values()) + " |")
    print("|---|---|---|" + "---|" * len(KEYS))
    for frequency, acceleration, level, errors in rows:
        cells = [
            f"{100 * np.mean(errors[k]):+.2f} ± {100 * np.std(errors[k]):.2f}" for k in KEYS
        ]
        print(
            f"| {frequency:g} | {'yes' if acceleration else 'no'} | {100 * level:g} % | "
            + " | ".join(cells)
            + " |"
        )
    fig, axes = plt.subplots(1, len(KEYS), figsize=(16, 3.4), layout="constrained")
    for ax, (key, label) in zip(axes, KEYS.items(), strict=True):
        for frequency, acceleration, style in (
            (40.0, True, "C0-o"),
            (40.0, False, "C0--s"),
            (100.0, True, "C3-o"),
            (100.0, False, "C3--s"),
        ):
            sel = [r for r in rows if r[0] == frequency and r[1] == acceleration]
            levels = [100 * r[2] for r in sel]
            mean = [100 * np.mean(r[3][key]) for r in sel]
            ax.plot(
                levels,
                mean,
                style,
                ms=4,
                label=f"{frequency:g} Hz, {'with' if acceleration else 'no'} acceleration",
            )
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xlabel("noise on every channel (% of its std)")
        ax.set_title(label)
    axes[0].set_ylabel("error, mean of 3 seeds (%)")
    axes[-1].legend(fontsize=7)
    return fig


DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
DOCS_FIGURES["identify_noise_bias.png"] = noise_study()
