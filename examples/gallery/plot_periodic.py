"""
Whole frequency-response curves of exact periodic orbits
========================================================

Left: pyHarm's SDOF clearance case (m = 1, c_v = 0.05, k0 = 1, gap edges at +-0.1745,
contact adds 3, F0 = 0.03) followed by continuation of the exact period-1 orbit
(``clearjoint.periodic.frequency_response``): stable orbits solid, unstable dashed,
folds and grazings marked, and the eq 7 shortcut (grey dots) for comparison. Right: a
one-sided soft contact whose period-1 orbit loses stability through a period doubling
and regains it (MODEL.md sec. 5.1).
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from clearjoint import Joint, Losses
from clearjoint.periodic import frequency_response
from clearjoint.stiffness import equivalent_linear_response

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

joint = Joint(
    mass=1.0,
    clearance=2 * 0.1745,
    gap_stiffness=1.0,
    compression_stiffness=3.0,
    tension_stiffness=3.0,
)
zeta = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 2 zeta sqrt(m k_c) = 0.05
curve = frequency_response(joint, 0.03, 0.05, 1.8, losses=Losses(damping_ratio=zeta))
print(curve)

fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.2))
curve.plot(axes[0])
eq7 = [
    (w, b.displacement_amplitude)
    for w in np.linspace(0.6, 1.8, 121)
    for b in equivalent_linear_response(joint, 0.03, float(w), zeta, method="period")
]
axes[0].plot(
    [w / (2 * math.pi) for w, _ in eq7],
    [x * 1e3 for _, x in eq7],
    ".",
    ms=2.5,
    color="0.5",
    label="eq 7 (k_d(A))",
)
axes[0].legend(frameon=False, fontsize="small")
axes[0].set_title("pyHarm's SDOF clearance case (m = 1, c_v = 0.05, F0 = 0.03)")

one_sided = Joint(
    mass=1.0,
    clearance=0.2,
    gap_stiffness=1.0,
    compression_stiffness=20.0,
    tension_stiffness=1e-3,
)
doubling = frequency_response(one_sided, 1.0, 1.5, 4.5, losses=Losses(damping_ratio=0.05))
print(doubling)
doubling.plot(axes[1])
axes[1].set_title("One-sided contact (k_c = 20 k0, F0 = 1): period doubling")
fig.tight_layout()
DOCS_FIGURES["periodic_frequency_response.png"] = fig
