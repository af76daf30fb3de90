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


#: Grey levels of the stages, light enough to print the curve over them.
STAGE_SHADES = {"free-play": "0.93", "compression": "0.72", "tension": "0.83"}
STAGE_HATCHES = {"free-play": "", "compression": "//", "tension": ".."}


def displacement_stages_figure(
    time: NDArray[np.float64],
    displacement: NDArray[np.float64],
    stages: Sequence[tuple[str, float, float]],
    *,
    title: str | None = None,
) -> Figure:
    """Return the paper's Fig. 7: a displacement record with its stages shaded.

    Parameters
    ----------
    time, displacement : (N,) ndarray
        s and m (plotted in ms and um).
    stages : sequence of (name, start, end)
        name in {"free-play", "compression", "tension"}, times in s.
    """
    fig = Figure(figsize=(7.0, 4.0), layout="constrained")
    ax = fig.add_subplot()
    seen: set[str] = set()
    for name, start, end in stages:
        ax.axvspan(
            start * 1e3,
            end * 1e3,
            facecolor=STAGE_SHADES.get(name, "white"),
            hatch=STAGE_HATCHES.get(name, ""),
            edgecolor="0.55",
            lw=0.0,
            label=None if name in seen else name,
        )
        seen.add(name)
    ax.plot(time * 1e3, displacement * 1e6, color="black", lw=1.4, label="displacement")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("displacement x (µm)")
    ax.set_xlim(time[0] * 1e3, time[-1] * 1e3)
    ax.legend(
        frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=4, fontsize="small"
    )
    if title:
        ax.set_title(title)
    return fig


def force_displacement_figure(
    displacement: NDArray[np.float64],
    force: NDArray[np.float64],
    *,
    label: str = "restoring force",
    title: str | None = None,
) -> Figure:
    """Return a force-displacement loop (force in N against displacement in um)."""
    fig = Figure(figsize=(5.0, 4.0), layout="constrained")
    ax = fig.add_subplot()
    x = np.append(displacement, displacement[:1]) * 1e6
    f = np.append(force, force[:1])
    ax.plot(x, f, color="black", lw=1.4, label=label)
    ax.axhline(0.0, color="0.7", lw=0.6)
    ax.axvline(0.0, color="0.7", lw=0.6)
    ax.set_xlabel("displacement x (µm)")
    ax.set_ylabel("force (N)")
    ax.legend(frameon=False)
    if title:
        ax.set_title(title)
    return fig
