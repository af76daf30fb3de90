"""
Harmonic balance on large structures: cost per curve point against the unknowns
===============================================================================

The figure of docs/harmonic.md, "Speed", "Structures at scale": the cost per point of the
issue-25 mast curve (H = 7, 0.1 N at the tip) and its stability verdict's time per point,
against the unknowns (2H + 1) N, log-log, with the fitted power law. The numbers are read
from ``examples/bench_scale.json``, the table ``benchmarks/bench_scale.py --json`` wrote
(the command, date and load are in the file and in the title); rerun that command with
``--json examples/bench_scale.json`` to redraw with new measurements.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

HERE = Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd()
TABLE = HERE.parent / "bench_scale.json"  # the gallery runs from examples/gallery/


def draw(table: dict) -> plt.Figure:
    """Cost per point and the verdict's time per point against the unknowns, with the fit
    over the sizes the benchmark fitted (from 10 bays up)."""
    sizes = table["sizes"]
    x = np.array([s["unknowns"] for s in sizes], dtype=float)
    per_point = np.array([s["per_point"] for s in sizes])
    verdict = np.array([s["verdict_per_point"] for s in sizes])
    fitted = np.isin([s["bays"] for s in sizes], table["fit"]["bays"])
    slope, offset = np.polyfit(np.log(x[fitted]), np.log(per_point[fitted]), 1)
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.loglog(x, per_point, "o-", label="cost per point")
    ax.loglog(x, np.maximum(verdict, 1e-6), "s--", label="of which the stability verdict")
    xf = x[fitted]
    ax.loglog(xf, np.exp(offset) * xf**slope, ":", label=f"fit ~ unknowns^{slope:.2f}")
    for s, xi, yi in zip(sizes, x, per_point, strict=True):
        ax.annotate(f"{s['bays']} bays", (xi, yi), textcoords="offset points", xytext=(4, 4))
    ax.set_xlabel("unknowns (2H + 1) N")
    ax.set_ylabel("s")
    ax.set_title(f"Harmonic balance on the mast, H = {table['harmonics']} ({table['date'][:10]})")
    ax.legend()
    fig.tight_layout()
    return fig


DOCS_FIGURES = {}  # figures of the docs this script draws, by file name in docs/figures/
DOCS_FIGURES["harmonic_scale_growth.png"] = draw(json.loads(TABLE.read_text()))
