"""
A 10-bay deployable mast with 20 clearance joints
=================================================

The planar mast of ``clearjoint.structure.mast``: a hinge joint (clearance 50 um, contact
stiffness 5e7 N/m, k0 = 1e5 N/m) in series with each longeron. Its first modes with every
joint closed and every joint open, its exact free decay from a 3 mm tip deflection along
closed mode 1, and the first mode's frequency and damping against amplitude read from
that decay cycle by cycle (docs/structure.md).
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from clearjoint import ClearanceJoint
from clearjoint.structure import decay_backbone, free_decay, mast

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
CYCLES = 80  # closed-mode periods of free decay

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
DOCS_FIGURES["structure_mast.png"] = fig

# %%
# Linear modes with every joint closed and every joint open bound the nonlinear ones.
closed, opened = tower.modes("closed"), tower.modes("open")
fig, axes = plt.subplots(1, 2, figsize=(9, 6))
closed.plot(axes[0])
opened.plot(axes[1])
fig.tight_layout()
DOCS_FIGURES["structure_modes.png"] = fig

# %%
# The exact free decay (every gap edge an event) and its per-cycle backbone.
tip = tower.dof_names.index("n21x")
shape = closed.shapes[:, 0]
u0 = 3e-3 * shape / shape[tip]
period = 2 * math.pi / closed.omega[0]
decay = free_decay(tower, (u0, np.zeros(tower.n_dof)), CYCLES * period, samples_per_period=64)
print(repr(decay))
fig, ax = plt.subplots(figsize=(7, 3.5))
decay.plot(ax, dof=tip)
ax.set_title("free decay of the tip from 3 mm along closed mode 1")
fig.tight_layout()
DOCS_FIGURES["structure_decay.png"] = fig

backbone = decay_backbone(decay, tip, mode=1)  # the tip's share of closed mode 1
print(repr(backbone))
fig, ax = plt.subplots(figsize=(6, 4))
backbone.plot(ax)
ax.axhline(closed.frequency_hz[0], color="0.5", ls=":", label="closed mode 1")
ax.set_xscale("log")
ax.set_title("first mode: frequency and damping against tip amplitude")
ax.legend(loc="lower right", fontsize="small")
fig.tight_layout()
DOCS_FIGURES["structure_backbone.png"] = fig
