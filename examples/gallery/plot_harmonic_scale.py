"""
Harmonic balance on large structures: cost per curve point against the unknowns
===============================================================================

The figure of docs/harmonic.md, "Speed", "Structures at scale": the cost per point of the
issue-25 mast curve (H = 7, 0.1 N at the tip) and its stability verdict's share, against
the unknowns (2H + 1) N, log-log, with the fitted power law. The numbers are those
measured by ``python benchmarks/bench_scale.py --bays 5,10,20,40:30,80:10`` on
2026-11-28 (2 shared cores, load about 10; the 80-bay curve found no start): rerun it
and put its numbers here to redraw.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

#: (unknowns, s per point, of which the stability verdict s) for 10, 20 and 40 bays.
MEASURED = np.array(
    [
        (600, 0.1148, 0.0328),
        (1200, 0.3073, 0.1759),
        (2400, 5.1489, 4.6879),
    ]
)


def draw() -> plt.Figure:
    """Cost per point and the verdict's share against the unknowns, with the fit."""
    x, per_point, verdict = MEASURED.T
    slope, offset = np.polyfit(np.log(x), np.log(per_point), 1)
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.loglog(x, per_point, "o-", label="cost per point")
    ax.loglog(x, verdict, "s--", label="of which the stability verdict")
    ax.loglog(x, np.exp(offset) * x**slope, ":", label=f"fit ~ unknowns^{slope:.2f}")
    ax.set_xlabel("unknowns (2H + 1) N")
    ax.set_ylabel("s")
    ax.set_title("Harmonic balance on the mast, H = 7 (cost per curve point)")
    ax.legend()
    fig.tight_layout()
    return fig


DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
DOCS_FIGURES["harmonic_scale_growth.png"] = draw()
