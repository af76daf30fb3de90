"""The result of identifying one record: values, standard errors, flags, and their views.

MODEL.md section 3. :class:`Identification` carries per-cycle values (:class:`CycleResult`),
their summary with a standard error per quantity, a credibility flag per quantity
(``ok``, ``doubtful`` or ``rejected``, each with its reason), warnings, and the cycle
average it was fitted on (for :meth:`Identification.plot`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.identify.segments import STAGE_COMPRESSION, STAGE_FREE, STAGE_TENSION
from clearjoint.units import unit_of_name

#: A damper's free play: where the restoring force's magnitude is below this fraction of
#: its friction force (:meth:`Identification.stage_runs`).
DAMPER_FREE_PLAY_FRACTION = 0.2


def damper_stages(force: FloatArray, friction: float) -> NDArray[np.int8]:
    """A damper's stage per sample (n,), from its restoring force ``force`` (n,), N.

    Free play (0) where abs(F) is below ``DAMPER_FREE_PLAY_FRACTION`` of ``friction``,
    compression (1) above it, tension (-1) below its negative: a damper plays free after
    each reversal, wherever the displacement is.
    """
    level = DAMPER_FREE_PLAY_FRACTION * friction
    stage = np.full(force.shape, STAGE_FREE, dtype=np.int8)
    stage[force > level] = STAGE_COMPRESSION
    stage[force < -level] = STAGE_TENSION
    return stage


if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

FloatArray = NDArray[np.float64]

#: Quantities measured per cycle and summarised per test (mean, spread, standard error).
QUANTITIES = (
    "amplitude_m",
    "clearance_m",
    "compression_stiffness_n_per_m",
    "tension_stiffness_n_per_m",
    "friction_force_n",
    "energy_per_cycle_j",
    "compression_penetration_m",
    "tension_penetration_m",
    "gap_stiffness_n_per_m",
    "secant_stiffness_n_per_m",
    "dynamic_stiffness_n_per_m",
    "friction_force_positive_n",
    "friction_force_negative_n",
    "mass_kg",
)

#: The units of each quantity, for to_xarray and the figures.
UNITS = {key: unit_of_name(key) for key in QUANTITIES}

FLAGS = ("ok", "doubtful", "rejected")


@dataclass(frozen=True)
class CycleResult:
    """What one steady cycle gives: each of ``QUANTITIES`` (SI), its sample span, the gap
    edges, the model that fitted the record ("joint", "damper" or "line") and, for a joint,
    the elastic lines (intercept, slope) of its tension, free-play and compression stages.

    Amplitude, energy and secant stiffness are the cycle's own; the fitted quantities are
    the jackknife pseudo-value of the cycle's group (G times the fit of all cycles minus
    G - 1 times the fit without the group; G <= 8 contiguous groups, one cycle each when
    there are at most eight), whose mean is near the estimate and whose spread over
    sqrt(G) is its standard error.
    """

    start: int
    stop: int
    values: dict[str, float]
    upper_edge: float
    lower_edge: float
    model: str
    lines: tuple[tuple[float, float], ...] = ()

    def __repr__(self) -> str:
        amplitude = self.values.get("amplitude_m", math.nan)
        clearance = self.values.get("clearance_m", math.nan)
        return (
            f"CycleResult(samples {self.start}-{self.stop}, {self.model}, "
            f"X = {amplitude * 1e6:.4g} um, clearance {clearance * 1e6:.4g} um, "
            f"edges {self.lower_edge * 1e6:.4g} / {self.upper_edge * 1e6:.4g} um)"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the cycle's values as an ``xarray.Dataset`` of 0-d variables, units in attrs.

        Returns
        -------
        xarray.Dataset
            One 0-d variable per entry of ``values`` (its unit from :data:`UNITS`),
            ``upper_edge`` and ``lower_edge`` (m), and the elastic lines
            ``line_intercept`` (N) and ``line_slope`` (N/m) on ``stage`` (tension,
            free play, compression; empty but for a joint). ``attrs`` give the
            sample span and the model.
        """
        import xarray as xr

        names = ("tension", "free play", "compression")[: len(self.lines)]
        data = xr.Dataset(
            {
                key: ((), value, {"units": UNITS.get(key, "1")})
                for key, value in self.values.items()
            },
            attrs={
                "title": "clearjoint one identified cycle",
                "start_sample": self.start,
                "stop_sample": self.stop,
                "model": self.model,
            },
        )
        data["upper_edge"] = ((), self.upper_edge, {"units": "m"})
        data["lower_edge"] = ((), self.lower_edge, {"units": "m"})
        data["line_intercept"] = ("stage", [c for c, _ in self.lines], {"units": "N"})
        data["line_slope"] = ("stage", [k for _, k in self.lines], {"units": "N/m"})
        return data.assign_coords(stage=("stage", list(names)))

    def to_pandas(self) -> pd.DataFrame:
        """Return the cycle as a one-row ``pandas.DataFrame`` (a record's cycles together:
        :meth:`Identification.to_pandas`).

        Columns ``start``, ``stop``, ``model``, ``upper_edge_m``, ``lower_edge_m``, then
        each entry of ``values`` (its name carries the unit).
        """
        import pandas as pd

        row: dict[str, Any] = {
            "start": self.start,
            "stop": self.stop,
            "model": self.model,
            "upper_edge_m": self.upper_edge,
            "lower_edge_m": self.lower_edge,
            **self.values,
        }
        return pd.DataFrame({key: [value] for key, value in row.items()})

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the cycle's fitted elastic lines, force (N) against x (um), and its gap edges.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Two dotted vertical lines at the gap edges, then one line per fitted stage
            (tension, free play, compression), each over its own span (half the gap
            beyond each edge).
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        width = max(self.upper_edge - self.lower_edge, 1e-12)
        for edge in (self.lower_edge, self.upper_edge):
            axes.axvline(edge * 1e6, color="0.5", ls=":", lw=0.8)
        spans = (
            (self.lower_edge - 0.5 * width, self.lower_edge),
            (self.lower_edge, self.upper_edge),
            (self.upper_edge, self.upper_edge + 0.5 * width),
        )
        for (intercept, slope), span, name in zip(
            self.lines, spans, ("tension", "free play", "compression"), strict=False
        ):
            x = np.array(span)
            axes.plot(x * 1e6, intercept + slope * x, color="black", lw=1.5, label=name)
        axes.set_xlabel("displacement x (µm)")
        axes.set_ylabel("restoring force (N)")
        if self.lines:
            axes.legend(frameon=False, fontsize="small")
        return axes


