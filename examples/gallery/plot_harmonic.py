"""
Harmonic balance against exact shooting, and a nonlinear mode against the paper's backbone
==========================================================================================

Two pictures of docs/harmonic.md. First, pyHarm's SDOF clearance case (m = 1, k0 = 1,
contact adds 3, gap edges at +-0.1745, c_v = 0.05, F0 = 0.03): the frequency-response
curve by harmonic balance with H = 12 (clearjoint.harmonic) and the exact one by shooting
(clearjoint.periodic), stable branches solid, unstable dashed. Second, the first nonlinear
mode (EPMC, H = 15) of the paper's joint with 2 % damping, against the exact free
frequency 1 / T(A) of MODEL.md section 1, placed by the orbit's x_max. The tables of that
page come from ``python docs/make_harmonic_figures.py``.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from clearjoint import Joint, Losses, stiffness
from clearjoint.harmonic import frequency_response, nonlinear_modes
from clearjoint.periodic import frequency_response as exact_response

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

PYHARM = Joint(mass=1.0, clearance=2 * 0.1745, compression_stiffness=3.0, gap_stiffness=1.0)
ZETA = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 0.05 as a damping ratio of the contact state
PAPER = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)

hb = frequency_response(
    PYHARM, 0.03, 0.5, 1.8, harmonics=12, losses=Losses(damping_ratio=ZETA), max_step=0.05
)
ex = exact_response(PYHARM, 0.03, 0.5, 1.8, losses=Losses(damping_ratio=ZETA))
print(hb)
print(ex)
fig, ax = plt.subplots(figsize=(7.0, 4.2), layout="constrained")
hb.plot(ax=ax)
ax.plot(ex.omega / (2 * math.pi), ex.amplitude * 1e3, ":", color="k", lw=1.0, label="exact")
ax.legend(frameon=False, fontsize="small")
ax.set_title("pyHarm's SDOF clearance case: harmonic balance (H = 12) and exact shooting")
DOCS_FIGURES["harmonic_frf.png"] = fig

# %%
# The nonlinear mode and the paper's dynamic stiffness as its backbone.

amplitudes = np.geomspace(50e-6, 3e-3, 40)
nm = nonlinear_modes(PAPER, 1, amplitudes, harmonics=15, losses=Losses(damping_ratio=0.02))
print(nm)
fig, ax = plt.subplots(figsize=(6.4, 4.0), layout="constrained")
nm.plot(ax=ax)
a = np.geomspace(1e-6, 3e-3, 200)
orbit = stiffness.free_orbit(PAPER, a)
# the EPMC amplitude is the fundamental; place the exact backbone by its x_max
ax.plot(
    np.interp(orbit.x_max, nm.x_max, nm.amplitude, left=np.nan, right=np.nan) * 1e6,
    1.0 / stiffness.period(PAPER, a),
    ":",
    color="k",
    label="2 pi / T(A) (paper, exact)",
)
ax.legend(frameon=False, fontsize="small", loc="lower right")
DOCS_FIGURES["harmonic_mode.png"] = fig
