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
from clearjoint.figures import Curve, stiffness_coefficient_figure
from clearjoint.stiffness import stiffness_curve

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

amplitude = np.linspace(0.0, 0.5e-3, 300)  # penetration A beyond the gap edge, m
curves = []
for clearance in (0.106e-3, 0.196e-3):  # the paper's two joints, m = 2 kg, k_c = 80 MN/m
    joint = Joint(mass=2.0, clearance=clearance, compression_stiffness=8e7)
    c_d = stiffness_curve(joint, amplitude).stiffness_coefficient
    curves.append(Curve(amplitude, c_d, f"c = {clearance * 1e3:.3f} mm, eq 9 (k0 = 0)"))
for clearance in (0.106e-3, 0.196e-3):  # a little stiffness in the gap, a softer tension side
    joint = Joint(
        mass=2.0,
        clearance=clearance,
        compression_stiffness=8e7,
        tension_stiffness=0.7 * 8e7,
        gap_stiffness=0.05 * 8e7,
    )
    c_d = stiffness_curve(joint, amplitude).stiffness_coefficient
    label = f"c = {clearance * 1e3:.3f} mm, exact, k0 = 0.05 k_c, k_t = 0.7 k_c"
    curves.append(Curve(amplitude, c_d, label))
fig = stiffness_coefficient_figure(
    curves, title="Stiffness coefficient against amplitude (paper Fig. 12)"
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
