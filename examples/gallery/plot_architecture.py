"""
How the code is organised: the layers and the way of one frf call
==================================================================

The picture of docs/develop/architecture.md: clearjoint's layers bottom to top (each
imports only from the layers below it; tests/test_architecture.py checks it) and, in red,
the way of ``clearjoint frf examples/frf.toml --from 10Hz --to 360Hz`` from the command
line down to the compiled law and back.
"""

from __future__ import annotations

import itertools

import matplotlib.pyplot as plt
from matplotlib.patches import FancyBboxPatch

#: The layers, bottom to top: (name, what it holds).
LAYERS = (
    ("units, checks", "units.py, io_toml.py, checks.py, errors.py"),
    ("laws", "laws/clearance.py: force, tangent, contact state"),
    ("joint, system", "joint.py (Joint, Losses), system.py (VibrationSystem)"),
    ("results", "results/: FrequencyResponse, PeriodicOrbit, Motion, ..."),
    ("continuation", "continuation.py: pseudo-arclength"),
    ("exact flow", "exact/: kernel, single, shooting, march"),
    ("solvers", "stiffness, simulate/, periodic, structure/,\nharmonic/, dissipation"),
    ("records, rig, identify", "records/, rig.py, identify/"),
    ("analysis", "fit, findings, verification"),
    ("studies", "studies/: study file + overrides -> objects -> run"),
    ("sweep, parallel", "sweep/, parallel.py"),
    ("output", "figures, report, reproduction"),
    ("cli", "cli.py, cli_parser.py: parse and print"),
)

#: The frf call, top to bottom: (layer index, label).
CALL = (
    (12, "cli: parse frf args"),
    (9, "studies: Joint, Losses,\nmethod; write netCDF"),
    (6, "periodic.frequency_response"),
    (5, "shooting, kernel: the exact map"),
    (4, "continue_branch along it"),
    (1, "clearance law (inlined)"),
    (3, "FrequencyResponse, back up"),
)


def draw() -> plt.Figure:
    """Return the architecture figure."""
    fig, ax = plt.subplots(figsize=(9.0, 7.2))
    height, gap, width = 0.46, 0.13, 6.2
    for i, (name, what) in enumerate(LAYERS):
        y = i * (height + gap)
        ax.add_patch(
            FancyBboxPatch(
                (0.0, y),
                width,
                height,
                boxstyle="round,pad=0.02",
                facecolor="#e8eef7" if i % 2 else "#d5e1f2",
                edgecolor="#4a6890",
            )
        )
        ax.text(0.12, y + height / 2, name, va="center", fontsize=11, fontweight="bold")
        ax.text(2.25, y + height / 2, what, va="center", fontsize=9)
    x = width + 0.35
    ys = [i * (height + gap) + height / 2 for i, _ in CALL]
    for (_, label), y in zip(CALL, ys, strict=True):
        ax.plot([width, x], [y, y], color="#b04020", lw=1.0)
        ax.text(x + 0.1, y, label, va="center", fontsize=9, color="#b04020")
    for y0, y1 in itertools.pairwise(ys[:6]):  # down to the law; the result goes back up
        ax.annotate(
            "",
            xy=(x, y1),
            xytext=(x, y0),
            arrowprops={"arrowstyle": "-|>", "color": "#b04020", "lw": 1.6},
        )
    ax.annotate(  # the result goes back up to studies
        "",
        xy=(x - 0.15, ys[1] - 0.1),
        xytext=(x - 0.15, ys[6]),
        arrowprops={"arrowstyle": "-|>", "color": "#b04020", "lw": 1.0, "ls": "--"},
    )
    top = len(LAYERS) * (height + gap)
    ax.text(
        x,
        top + 0.05,
        "clearjoint frf examples/frf.toml",
        fontsize=9,
        color="#b04020",
        family="monospace",
    )
    ax.text(0.0, top + 0.05, "imports point down only", fontsize=9, style="italic")
    ax.set_xlim(-0.1, x + 2.6)
    ax.set_ylim(-0.1, top + 0.35)
    ax.axis("off")
    fig.tight_layout()
    return fig


DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
DOCS_FIGURES["architecture.png"] = draw()
