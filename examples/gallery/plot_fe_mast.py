"""
Your own finite-element model: a 3-D mast from OpenSees, reduced onto its joints
================================================================================

The 20-bay triangular mast of ``examples/opensees_mast.py``, built in OpenSees (frame
elements, lumped masses, 363 DOFs) and shipped as Matrix Market files, with a clearance
joint (50 um, 2e7 N/m, k0 = 2e5 N/m) in each longeron hinge at mid-height. The model
file ``examples/opensees_mast.toml`` reads the matrices, adds the joints and reduces the
mast onto them (Craig-Bampton, 20 fixed-interface modes): 28 DOFs. Its reduction check,
the first closed modes drawn on the full mast, its nonlinear first mode and the tip's
frequency response by harmonic balance (docs/fe_models.md).
"""

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from clearjoint.harmonic import frequency_response, nonlinear_modes
from clearjoint.structure import read_model
from clearjoint.structure.model import system_modes

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
HERE = Path.cwd()  # sphinx-gallery and docs/make_figures.py run it in examples/gallery
EXAMPLES = HERE.parent if HERE.name == "gallery" else HERE / "examples"

reduced = read_model(EXAMPLES / "opensees_mast.toml")
full = reduced.full
print(repr(reduced))
nodes = np.loadtxt(EXAMPLES / "opensees_mast" / "nodes.csv", delimiter=",", skiprows=1)
where = {int(row[0]): row[1:] for row in nodes}


def node_motion(u):
    """(tag, x, z, u_x) of each node that has an x DOF, from a full-model vector."""
    out = []
    for k, name in enumerate(full.dof_names):
        tag, dof = name[1:].split("d")
        if dof == "1":
            x, _, z = where[int(tag)]
            out.append((x, z, u[k]))
    return np.array(out)


# %%
# The check: the reduced model's closed and open modes against the full model's.
check = reduced.check(8)
print(repr(check))
fig, ax = plt.subplots(figsize=(5, 3.5))
check.plot(ax)
ax.set_title("Craig-Bampton, 20 fixed-interface modes: 28 of 363 DOFs")
fig.tight_layout()
DOCS_FIGURES["fe_mast_check.png"] = fig

# %%
# Closed modes 1 and 3 (mode 2 is mode 1 turned by 90 degrees: the section is symmetric),
# expanded onto every DOF and drawn in the x-z plane; the hinge level in red.
closed = system_modes(reduced, "closed")
fig, ax = plt.subplots(figsize=(5, 6))
xz = node_motion(np.zeros(full.n_dof))
ax.plot(xz[:, 0], xz[:, 1], "o", color="0.7", ms=3, label="nodes (undeformed)")
for k in (0, 2):
    u = reduced.expand(closed.shapes[:, k])
    motion = node_motion(u)
    scale = 0.3 / np.max(np.abs(motion[:, 2]))
    ax.plot(
        motion[:, 0] + scale * motion[:, 2],
        motion[:, 1],
        ".",
        color=f"C{k}",
        label=f"closed mode {k + 1}: {closed.frequency_hz[k]:.3g} Hz",
    )
hinge_z = 5.0
ax.axhline(hinge_z, color="C3", lw=0.8, ls=":", label="longeron hinges (3 joints)")
ax.set_xlabel("x (m), mode shapes scaled")
ax.set_ylabel("z (m)")
ax.legend(fontsize="small", loc="lower left")
fig.tight_layout()
DOCS_FIGURES["fe_mast_modes.png"] = fig

# %%
# The nonlinear first mode (EPMC, H = 5) against the tip's amplitude: from the open
# pattern's 2.72 Hz up toward the closed one's as the hinges close.
tip = full.dof_names.index("n2001d1")
on_tip = reduced.basis[tip]  # u_tip = basis[tip] . q
tip_amplitudes = np.geomspace(2e-5, 1e-2, 14)
mode = nonlinear_modes(reduced, 1, tip_amplitudes / abs(on_tip[0]), harmonics=5)
coefficients = mode.harmonic_shapes @ on_tip
tip_amplitude = np.hypot(coefficients[:, 1], coefficients[:, 2])
fig, ax = plt.subplots(figsize=(5.5, 3.5))
ax.semilogx(1e3 * tip_amplitude, mode.frequency / (2 * math.pi), "o-", label="nonlinear mode 1")
open_hz = system_modes(reduced, "open").frequency_hz[0]
for value, label in ((closed.frequency_hz[0], "closed"), (open_hz, "open")):
    ax.axhline(value, color="0.5", ls=":", lw=0.8)
    ax.annotate(
        f"{label} {value:.3g} Hz", (1e3 * tip_amplitude[0], value), fontsize="small", va="bottom"
    )
ax.set_xlabel("tip amplitude (mm, fundamental)")
ax.set_ylabel("frequency (Hz)")
ax.set_title("first mode of the OpenSees mast")
fig.tight_layout()
DOCS_FIGURES["fe_mast_backbone.png"] = fig

# %%
# The tip's frequency response to 0.05 N at the tip along x (H = 3), by continuation
# through its folds; Hill's method marks the unstable stretches (dashed).
force = np.zeros(full.n_dof)
force[tip] = 0.05
curve = frequency_response(
    reduced,
    reduced.project_force(force),
    2 * math.pi * 2.5,
    2 * math.pi * 4.5,
    harmonics=3,
    max_points=1500,
    max_step=0.05,
    check_points=0,
)
print(repr(curve))
coefficients = curve.coefficients @ on_tip
hz = curve.omega / (2 * math.pi)
mm = 1e3 * np.hypot(coefficients[:, 1], coefficients[:, 2])
fig, ax = plt.subplots(figsize=(5.5, 3.5))
ax.plot(hz, np.where(curve.stable, mm, np.nan), color="C0", label="stable")
ax.plot(hz, np.where(curve.stable, np.nan, mm), color="C0", ls="--", lw=0.8, label="unstable")
ax.legend(fontsize="small")
ax.set_xlabel("forcing frequency (Hz)")
ax.set_ylabel("tip amplitude (mm, fundamental)")
ax.set_title("0.05 N at the tip: the hinges stiffen the mast")
fig.tight_layout()
DOCS_FIGURES["fe_mast_frf.png"] = fig
