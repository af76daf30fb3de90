"""The paper's figures as matplotlib Figures (MODEL.md section 4), readable in grey print.

One function per figure; each takes results (arrays in SI) and returns a
Figure. Axes are labelled in engineering units (um, mm, Hz).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

#: Line styles that stay apart in grey print, cycled per curve.
_STYLES: tuple[tuple[Any, str], ...] = (
    ("-", "black"),
    ("--", "0.35"),
    ("-.", "black"),
    (":", "0.2"),
    ((0, (5, 1, 1, 1, 1, 1)), "0.45"),
)


@dataclass(frozen=True)
class Curve:
    """One labelled curve: x and y arrays in SI, and its legend label."""

    x: NDArray[np.float64]
    y: NDArray[np.float64]
    label: str


def stiffness_coefficient_figure(curves: Sequence[Curve], *, title: str | None = None) -> Figure:
    """Return the paper's Fig. 12: the stiffness coefficient c_d against the amplitude A.

    Parameters
    ----------
    curves : sequence of Curve
        Each with x = penetration A in m (plotted in um) and y = c_d.
    title : str, optional
    """
    fig = Figure(figsize=(6.0, 4.0), layout="constrained")
    ax = fig.add_subplot()
    for i, curve in enumerate(curves):
        style, colour = _STYLES[i % len(_STYLES)]
        ax.plot(curve.x * 1e6, curve.y, linestyle=style, color=colour, lw=1.6, label=curve.label)
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel("amplitude beyond the gap edge A (µm)")
    ax.set_ylabel("stiffness coefficient $c_d = k_d / k_\\infty$")
    ax.set_ylim(0.0, 1.05)
    ax.set_xlim(left=0.0)
    ax.grid(True, color="0.85", lw=0.6)
    ax.legend(frameon=False)
    if title:
        ax.set_title(title)
    return fig
