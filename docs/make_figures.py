"""Regenerate the pictures in docs/figures/ from the library: ``python docs/make_figures.py``."""

from __future__ import annotations

from pathlib import Path

from clearjoint.figures import (
    displacement_stages_figure,
    force_displacement_figure,
    stiffness_coefficient_figure,
)
from clearjoint.report import example_cycle, stiffness_study

HERE = Path(__file__).parent / "figures"


def main() -> None:
    HERE.mkdir(exist_ok=True)
    study = stiffness_study()
    fig = stiffness_coefficient_figure(
        study.curves, title="Stiffness coefficient against amplitude (paper Fig. 12)"
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


if __name__ == "__main__":
    main()
