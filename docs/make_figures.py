"""Regenerate the pictures in docs/figures/ from the library: ``python docs/make_figures.py``."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from clearjoint import Friction, Joint, Pin
from clearjoint import dissipation as ds
from clearjoint.contact import HertzValidityWarning
from clearjoint.figures import (
    EnergyPanel,
    agreement_map_figure,
    displacement_stages_figure,
    dissipation_figure,
    force_displacement_figure,
    stiffness_coefficient_figure,
)
from clearjoint.report import example_cycle, stiffness_study
from clearjoint.simulate import SimulationError

HERE = Path(__file__).parent / "figures"


#: The losses of examples/study.toml.
LOSSES = {
    "damping_ratio": 0.01,
    "restitution": 0.8,
    "friction": Friction(0.2, 300.0),
    "contact_friction_coefficient": 0.15,
}


def _joint(clearance: float) -> Joint:
    return Joint(mass=2.0, clearance=clearance, compression_stiffness=8e7, tension_stiffness=5e7)


def dissipation_pictures() -> None:
    """Energies against amplitude for the paper's two clearances, and the agreement map.

    The largest forces push the pin's contact arc past Hertz's limit; the library
    warns of it at each such cycle, and docs/dissipation.md says so once.
    """
    warnings.simplefilter("ignore", HertzValidityWarning)
    panels = []
    for clearance in (0.106e-3, 0.196e-3):
        joint = _joint(clearance)
        pin = Pin.for_clearance(radius=5e-3, clearance=clearance, length=25e-3)
        grid = np.geomspace(2e-6, 3e-4, 80)
        closed = ds.energies(joint, grid, pin=pin, **LOSSES)  # type: ignore[arg-type]
        exact_a, exact = [], {key: [] for key in ds.ENERGY_KEYS if key.endswith("_j")}
        initial = None
        for force in np.geomspace(300.0, 8000.0, 24):
            try:
                result = ds.compare(
                    joint,
                    float(force),
                    2 * math.pi * 400.0,
                    pin=pin,
                    initial=initial,
                    samples_per_period=256,
                    max_periods=4000,
                    **LOSSES,
                )  # type: ignore[arg-type]
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
                closed=closed,
                exact_amplitude=np.array(exact_a),
                exact={key: np.array(val) for key, val in exact.items()},
            )
        )
    dissipation_figure(panels).savefig(HERE / "dissipation_vs_amplitude.png", dpi=110)
    joint = _joint(0.106e-3)
    pin = Pin.for_clearance(radius=5e-3, clearance=0.106e-3, length=25e-3)
    survey = ds.agreement_map(
        joint,
        2 * math.pi * np.linspace(100.0, 900.0, 17),
        np.linspace(200.0, 5000.0, 17),
        pin=pin,
        **LOSSES,
    )  # type: ignore[arg-type]
    fig = agreement_map_figure(
        survey.omega,
        survey.force,
        survey.gap["total_j"],
        survey.penetration,
        title="c = 0.106 mm: grey where the closed-form total\nis within 5 % of the exact cycle",
    )
    fig.savefig(HERE / "dissipation_agreement_map.png", dpi=110)
    inside = np.abs(survey.gap["total_j"]) <= 0.05
    print(
        f"agreement map: {int(np.sum(inside))} of {inside.size} points within 5 %, "
        f"{int(np.sum(np.isnan(survey.gap['total_j'])))} without a periodic orbit"
    )


def rig_picture() -> None:
    """One record of the default campaign, with the exact cycle's stages over its last cycles."""
    from clearjoint.rig import load_campaign, simulate_test, structure_under_test
    from clearjoint.simulate import steady_state

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
        damping_ratio=rig.damping_ratio,
        friction=rig.bearing_friction,
        restitution=rig.restitution,
    )
    period = 1.0 / spec.frequency_hz
    first = campaign.periods - 3
    stages = [
        (st.name, (first + k) * period + st.start, (first + k) * period + st.end)
        for k in range(3)
        for st in cycle.stages
    ]
    keep = record.time >= first * period
    fig = displacement_stages_figure(
        record.time[keep],
        record.displacement[keep],
        stages,
        title="Virtual rig, joint 1 (c = 0.106 mm), 1.6 kN at 40 Hz: the measured record",
    )
    fig.savefig(HERE / "rig_record_stages.png", dpi=110)
    restoring = record.force - record.mass * record.acceleration  # type: ignore[operator]
    fig = force_displacement_figure(
        record.displacement[keep],
        restoring[keep],
        label="force - m x'' (measured)",
        title="The same record: restoring force against displacement",
    )
    fig.axes[0].lines[0].set_linestyle("none")
    fig.axes[0].lines[0].set_marker(".")
    fig.axes[0].lines[0].set_markersize(2)
    fig.savefig(HERE / "rig_record_loop.png", dpi=110)


def periodic_pictures() -> None:
    """Whole frequency-response curves: pyHarm's SDOF case with eq 7, and a period doubling."""
    import matplotlib.pyplot as plt

    from clearjoint.periodic import frequency_response
    from clearjoint.stiffness import equivalent_linear_response

    joint = Joint(
        mass=1.0,
        clearance=2 * 0.1745,
        gap_stiffness=1.0,
        compression_stiffness=3.0,
        tension_stiffness=3.0,
    )
    zeta = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 0.05
    fr = frequency_response(joint, 0.03, 0.05, 1.8, damping_ratio=zeta)
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.2))
    fr.plot(axes[0])
    omegas = np.linspace(0.6, 1.8, 121)
    eq7 = [
        (w, b.displacement_amplitude)
        for w in omegas
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
    pd = frequency_response(one_sided, 1.0, 1.5, 4.5, damping_ratio=0.05)
    pd.plot(axes[1])
    axes[1].set_title("One-sided contact (k_c = 20 k0, F0 = 1): period doubling")
    fig.tight_layout()
    fig.savefig(HERE / "periodic_frequency_response.png", dpi=110)


def main() -> None:
    HERE.mkdir(exist_ok=True)
    fig = stiffness_coefficient_figure(
        stiffness_study(), title="Stiffness coefficient against amplitude (paper Fig. 12)"
    )
    fig.savefig(HERE / "fig12_stiffness_coefficient.png", dpi=110)
    print(f"wrote {HERE / 'fig12_stiffness_coefficient.png'}")

    # the exact steady cycle of examples/study.toml's joint, without the pin
    ss = example_cycle()
    stages = [(s.name, s.start, s.end) for s in ss.stages]
    fig = displacement_stages_figure(
        ss.time,
        ss.displacement,
        stages,
        title="Exact steady cycle, 1 kN at 400 Hz, c = 0.106 mm (paper Fig. 7)",
    )
    fig.savefig(HERE / "fig7_displacement_stages.png", dpi=110)
    fig = force_displacement_figure(
        ss.displacement,
        ss.excitation,
        label="excitation force F0 sin(wt)",
        title="Excitation force against displacement",
    )
    fig.savefig(HERE / "loop_force_displacement.png", dpi=110)
    print(f"wrote {HERE / 'fig7_displacement_stages.png'} and the loop")
    dissipation_pictures()
    print("wrote the dissipation pictures")
    rig_picture()
    print("wrote the rig pictures")
    periodic_pictures()
    print("wrote the periodic pictures")


if __name__ == "__main__":
    main()