@dataclass(frozen=True)
class Identification:
    """The identification of one record: per-cycle values, their summary and credibility.

    ``summary[q]``, ``spread[q]`` and ``stderr[q]`` are, for each quantity in
    ``QUANTITIES``, the estimate (the fit of the steady cycles' average; for amplitude,
    energy and secant stiffness the mean over the cycles), the scatter of one cycle
    (``stderr * sqrt(cycles_used)``) and the estimate's standard error. ``flags[q]`` is
    (flag, reason) with flag one of ``ok``, ``doubtful``, ``rejected``.
    """

    source: str
    frequency_hz: float
    cycles_total: int
    cycles: tuple[CycleResult, ...]
    summary: dict[str, float]
    spread: dict[str, float]
    control: str
    restoring_force: FloatArray = field(repr=False)
    stage: NDArray[np.int8] = field(repr=False)
    stderr: dict[str, float] = field(default_factory=dict)
    flags: dict[str, tuple[str, str]] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    joint_id: str = ""
    loop: tuple[FloatArray, FloatArray] = field(default=(np.zeros(0), np.zeros(0)), repr=False)

    @property
    def cycles_used(self) -> int:
        return len(self.cycles)

    @property
    def model(self) -> str:
        """The loop's model: "joint" (free play between two contacts), "damper" or "line"."""
        return self.cycles[0].model

    @property
    def flag(self) -> str:
        """The worst flag of any quantity."""
        worst = max((FLAGS.index(f) for f, _ in self.flags.values()), default=0)
        return FLAGS[worst]

    @property
    def flag_reason(self) -> str:
        """The reasons of every flag that is not ``ok``, each once, joined by "; " (a
        quantity's own reasons are joined so too: each is counted once over all)."""
        reasons = [p for f, r in self.flags.values() if f != "ok" and r for p in r.split("; ")]
        return "; ".join(dict.fromkeys(reasons))

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"Identification({self.source!r}, model={self.model!r}, cycles "
            f"{self.cycles_used}/{self.cycles_total}, f={self.frequency_hz:.4g} Hz, "
            f"clearance={s['clearance_m'] * 1e3:.4g} mm, "
            f"k_c={s['compression_stiffness_n_per_m']:.4g} N/m, "
            f"k_t={s['tension_stiffness_n_per_m']:.4g} N/m, "
            f"friction={s['friction_force_n']:.4g} N, "
            f"energy={s['energy_per_cycle_j']:.4g} J/cycle, flag={self.flag!r})"
        )

    def row(self) -> dict[str, Any]:
        """One row for results.csv: each quantity with ``_std`` (spread over the cycles)
        and ``_se`` (standard error) beside it, then ``flag`` and ``flag_reason``."""
        out: dict[str, Any] = {
            "file": self.source,
            "frequency_hz": self.frequency_hz,
        }
        for key in QUANTITIES:
            out[key] = self.summary[key]
            out[f"{key}_std"] = self.spread[key]
            out[f"{key}_se"] = self.stderr.get(key, math.nan)
        out["cycles_used"] = self.cycles_used
        out["cycles_total"] = self.cycles_total
        out["control"] = self.control
        out["model"] = self.model
        out["flag"] = self.flag
        out["flag_reason"] = self.flag_reason
        return out

    def to_pandas(self) -> pd.DataFrame:
        """One row per quantity: value, spread, standard error, unit, flag, flag_reason."""
        import pandas as pd

        return pd.DataFrame(
            {
                "value": [self.summary[q] for q in QUANTITIES],
                "spread": [self.spread[q] for q in QUANTITIES],
                "stderr": [self.stderr.get(q, math.nan) for q in QUANTITIES],
                "unit": [UNITS[q] for q in QUANTITIES],
                "flag": [self.flags.get(q, ("ok", ""))[0] for q in QUANTITIES],
                "flag_reason": [self.flags.get(q, ("ok", ""))[1] for q in QUANTITIES],
            },
            index=pd.Index(QUANTITIES, name="quantity"),
        )

    def to_xarray(self) -> xr.Dataset:
        """The per-cycle values (dimension ``cycle``) with the summary, standard error and
        flag of each quantity in its attributes (``units`` too)."""
        import xarray as xr

        data = {}
        for q in QUANTITIES:
            flag, reason = self.flags.get(q, ("ok", ""))
            data[q] = (
                "cycle",
                np.array([c.values[q] for c in self.cycles]),
                {
                    "units": UNITS[q],
                    "estimate": self.summary[q],
                    "stderr": self.stderr.get(q, math.nan),
                    "flag": flag,
                    "flag_reason": reason,
                },
            )
        return xr.Dataset(
            data,
            coords={"cycle": np.arange(self.cycles_used)},
            attrs={
                "source": self.source,
                "model": self.model,
                "frequency_hz": self.frequency_hz,
                "control": self.control,
                "flag": self.flag,
                "flag_reason": self.flag_reason,
            },
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Plot the steady cycles' average loop (restoring force against displacement), the
        gap edges, the fitted stage lines (a joint) or the two slip levels (a damper), with
        the clearance, its standard error and the flag in the title; return the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6.0, 4.0))
        x, f = self.loop
        ax.plot(x * 1e3, f, color="0.3", lw=1.0, label="steady cycles' average")
        first = self.cycles[0]
        if self.model != "line":
            for edge in (first.upper_edge, first.lower_edge):
                ax.axvline(edge * 1e3, color="C3", lw=0.8, ls="--")
        if self.model == "damper":  # the two slip levels
            for key in ("friction_force_positive_n", "friction_force_negative_n"):
                ax.axhline(self.summary[key], color="C0", lw=1.0, ls=":")
        for (a, k), (lo, hi) in zip(
            first.lines,
            (
                (float(x.min()), first.lower_edge),
                (first.lower_edge, first.upper_edge),
                (first.upper_edge, float(x.max())),
            ),
            strict=False,
        ):
            xs = np.array([lo, hi])
            ax.plot(xs * 1e3, a + k * xs, color="C0", lw=1.5)
        ax.set_xlabel("displacement (mm)")
        ax.set_ylabel("restoring force (N)")
        s, e = self.summary, self.stderr
        ax.set_title(
            f"{self.model}: c = {s['clearance_m'] * 1e3:.4g} ± "
            f"{e.get('clearance_m', math.nan) * 1e3:.2g} mm [{self.flag}]",
            fontsize=9,
        )
        return ax

    def stage_runs(self, time: FloatArray) -> list[tuple[str, float, float]]:
        """The stages as (name, start, end) runs over the record's time, for figures.

        The runs of :attr:`stage`: a clearance joint's stages follow the displacement
        (inside the gap edges or beyond). A friction damper with backlash plays free after
        each reversal, not at the zero crossings: its stages follow the restoring force,
        free play where abs(F) is below ``DAMPER_FREE_PLAY_FRACTION`` of the identified
        friction force, compression where F is above it and tension below its negative.
        """
        stage = self.stage
        if self.model == "damper":
            stage = damper_stages(self.restoring_force, self.summary["friction_force_n"])
        names = {
            STAGE_FREE: "free-play",
            STAGE_COMPRESSION: "compression",
            STAGE_TENSION: "tension",
        }
        change = np.nonzero(np.diff(stage))[0] + 1
        bounds = np.concatenate(([0], change, [stage.size]))
        return [
            (names[int(stage[a])], float(time[a]), float(time[min(b, time.size - 1)]))
            for a, b in itertools.pairwise(bounds)
        ]


def identifications_figure(results: list[Identification], columns: int = 4) -> Figure:
    """Return one figure with every identification's loop (:meth:`Identification.plot`).

    Parameters
    ----------
    results : list of Identification
    columns : int
        Panels per row.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    n = max(len(results), 1)
    cols = min(columns, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(4.0 * cols, 3.2 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, ident in zip(axes, results, strict=False):
        ident.plot(ax)
        name = ident.source.replace("\\", "/").rsplit("/", 1)[-1]
        ax.set_title(f"{name}\n{ax.get_title()}", fontsize=8)
    for ax in axes[len(results) :]:
        ax.set_visible(False)
    return fig
