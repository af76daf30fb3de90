"""The paper's figures as matplotlib Figures (MODEL.md section 4), readable in grey print.

One function per figure; each takes results (arrays in SI) and returns a
Figure. Axes are labelled in engineering units (um, mm, Hz).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from clearjoint import fit
from clearjoint.analysis import Analysis, side_data, tests_of

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


#: Line styles and markers of the energy mechanisms, apart in grey print.
MECHANISM_STYLES: dict[str, tuple[str, str, str]] = {
    "sliding_friction_j": ("sliding friction", "-", "o"),
    "contact_friction_j": ("contact friction (pin)", "--", "s"),
    "impact_j": ("impact", "-.", "^"),
    "viscous_j": ("viscous", ":", "v"),
    "total_j": ("total", "-", "D"),
}


@dataclass(frozen=True)
class EnergyPanel:
    """One panel of energies against amplitude: closed-form curves and exact points (SI)."""

    title: str
    amplitude: NDArray[np.float64]
    closed: dict[str, NDArray[np.float64]]
    exact_amplitude: NDArray[np.float64]
    exact: dict[str, NDArray[np.float64]]


def dissipation_figure(panels: Sequence[EnergyPanel]) -> Figure:
    """Return each mechanism's energy per cycle against A: closed form (lines), exact (markers)."""
    fig = Figure(figsize=(5.2 * len(panels), 4.4), layout="constrained")
    axes = fig.subplots(1, len(panels), sharey=True, squeeze=False)[0]
    for ax, panel in zip(axes, panels, strict=True):
        for key, (label, style, marker) in MECHANISM_STYLES.items():
            if key not in panel.closed or not np.any(panel.closed[key] > 0):
                continue
            weight = 2.2 if key == "total_j" else 1.2
            ax.plot(
                panel.amplitude * 1e6,
                panel.closed[key] * 1e3,
                linestyle=style,
                color="black",
                lw=weight,
                label=f"{label}, closed form",
            )
            ax.plot(
                panel.exact_amplitude * 1e6,
                panel.exact[key] * 1e3,
                linestyle="none",
                marker=marker,
                mfc="white",
                mec="0.3",
                ms=5,
                label=f"{label}, exact cycle",
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("amplitude beyond the gap edge A (µm)")
        ax.set_title(panel.title)
        ax.grid(True, which="both", color="0.9", lw=0.5)
    axes[0].set_ylabel("energy per cycle (mJ)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(
        handles, labels, loc="outside lower center", ncols=3, frameon=False, fontsize="small"
    )
    return fig


def agreement_map_figure(
    omega: NDArray[np.float64],
    force: NDArray[np.float64],
    gap: NDArray[np.float64],
    penetration: NDArray[np.float64],
    *,
    tolerance: float = 0.05,
    title: str | None = None,
) -> Figure:
    """Return the map of where abs(closed / exact - 1) <= tolerance over frequency (Hz) and force.

    Grey: within tolerance; white: outside; hatched: no periodic orbit. Contours
    give the exact cycle's penetration A in um.
    """
    fig = Figure(figsize=(6.0, 4.6), layout="constrained")
    ax = fig.add_subplot()
    freq = omega / (2.0 * np.pi)
    inside = np.where(np.isnan(gap), np.nan, (np.abs(gap) <= tolerance).astype(float))
    ax.pcolormesh(freq, force, inside.T, cmap="Greys", vmin=0.0, vmax=2.5, shading="nearest")
    missing = np.isnan(gap).T.astype(float)
    if missing.any():
        ax.contourf(freq, force, missing, levels=[0.5, 1.5], colors="none", hatches=["xxx"])
    if np.any(np.isfinite(penetration)):
        lines = ax.contour(
            freq, force, penetration.T * 1e6, colors="black", linewidths=0.7, levels=6
        )
        ax.clabel(lines, fmt="%.0f µm", fontsize="x-small")
    ax.set_xlabel("forcing frequency (Hz)")
    ax.set_ylabel("force amplitude F0 (N)")
    ax.set_title(title or f"grey: closed form within {tolerance:.0%} of the exact cycle")
    return fig


#: A flag reason is cut to this many characters in a figure (the CSV has it whole).
NOTE_CHARACTERS = 110


def _short(text: str, limit: int = NOTE_CHARACTERS) -> str:
    """``text`` cut at a word before ``limit`` characters, with an ellipsis when cut."""
    if len(text) <= limit:
        return text
    return text[:limit].rsplit(" ", 1)[0].rstrip(",;:") + " …"


def identified_loop_figure(
    displacement: NDArray[np.float64],
    force: NDArray[np.float64],
    stage: NDArray[np.int8],
    edges: tuple[float, float],
    lines: Sequence[tuple[float, float]] = (),
    *,
    title: str | None = None,
    model: str = "joint",
    slip_levels: tuple[float, float] | None = None,
    note: str = "",
) -> Figure:
    """Return a record's loop, its samples marked by stage, the gap edges and fitted lines.

    Parameters
    ----------
    displacement, force : (n,) ndarray
        The record's displacement, m, and restoring force, N.
    stage : (n,) ndarray of int8
        -1, 0 or 1 per sample: a joint's tension, free play and compression; a damper's
        negative force, backlash (abs(F) small, after a reversal) and positive force.
    edges : tuple of float
        A joint's gap edges, m (dashed lines); not drawn for a damper, whose backlash
        follows each reversal, not a place in x.
    lines : sequence of (float, float)
        The (intercept N, slope N/m) of a joint's fitted tension, free-play and
        compression lines.
    title : str, optional
    model : {"joint", "damper", "line"}
        The identified model: it names the stages in the legend.
    slip_levels : tuple of float, optional
        A damper's two slip levels, N (dotted lines).
    note : str
        The flag reason, shown shortened under the axes.

    Returns
    -------
    Figure
        The displacement in mm when the loop spans a millimetre or more, else in µm.
    """
    fig = Figure(figsize=(6.0, 4.6), layout="constrained")
    ax = fig.add_subplot()
    damper = model == "damper"
    big = float(np.ptp(displacement)) >= 1e-3
    scale, unit = (1e3, "mm") if big else (1e6, "µm")
    names = (
        ("negative force", "backlash (after a reversal)", "positive force")
        if damper
        else ("tension", "free-play", "compression")
    )
    marks = {
        -1: (names[0], "v", "0.55"),
        0: (names[1], ".", "0.75"),
        1: (names[2], "^", "0.25"),
    }
    for value, (name, marker, colour) in marks.items():
        sel = stage == value
        if sel.any():
            ax.plot(
                displacement[sel] * scale,
                force[sel],
                linestyle="none",
                marker=marker,
                ms=2.5,
                color=colour,
                label=name,
            )
    span = np.array([displacement.min(), displacement.max()])
    for (intercept, slope), (low, high) in zip(
        lines, ((span[0], edges[1]), (edges[1], edges[0]), (edges[0], span[1])), strict=False
    ):
        xs = np.array([low, high])
        ax.plot(xs * scale, intercept + slope * xs, color="black", lw=1.4)
    if damper:
        for level, which in zip(slip_levels or (), ("positive", "negative"), strict=False):
            style = ":" if which == "positive" else "-."
            ax.axhline(level, color="black", lw=0.8, linestyle=style, label=f"{which} slip level")
    else:
        for edge in edges:
            ax.axvline(edge * scale, color="black", lw=0.8, linestyle="--")
    ax.set_xlabel(f"displacement x ({unit})")
    ax.set_ylabel("restoring force (N)")
    ax.legend(frameon=False, fontsize="small")
    if title:
        ax.set_title(title)
    if note:
        fig.text(0.01, 0.0, _short(note), fontsize="x-small", ha="left", va="bottom", wrap=True)
        fig.get_layout_engine().set(rect=(0.0, 0.05, 1.0, 0.95))  # type: ignore[union-attr,call-arg]
    return fig


_MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*")
_LINES = ("-", "--", "-.", ":", (0, (5, 1, 1, 1)), (0, (3, 1, 1, 1, 1, 1)))


def _points_and_lines(
    ax: Any,
    frequency: NDArray[np.float64],
    amplitude: NDArray[np.float64],
    values: NDArray[np.float64],
    lines: dict[float, tuple[NDArray[np.float64], NDArray[np.float64]]],
    *,
    divisor: float = 1.0,
    error: NDArray[np.float64] | None = None,
    unit: str = "",
) -> None:
    """Draw, per test frequency, the measured ``values`` (open markers, error bars when
    given) and its law's line against amplitude in µm, all divided by ``divisor``.

    Each frequency has its own marker, line style and colour (viridis: ordered by
    frequency, and still ordered by lightness in grey print). When the laws' lines lie
    closer together than the eye can part (within 2 % of the axis' span), a note in the
    panel says so, with their spread in ``unit``: the law barely depends on frequency.
    """
    import matplotlib

    freqs = sorted(set(frequency.tolist()))
    cmap = matplotlib.colormaps["viridis"]
    for n, f in enumerate(freqs):
        sel = frequency == f
        marker = _MARKERS[n % len(_MARKERS)]
        colour = cmap(0.85 * n / max(len(freqs) - 1, 1))
        style = {"color": colour, "mfc": "white", "ms": 5, "label": f"{f:g} Hz"}
        if error is not None:
            ax.errorbar(
                amplitude[sel] * 1e6,
                values[sel] / divisor,
                yerr=error[sel] / divisor,
                fmt=marker,
                capsize=2,
                **style,
            )
        else:
            ax.plot(amplitude[sel] * 1e6, values[sel] / divisor, marker, **style)
        if f in lines:
            grid, law = lines[f]
            ax.plot(
                grid * 1e6, law / divisor, linestyle=_LINES[n % len(_LINES)], color=colour, lw=1.2
            )
    drawn = [lines[f] for f in freqs if f in lines]
    if len(drawn) > 1 and all(g.shape == drawn[0][0].shape for g, _ in drawn):
        laws = np.array([law for _, law in drawn]) / divisor
        spread = float(np.max(laws.max(axis=0) - laws.min(axis=0)))
        low, high = ax.get_ylim()
        if spread < 0.02 * (high - low):
            ax.text(
                0.98,
                0.03,
                f"the {len(drawn)} frequencies' lines lie within {spread:.2g} {unit}".rstrip()
                + "\nof each other: the law barely depends on frequency",
                transform=ax.transAxes,
                ha="right",
                va="bottom",
                fontsize="small",
                color="0.25",
            )


@dataclass(frozen=True)
class StiffnessPanel:
    """Measured stiffness points and their eq 19 (or eq 20) lines, for one joint and side.

    ``frequency`` in Hz, ``amplitude`` in m, ``stiffness`` (and ``error``) in N/m;
    ``lines`` maps a frequency (Hz) to (amplitude grid, law values).
    """

    title: str
    frequency: NDArray[np.float64]
    amplitude: NDArray[np.float64]
    stiffness: NDArray[np.float64]
    lines: dict[float, tuple[NDArray[np.float64], NDArray[np.float64]]]
    error: NDArray[np.float64] | None = None


def stiffness_panels_figure(
    panels: Sequence[StiffnessPanel], *, ylabel: str, title: str | None = None
) -> Figure:
    """Return Figs. 8 and 10: stiffness against amplitude, one marker and line per frequency."""
    cols = min(len(panels), 2)
    rows = math.ceil(len(panels) / cols)
    fig = Figure(figsize=(5.2 * cols, 3.8 * rows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel()
    for ax, panel in zip(axes, panels, strict=False):
        _points_and_lines(
            ax,
            panel.frequency,
            panel.amplitude,
            panel.stiffness,
            panel.lines,
            divisor=1e6,
            error=panel.error,
            unit="MN/m",
        )
        ax.set_title(panel.title, fontsize="medium")
        ax.set_xlabel("amplitude A (µm)")
        ax.set_ylabel(ylabel)
        ax.grid(True, color="0.9", lw=0.5)
    for ax in axes[len(panels) :]:
        ax.set_visible(False)
    axes[0].legend(frameon=False, fontsize="small")
    if title:
        fig.suptitle(title)
    return fig


def coefficient_bars_figure(
    labels: Sequence[str], frequency_part: Sequence[float], amplitude_part: Sequence[float]
) -> Figure:
    """Return Fig. 9: the normalised eq 19 coefficients, a bar pair per joint and side."""
    fig = Figure(figsize=(6.5, 3.8), layout="constrained")
    ax = fig.add_subplot()
    x = np.arange(len(labels))
    ax.bar(x - 0.2, frequency_part, 0.4, color="0.35", label="a1 mean(w) / mean(k)")
    ax.bar(
        x + 0.2,
        amplitude_part,
        0.4,
        color="white",
        edgecolor="black",
        hatch="//",
        label="a2 mean(A) / mean(k)",
    )
    ax.set_xticks(x, labels, rotation=20, ha="right")
    ax.axhline(0.0, color="black", lw=0.6)
    ax.set_ylabel("normalised coefficient")
    ax.legend(frameon=False, fontsize="small")
    return fig


@dataclass(frozen=True)
class EnergyLawPanel:
    """Measured energy per cycle and eq 21 curves for one joint (``frequency`` in Hz)."""

    title: str
    frequency: NDArray[np.float64]
    amplitude: NDArray[np.float64]
    energy: NDArray[np.float64]
    curves: dict[float, tuple[NDArray[np.float64], NDArray[np.float64]]]


def energy_law_figure(panels: Sequence[EnergyLawPanel]) -> Figure:
    """Return Fig. 11: energy per cycle against amplitude, with the eq 21 exponentials."""
    fig = Figure(figsize=(5.2 * len(panels), 4.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(panels), squeeze=False)).ravel()
    for ax, panel in zip(axes, panels, strict=True):
        _points_and_lines(ax, panel.frequency, panel.amplitude, panel.energy, panel.curves)
        ax.set_yscale("log")
        ax.set_xlabel("amplitude Abar = X - c/2 (µm)")
        ax.set_ylabel("energy per cycle (J)")
        ax.set_title(panel.title, fontsize="medium")
        ax.grid(True, which="both", color="0.9", lw=0.5)
    axes[0].legend(frameon=False, fontsize="small")
    return fig


def law_versus_measured_figure(
    measured: NDArray[np.float64],
    law: NDArray[np.float64],
    model: NDArray[np.float64] | None = None,
    groups: NDArray[np.str_] | None = None,
    *,
    reference: str = "measured",
) -> Figure:
    """Return Fig. 13: eq 22 (and the section-2 model) against the reference energy.

    ``reference`` names the x axis: "measured" for real records, "virtual rig" where
    the energies were simulated. The 1:1 line is in the legend; the log axes carry
    enough labelled ticks to read a value (1, 2, 3, 5 per decade over a decade or so,
    1, 2, 5 up to three, decades beyond), written as plain numbers (0.05, 0.2).
    """
    from matplotlib.ticker import LogLocator, NullFormatter

    fig = Figure(figsize=(5.6, 4.8), layout="constrained")
    ax = fig.add_subplot()
    names = sorted(set(groups.tolist())) if groups is not None else [""]
    for n, name in enumerate(names):
        sel = groups == name if groups is not None else np.ones(measured.size, dtype=bool)
        ax.plot(
            measured[sel],
            law[sel],
            _MARKERS[n % len(_MARKERS)],
            color="black",
            mfc="white",
            ms=5,
            label=f"eq 22 {name}".strip(),
        )
        if model is not None:
            ax.plot(
                measured[sel],
                model[sel],
                _MARKERS[n % len(_MARKERS)],
                color="0.55",
                ms=4,
                label=f"section 2 model {name}".strip(),
            )
    values = [measured, law] + ([model] if model is not None else [])
    finite = np.concatenate([v[np.isfinite(v) & (v > 0)] for v in values])
    span = np.array([finite.min(), finite.max()]) if finite.size else np.array([1e-3, 1.0])
    ax.plot(span, span, color="0.6", lw=0.8, label="1:1")
    ax.set_xscale("log")
    ax.set_yscale("log")
    decades = float(np.log10(span[1] / span[0])) if span[0] > 0 else 3.0
    # enough labelled ticks: 1-2-3-5 per decade over a decade or so, 1-2-5 to three decades
    subs = (1.0, 2.0, 3.0, 5.0) if decades < 1.5 else (1.0, 2.0, 5.0) if decades < 3 else (1.0,)
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(LogLocator(base=10.0, subs=subs, numticks=15))
        axis.set_major_formatter(_plain_numbers())
        axis.set_minor_formatter(NullFormatter())
    ax.tick_params(axis="x", labelrotation=35)
    ax.set_xlabel(f"{reference} energy per cycle (J)")
    ax.set_ylabel("predicted energy per cycle (J)")
    ax.legend(frameon=False, fontsize="small")
    return fig


def _plain_numbers() -> Any:
    """A log axis' tick formatter: plain numbers (0.05, 2, 300), and no label for a tick
    outside the axis' view (the locator returns some beyond it; they are never drawn)."""
    from matplotlib.ticker import Formatter

    class PlainNumbers(Formatter):
        def __call__(self, value: float, pos: int | None = None) -> str:
            if self.axis is not None:
                low, high = sorted(self.axis.get_view_interval())
                if not low * (1 - 1e-9) <= value <= high * (1 + 1e-9):
                    return ""
            return f"{value:g}"

    return PlainNumbers()


def identification_accuracy_figure(accuracy: Sequence[dict[str, Any]]) -> Figure:
    """Return the identification's relative error per test against the rig's truth, in %.

    One column of points per quantity (clearance, contact stiffness per side, energy
    per cycle), with the +-1 % band shaded and named in a legend outside the axes.
    """
    keys = (
        ("clearance_error", "clearance"),
        ("compression_stiffness_error", "k_c (slope)"),
        ("tension_stiffness_error", "k_t (slope)"),
        ("energy_error", "energy per cycle"),
    )
    fig = Figure(figsize=(6.8, 3.4), layout="constrained")
    ax = fig.add_subplot()
    ax.axhspan(-1.0, 1.0, color="0.92", lw=0, label="±1 %")
    for n, (key, _) in enumerate(keys):
        values = np.array([a[key] for a in accuracy if key in a], dtype=np.float64) * 100
        jitter = np.linspace(-0.25, 0.25, values.size) if values.size > 1 else np.zeros(1)
        ax.plot(n + jitter[: values.size], values, "o", color="0.2", mfc="white", ms=3.5)
    ax.axhline(0.0, color="black", lw=0.6)
    ax.set_xticks(range(len(keys)), [label for _, label in keys])
    ax.set_ylabel("identified / true - 1 (%)")
    # the legend outside the axes, on the right: no data point can sit on it
    ax.legend(frameon=False, fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return fig


# ---- the report's figures from an analysis ------------------------------------------------


#: Below this R^2 a figure's caption warns that its law does not describe the data.
POOR_R_SQUARED = 0.5


def _warning(laws: dict[str, fit.LinearFit]) -> str:
    poor = [
        f"{label} (R² = {law.r_squared:.2f})"
        for label, law in laws.items()
        if law.r_squared < POOR_R_SQUARED
    ]
    if not poor:
        return ""
    return (
        f" WARNING: R² below {POOR_R_SQUARED:g} for "
        + "; ".join(poor)
        + ": that law does not describe these data."
    )


def report_figures(
    analysis: Analysis,
    model_energy: Sequence[float] | None,
    stiffness_curves: Sequence[Curve],
    *,
    measured: bool = True,
) -> dict[str, Figure]:
    """Return the report's figures (paper Figs. 7-13) by caption, from an analysis.

    A figure whose law has R² below ``POOR_R_SQUARED`` says so in its caption.

    Parameters
    ----------
    analysis : Analysis
        The identified tests and their fitted laws.
    model_energy : sequence of float, optional
        Section 2's energy at each jointed test (J), drawn in Fig. 13 when given.
    stiffness_curves : sequence of Curve
        Fig. 12's c_d curves (none: Fig. 12 is left out).
    measured : bool
        True for real records ("measured"), False for the virtual rig's ("virtual rig").
    """
    rows = analysis.rows
    out: dict[str, Figure] = {}
    # Fig. 7: the first jointed record with its stages
    for record, ident in analysis.identifications:
        if ident.model != "line":
            first = ident.cycles[-3] if len(ident.cycles) >= 3 else ident.cycles[0]
            span = slice(first.start, ident.cycles[-1].stop)
            runs = [
                r
                for r in ident.stage_runs(record.time)
                if r[2] >= record.time[span.start] and r[1] <= record.time[span.stop - 1]
            ]
            how = (
                " (a damper: free play where the force is near zero, after each reversal)"
                if ident.model == "damper"
                else ""
            )
            out[f"Fig. 7: stages of {Path(ident.source).name}{how}"] = displacement_stages_figure(
                record.time[span], record.displacement[span], runs
            )
            break
    for laws, caption, ylabel in (
        (
            analysis.stiffness_laws,
            "Fig. 8: per-side dynamic stiffness k_d,s with the eq 19 planes.",
            "dynamic stiffness k_d,s (MN/m)",
        ),
        (
            analysis.contact_laws,
            "Contact slopes k_s,meas with their eq 19 planes (not a paper figure).",
            "contact slope (MN/m)",
        ),
    ):
        panels = []
        column = (
            "dynamic_stiffness_n_per_m" if laws is analysis.stiffness_laws else "stiffness_n_per_m"
        )
        for label, law in laws.items():
            name, side = label.rsplit(", ", 1)
            sel = tests_of(rows, name)
            freq = np.array([r["test_frequency_hz"] for r in sel], dtype=np.float64)
            _, amp, k = side_data(sel, side, column)
            freq = freq[np.isfinite([r[f"{side}_{column}"] for r in sel])]
            grid = np.linspace(amp.min(), amp.max(), 20)
            lines = {
                f: (grid, fit.evaluate_stiffness_law(law, 2 * math.pi * f, grid))
                for f in sorted(set(freq.tolist()))
            }
            panels.append(StiffnessPanel(label, freq, amp, k, lines))
        if panels:
            out[caption + _warning(laws)] = stiffness_panels_figure(panels, ylabel=ylabel)
    if analysis.normalised:
        labels = list(analysis.normalised)
        out["Fig. 9: normalised eq 19 coefficients"] = coefficient_bars_figure(
            labels,
            [v[0] for v in analysis.normalised.values()],
            [v[1] for v in analysis.normalised.values()],
        )
    panels = []
    for label, js in analysis.joint_stiffness.items():
        freq = js.omega / (2 * math.pi)
        panels.append(StiffnessPanel(label, freq, js.amplitude, js.value, {}, js.error))
    if panels:
        out["Fig. 10: the joint's own dynamic stiffness k_dj, eq 20 on k_d,s"] = (
            stiffness_panels_figure(panels, ylabel="joint stiffness k_dj (MN/m)")
        )
    energy_panels = []
    for name in sorted({r["structure"] for r in rows if r["jointed"]}):
        sel = tests_of(rows, name)
        freq = np.array([r["test_frequency_hz"] for r in sel])
        amp = np.array([r["mean_amplitude_m"] for r in sel])
        energy = np.array([r["energy_per_cycle_j"] for r in sel])
        curves = {}
        for f in sorted(set(freq.tolist())):
            exponential = analysis.exponential_laws.get(f"{name}, {f:g} Hz")
            if exponential is not None:
                grid = np.linspace(amp[freq == f].min(), amp[freq == f].max(), 20)
                curves[f] = (grid, fit.evaluate_exponential_law(exponential, grid))
        energy_panels.append(EnergyLawPanel(name, freq, amp, energy, curves))
    if energy_panels:
        caption = "Fig. 11: energy per cycle with the eq 21 laws." + _warning(
            analysis.exponential_laws
        )
        out[caption] = energy_law_figure(energy_panels)
    if stiffness_curves:
        out[
            "Fig. 12: stiffness coefficient c_d against amplitude, for "
            + ", ".join(sorted({c.label.split(",")[0] for c in stiffness_curves}))
        ] = stiffness_coefficient_figure(stiffness_curves)
    general = analysis.dissipation_law
    if general is not None:
        jointed = [r for r in rows if r["jointed"]]
        energy = np.array([r["energy_per_cycle_j"] for r in jointed])
        predicted = fit.evaluate_dissipation_law(
            general,
            [r["omega"] for r in jointed],
            [r["nominal_clearance_m"] for r in jointed],
            [r["mean_amplitude_m"] for r in jointed],
        )
        model = np.array(model_energy) if model_energy is not None else None
        reference = "measured" if measured else "virtual rig"
        what = "eq 22 and the section-2 model" if model is not None else "eq 22"
        caption = f"Fig. 13: {what} against the {reference} energy per cycle." + _warning(
            {"eq 22": general}
        )
        out[caption] = law_versus_measured_figure(
            energy,
            predicted,
            model,
            np.array([r["structure"] for r in jointed]),
            reference=reference,
        )
    return out


def structure_modes(closed: Any, opened: Any) -> Figure:
    """Return the closed- and open-pattern mode shapes of a structure side by side (MODEL.md 5.2).

    Parameters
    ----------
    closed, opened : clearjoint.structure.Modes
        The modes with every joint closed and every joint open.

    Returns
    -------
    matplotlib.figure.Figure
        Two Axes, each drawn by ``Modes.plot``.
    """
    fig = Figure(figsize=(9.0, 6.0), layout="constrained")
    left, right = fig.subplots(1, 2)
    closed.plot(left)
    opened.plot(right)
    return fig
