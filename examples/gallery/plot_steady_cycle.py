"""
The exact steady cycle and its stages (the paper's Fig. 7)
==========================================================

The forced joint of ``examples/study.toml`` (1 kN at 400 Hz, c = 0.106 mm, no pin),
integrated exactly event by event until its orbit repeats: displacement against time with
the free-play, compression and tension stages, and the excitation force against
displacement.
"""

import matplotlib.pyplot as plt

from clearjoint.figures import displacement_stages_figure, force_displacement_figure
from clearjoint.report import example_cycle

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

cycle = example_cycle()
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
