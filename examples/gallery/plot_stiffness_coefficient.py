"""
Stiffness coefficient against amplitude (the paper's Fig. 12)
=============================================================

The dynamic stiffness of a joint with clearance rises with the amplitude: c_d = k_d / k_inf
(MODEL.md eq 9) for the paper's two clearances, by eq 9 (k0 = 0) and exactly for a joint
with a little stiffness inside the gap and a softer tension side (eq 5).
"""

import matplotlib.pyplot as plt
import numpy as np

from clearjoint import Joint
from clearjoint.figures import stiffness_coefficient_figure
from clearjoint.report import stiffness_study
from clearjoint.stiffness import stiffness_curve

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

fig = stiffness_coefficient_figure(
    stiffness_study(), title="Stiffness coefficient against amplitude (paper Fig. 12)"
)
DOCS_FIGURES["fig12_stiffness_coefficient.png"] = fig

# %%
# One joint as a result object
# ----------------------------
# ``stiffness_curve`` returns what ``clearjoint stiffness`` prints, as one object: a short
# summary, a table, an ``xarray.Dataset`` with units, and its own plot.

joint = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
curve = stiffness_curve(joint, np.linspace(0.0, 300e-6, 61))
print(curve)
print(curve.to_pandas().iloc[::15])

# %%
ax = curve.plot()
ax.set_title("c_d of one joint: StiffnessCurve.plot()")
plt.show()
