"""Regenerate the pictures in docs/figures/ from the library: ``python docs/make_figures.py``."""

from __future__ import annotations

from pathlib import Path

from clearjoint.figures import stiffness_coefficient_figure
from clearjoint.report import stiffness_study

HERE = Path(__file__).parent / "figures"


def main() -> None:
    HERE.mkdir(exist_ok=True)
    study = stiffness_study()
    fig = stiffness_coefficient_figure(
        study.curves, title="Stiffness coefficient against amplitude (paper Fig. 12)"
    )
    fig.savefig(HERE / "fig12_stiffness_coefficient.png", dpi=110)
    print(f"wrote {HERE / 'fig12_stiffness_coefficient.png'}")


if __name__ == "__main__":
    main()
