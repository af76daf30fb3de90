"""Figures of docs/structure.md: the 10-bay mast, its modes, a free decay and its backbone.

Run: ``OPENBLAS_NUM_THREADS=1 python docs/make_structure_figures.py`` (a few minutes on
2 cores). Writes docs/figures/structure_*.png.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from clearjoint import ClearanceJoint
from clearjoint.structure import decay_backbone, free_decay, mast

OUT = Path(__file__).parent / "figures"
CYCLES = 80


def main() -> None:
    OUT.mkdir(exist_ok=True)
    hinge = ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)
    tower = mast(10, joints=hinge, rayleigh=(0.5, 2e-6))

    fig, ax = plt.subplots(figsize=(3.5, 6))
    tower.draw(ax, color="k", lw=1)
    for i in tower.joint_members:
        m = tower.members[i]
        mid = 0.5 * (tower.nodes[m.start] + tower.nodes[m.end])
        ax.plot(*mid, "o", color="C3", ms=5)
    ax.set_title("10-bay mast: 20 hinge joints (red)")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.tight_layout()
    fig.savefig(OUT / "structure_mast.png", dpi=110)

    closed, opened = tower.modes("closed"), tower.modes("open")
    fig, axes = plt.subplots(1, 2, figsize=(9, 6))
    closed.plot(axes[0])
    opened.plot(axes[1])
    fig.tight_layout()
    fig.savefig(OUT / "structure_modes.png", dpi=110)

    tip = tower.dof_names.index("n21x")
    shape = closed.shapes[:, 0]
    u0 = 3e-3 * shape / shape[tip]
    period = 2 * math.pi / closed.omega[0]
    start = time.perf_counter()
    decay = free_decay(tower, (u0, np.zeros(tower.n_dof)), CYCLES * period, samples_per_period=64)
    print(f"free decay: {time.perf_counter() - start:.0f} s, {decay!r}")
    fig, ax = plt.subplots(figsize=(7, 3.5))
    decay.plot(ax, dof=tip)
    ax.set_title("free decay of the tip from 3 mm along closed mode 1")
    fig.tight_layout()
    fig.savefig(OUT / "structure_decay.png", dpi=110)

    backbone = decay_backbone(decay, tip)
    print(repr(backbone))
    fig, ax = plt.subplots(figsize=(6, 4))
    backbone.plot(ax)
    ax.axhline(closed.frequency_hz[0], color="0.5", ls=":", label="closed mode 1")
    ax.set_xscale("log")
    ax.set_title("first mode: frequency and damping against tip amplitude")
    ax.legend(loc="lower right", fontsize="small")
    fig.tight_layout()
    fig.savefig(OUT / "structure_backbone.png", dpi=110)


if __name__ == "__main__":
    main()
