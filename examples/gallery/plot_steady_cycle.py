"""
The exact steady cycle and its stages (the paper's Fig. 7)
==========================================================

The forced joint of ``examples/study.toml`` (1 kN at 400 Hz, c = 0.106 mm, no pin),
integrated exactly event by event until its orbit repeats: displacement against time with
the free-play, compression and tension stages, and the excitation force against
displacement.
"""

import math

import matplotlib.pyplot as plt

from clearjoint import Friction, Joint, Losses
from clearjoint.figures import displacement_stages_figure, force_displacement_figure
from clearjoint.simulate import steady_state

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

joint = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, tension_stiffness=5e7)
cycle = steady_state(
    joint,
    1000.0,  # F0, N
    2 * math.pi * 400.0,  # omega, rad/s
    losses=Losses(damping_ratio=0.01, restitution=0.8, friction=Friction(0.2, 300.0)),
    samples_per_period=512,
)
print(cycle)  # a SteadyState: its short summary

stages = [(s.name, s.start, s.end) for s in cycle.stages]
fig = displacement_stages_figure(
    cycle.time,
    cycle.displacement,
    stages,
    title="Exact steady cycle, 1 kN at 400 Hz, c = 0.106 mm (paper Fig. 7)",
)
DOCS_FIGURES["fig7_displacement_stages.png"] = fig

# %%
fig = force_displacement_figure(
    cycle.displacement,
    cycle.excitation,
    label="excitation force F0 sin(wt)",
    title="Excitation force against displacement",
)
DOCS_FIGURES["loop_force_displacement.png"] = fig

# %%
# The same result, as data
# ------------------------
# ``to_xarray()`` carries every array with its unit (and the energy ledger); ``plot()``
# draws x(t) with the contact stages shaded.

data = cycle.to_xarray()
print(data["displacement"].attrs["units"], float(data["energy_input"]), "J per orbit")
ax = cycle.plot()
ax.set_title("SteadyState.plot()")
plt.show()
