"""
Energy dissipated per cycle: closed forms against the exact cycle
=================================================================

Each mechanism's energy per cycle (MODEL.md eq 10-17) against the penetration A for the
paper's two clearances: the closed forms on the free cycle (lines) and the integrals over
exact forced steady cycles (markers, 400 Hz, the force stepped upward). Then where over
(frequency, force) the closed-form total is within 5 % of the exact cycle.

The largest forces push the pin's contact arc past Hertz's limit; the library warns of it
at each such cycle, and docs/dissipation.md says so once, so the warning is silenced here.
"""

import math
import warnings

import matplotlib.pyplot as plt
import numpy as np

from clearjoint import Friction, Joint, Losses, Pin
from clearjoint import dissipation as ds
from clearjoint.contact import HertzValidityWarning
from clearjoint.figures import EnergyPanel, agreement_map_figure, dissipation_figure
from clearjoint.simulate import SimulationError

DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
warnings.simplefilter("ignore", HertzValidityWarning)

#: The losses of examples/study.toml.
LOSSES = {
    "damping_ratio": 0.01,
    "restitution": 0.8,
    "friction": Friction(0.2, 300.0),
    "contact_friction_coefficient": 0.15,
}


def joint_with(clearance):
    return Joint(mass=2.0, clearance=clearance, compression_stiffness=8e7, tension_stiffness=5e7)


panels = []
for clearance in (0.106e-3, 0.196e-3):
    joint = joint_with(clearance)
    pin = Pin.for_clearance(radius=5e-3, clearance=clearance, length=25e-3)
    grid = np.geomspace(2e-6, 3e-4, 80)
    closed = ds.energies(joint, grid, losses=Losses(pin=pin, **LOSSES))
    exact_a, exact = [], {key: [] for key in ds.ENERGY_KEYS if key.endswith("_j")}
    initial = None
    for force in np.geomspace(300.0, 8000.0, 24):
        try:
            result = ds.compare(
                joint,
                float(force),
                2 * math.pi * 400.0,
                losses=Losses(pin=pin, **LOSSES),
                initial=initial,
                samples_per_period=256,
                max_periods=4000,
            )
        except SimulationError:
            continue
        initial = result.cycle.initial_state
        if result.penetration <= 0.0:
            continue
        exact_a.append(result.penetration)
        for key in exact:
            exact[key].append(result.exact[key])
    panels.append(
        EnergyPanel(
            title=f"c = {clearance * 1e3:.3f} mm (exact: 400 Hz, F0 stepped)",
            amplitude=grid,
            closed=dict(closed),
            exact_amplitude=np.array(exact_a),
            exact={key: np.array(val) for key, val in exact.items()},
        )
    )
DOCS_FIGURES["dissipation_vs_amplitude.png"] = dissipation_figure(panels)

# %%
# Where the closed forms hold
# ---------------------------

joint = joint_with(0.106e-3)
pin = Pin.for_clearance(radius=5e-3, clearance=0.106e-3, length=25e-3)
survey = ds.agreement_map(
    joint,
    2 * math.pi * np.linspace(100.0, 900.0, 17),
    np.linspace(200.0, 5000.0, 17),
    losses=Losses(pin=pin, **LOSSES),
)
DOCS_FIGURES["dissipation_agreement_map.png"] = agreement_map_figure(
    survey.omega,
    survey.force,
    survey.gap["total_j"],
    survey.penetration,
    title="c = 0.106 mm: grey where the closed-form total\nis within 5 % of the exact cycle",
)
inside = np.abs(survey.gap["total_j"]) <= 0.05
print(
    f"agreement map: {int(np.sum(inside))} of {inside.size} points within 5 %, "
    f"{int(np.sum(np.isnan(survey.gap['total_j'])))} without a periodic orbit"
)

# %%
# The energies as a result object
# -------------------------------
# ``energies`` returns an ``Energies``: still a mapping by key, with a summary, a table and
# its own log-log plot.

values = ds.energies(joint, np.geomspace(2e-6, 1e-4, 40), losses=Losses(pin=pin, **LOSSES))
print(values)
print(values.to_pandas()[["impact_j", "total_j", "loss_factor"]].iloc[::13])
ax = values.plot()
ax.set_title("Energies.plot(), c = 0.106 mm")
plt.show()
