"""
A record of the virtual test rig
================================

One test of the default campaign (joint 1, c = 0.106 mm, 1.6 kN at 40 Hz) as the rig's
sensors record it, over its last three cycles, with the exact cycle's stages shaded; then
the same record's restoring force (force - m x'') against displacement.
"""

import math

import numpy as np

from clearjoint.figures import displacement_stages_figure, force_displacement_figure
from clearjoint.rig import load_campaign, simulate_test, structure_under_test
from clearjoint.simulate import steady_state

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/

campaign = load_campaign()
spec = next(t for t in campaign.tests if t.file_stem == "joint-1_40Hz_1600N")
seed = np.random.SeedSequence(campaign.seed).spawn(len(campaign.tests))[spec.index]
record, _ = simulate_test(campaign.rig, spec, campaign.periods, seed)
joint, _, _ = structure_under_test(campaign.rig, spec)
rig = campaign.rig
cycle = steady_state(
    joint,
    spec.force_amplitude,
    2 * math.pi * spec.frequency_hz,
    losses=rig.losses(),
)
period = 1.0 / spec.frequency_hz
first = campaign.periods - 3
stages = [
    (st.name, (first + k) * period + st.start, (first + k) * period + st.end)
    for k in range(3)
    for st in cycle.stages
]
keep = record.time >= first * period
DOCS_FIGURES["rig_record_stages.png"] = displacement_stages_figure(
    record.time[keep],
    record.displacement[keep],
    stages,
    title="Virtual rig, joint 1 (c = 0.106 mm), 1.6 kN at 40 Hz: the measured record",
)

# %%
restoring = record.force - record.mass * record.acceleration
fig = force_displacement_figure(
    record.displacement[keep],
    restoring[keep],
    label="force - m x'' (measured)",
    title="The same record: restoring force against displacement",
)
line = fig.axes[0].lines[0]
line.set_linestyle("none")
line.set_marker(".")
line.set_markersize(2)
DOCS_FIGURES["rig_record_loop.png"] = fig
