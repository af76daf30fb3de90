"""Results of the single joint's time-domain solver: Motion, SteadyState, FrequencySweep.

The exact motion's record (MODEL.md sec. 2): its samples, stages, impacts and
energy ledger (:class:`EnergyLedger`, input = losses + change of mechanical
energy), the steady cycle (:class:`SteadyState`) and the stepped-sine sweep
(:class:`FrequencySweep`). No solver is imported here: ``clearjoint.simulate``
makes these, and the shooting solver (``clearjoint.periodic``) and the loss
analysis (``clearjoint.dissipation``) read them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes

__all__ = ["EnergyLedger", "FrequencySweep", "Motion", "Stage", "SteadyState"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class EnergyLedger:
    """Energies over one steady cycle (or over a whole time response), J.

    ``input`` is the work of F0 sin(w t); ``viscous``, ``sliding_friction`` and
    ``impact`` are the losses the equation of motion carries, so that
    input = losses + mechanical_energy_change exactly. ``contact_friction`` is
    MODEL.md eq 15 evaluated along the motion without feedback on it (0 without
    a pin or with mu_c = 0).
    """

    input: float
    viscous: float
    sliding_friction: float
    impact: float
    contact_friction: float = 0.0
    mechanical_energy_change: float = 0.0

    @property
    def losses(self) -> float:
        """viscous + sliding_friction + impact: the losses carried by the motion, J."""
        return self.viscous + self.sliding_friction + self.impact

    @property
    def balance_error(self) -> float:
        """abs(input - losses - mechanical_energy_change) / max(abs(input), losses)."""
        scale = max(abs(self.input), self.losses, 1e-300)
        return abs(self.input - self.losses - self.mechanical_energy_change) / scale

    def as_dict(self) -> dict[str, float]:
        """The ledger as a plain mapping (J)."""
        return {
            "input": self.input,
            "viscous": self.viscous,
            "sliding_friction": self.sliding_friction,
            "impact": self.impact,
            "contact_friction": self.contact_friction,
            "mechanical_energy_change": self.mechanical_energy_change,
            "losses": self.losses,
        }

    def __repr__(self) -> str:
        return (
            f"EnergyLedger(input {self.input * 1e3:.4g} mJ, losses {self.losses * 1e3:.4g} mJ "
            f"(viscous {self.viscous * 1e3:.4g}, sliding friction "
            f"{self.sliding_friction * 1e3:.4g}, impact {self.impact * 1e3:.4g}), "
            f"contact friction {self.contact_friction * 1e3:.4g} mJ, "
            f"balance error {self.balance_error:.1e})"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the ledger as an ``xarray.Dataset`` of 0-d variables, each in J.

        Returns
        -------
        xarray.Dataset
            One 0-d variable per entry of :meth:`as_dict` (``attrs["units"] == "J"``)
            and ``balance_error`` (1).
        """
        import xarray as xr

        data = xr.Dataset(
            {key: ((), value, {"units": "J"}) for key, value in self.as_dict().items()},
            attrs={"title": "clearjoint energy ledger"},
        )
        data["balance_error"] = ((), self.balance_error, {"units": "1"})
        return data

    def to_pandas(self) -> pd.DataFrame:
        """Return the ledger as a ``pandas.DataFrame``: index ``entry``, one column ``energy_j``.

        A ledger has no rows of its own: its table is one row per entry of :meth:`as_dict`.
        """
        import pandas as pd

        entries = self.as_dict()
        return pd.DataFrame(
            {"energy_j": list(entries.values())}, index=pd.Index(list(entries), name="entry")
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the input beside each loss as horizontal bars (mJ); return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            One bar container: input, viscous, sliding friction, impact, contact
            friction and the change of mechanical energy.
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        entries = {k: v for k, v in self.as_dict().items() if k != "losses"}
        axes.barh(
            [k.replace("_", " ") for k in entries],
            [v * 1e3 for v in entries.values()],
            color=["0.3"] + ["0.7"] * (len(entries) - 1),
        )
        axes.invert_yaxis()
        axes.set_xlabel("energy (mJ)")
        return axes


@dataclass(frozen=True)
class Stage:
    """One stage of the motion: ``name`` in {"free-play", "compression", "tension"}, times in s."""

    name: str
    start: float
    end: float

    def __repr__(self) -> str:
        return f"Stage({self.name}, {self.start * 1e3:.6g}-{self.end * 1e3:.6g} ms)"

    def to_xarray(self) -> xr.Dataset:
        """Return the stage as an ``xarray.Dataset`` of 0-d ``name``, ``start``, ``end`` (s)."""
        import xarray as xr

        return xr.Dataset(
            {
                "name": ((), self.name),
                "start": ((), self.start, {"units": "s"}),
                "end": ((), self.end, {"units": "s"}),
            },
            attrs={"title": "clearjoint stage of the motion"},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the stage as a one-row ``pandas.DataFrame`` (a motion's stages: its to_xarray).

        Columns ``name``, ``start_s``, ``end_s``.
        """
        import pandas as pd

        return pd.DataFrame({"name": [self.name], "start_s": [self.start], "end_s": [self.end]})

    def plot(self, ax: Axes | None = None) -> Axes:
        """Shade the stage's time span (ms) on ``ax``; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (usually a motion's plot); a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Its last patch spans start to end in ms, labelled with the stage's name.
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        axes.axvspan(self.start * 1e3, self.end * 1e3, color="0.85", zorder=0, label=self.name)
        axes.set_xlabel("time (ms)")
        return axes


@dataclass(frozen=True)
class Motion:
    """A sampled stretch of the exact motion, with its stages, impacts and energy ledger.

    Attributes
    ----------
    time : (N,) ndarray
        Time from the start of the stretch, s.
    displacement, velocity, acceleration : (N,) ndarray
        x (m), x' (m/s), x'' (m/s^2).
    excitation : (N,) ndarray
        F0 sin(w t), N.
    restoring_force : (N,) ndarray
        f(x), N.
    stages : tuple of Stage
    impact_times : (I,) ndarray
        When each contact was entered, s.
    impact_velocities : (I,) ndarray
        Approach speed before restitution, m/s, signed: + into compression, - into tension.
    energy : EnergyLedger
    events : int
        Number of events (edges, velocity zeros, stick releases) in the stretch.
    x_max, x_min : float
        Exact extremes of x (at turning points), m.
    stick_time : float
        Time spent stuck by sliding friction, s.
    final_state : tuple of float
        (x, v) at the end of the stretch, m and m/s.
    """

    time: FloatArray
    displacement: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    excitation: FloatArray
    restoring_force: FloatArray
    stages: tuple[Stage, ...]
    impact_times: FloatArray
    impact_velocities: FloatArray
    energy: EnergyLedger
    events: int
    x_max: float
    x_min: float
    stick_time: float
    final_state: tuple[float, float]

    @property
    def amplitude(self) -> float:
        """Displacement amplitude X = (x_max - x_min) / 2, m."""
        return 0.5 * (self.x_max - self.x_min)

    # ---- working with the result: summary, xarray, pandas, plot ---------------------------

    def _summary(self) -> str:
        """The part of the repr a Motion and a SteadyState share (engineering units)."""
        duration = float(self.time[-1] - self.time[0]) if self.time.size > 1 else 0.0
        return (
            f"X = {self.amplitude * 1e6:.4g} um (x_max {self.x_max * 1e6:.4g} um, "
            f"x_min {self.x_min * 1e6:.4g} um), {self.time.size} samples over "
            f"{duration * 1e3:.4g} ms, {len(self.stages)} stages, "
            f"{self.impact_times.size} impacts, {self.events} events, "
            f"input {self.energy.input * 1e3:.4g} mJ, losses {self.energy.losses * 1e3:.4g} mJ, "
            f"balance error {self.energy.balance_error:.1e}"
        )

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._summary()})"

    def _scalars(self) -> dict[str, tuple[float | int, str]]:
        """Every scalar of the result with its unit: the 0-d variables of :meth:`to_xarray`."""
        values = {
            "x_max": (self.x_max, "m"),
            "x_min": (self.x_min, "m"),
            "amplitude": (self.amplitude, "m"),
            "stick_time": (self.stick_time, "s"),
            "events": (self.events, "1"),
            "final_displacement": (self.final_state[0], "m"),
            "final_velocity": (self.final_state[1], "m/s"),
        }
        for key, value in self.energy.as_dict().items():
            values[f"energy_{key}"] = (value, "J")
        return values

    def to_xarray(self) -> xr.Dataset:
        """Return the motion as an ``xarray.Dataset``, with each variable's unit in its attrs.

        Returns
        -------
        xarray.Dataset
            On ``time`` (N,): displacement, velocity, acceleration,
            excitation_force, restoring_force; on ``stage`` (S,): stage_name,
            stage_start, stage_end; on ``impact`` (I,): impact_time,
            impact_velocity; and 0-d variables for x_max, x_min, amplitude,
            stick_time, events, the final state and every entry of the energy
            ledger (``energy_input``, ...). ``attrs["units"]`` of each is SI.
        """
        import xarray as xr

        data = xr.Dataset(
            {
                "displacement": ("time", self.displacement, {"units": "m"}),
                "velocity": ("time", self.velocity, {"units": "m/s"}),
                "acceleration": ("time", self.acceleration, {"units": "m/s^2"}),
                "excitation_force": ("time", self.excitation, {"units": "N"}),
                "restoring_force": ("time", self.restoring_force, {"units": "N"}),
                "stage_name": ("stage", np.array([s.name for s in self.stages], dtype=str)),
                "stage_start": (
                    "stage",
                    np.array([s.start for s in self.stages], dtype=np.float64),
                    {"units": "s"},
                ),
                "stage_end": (
                    "stage",
                    np.array([s.end for s in self.stages], dtype=np.float64),
                    {"units": "s"},
                ),
                "impact_time": ("impact", self.impact_times, {"units": "s"}),
                "impact_velocity": ("impact", self.impact_velocities, {"units": "m/s"}),
            },
            coords={"time": ("time", self.time, {"units": "s"})},
            attrs={"title": f"clearjoint {type(self).__name__}"},
        )
        for name, (value, unit) in self._scalars().items():
            data[name] = ((), value, {"units": unit})
        return data

    def to_pandas(self) -> pd.DataFrame:
        """Return the sampled motion as a ``pandas.DataFrame``, one row per sample.

        Returns
        -------
        pandas.DataFrame
            Index ``time_s`` (N,); columns ``displacement_m``, ``velocity_m_per_s``,
            ``acceleration_m_per_s2``, ``excitation_force_n``, ``restoring_force_n``.
            Stages, impacts and the ledger are in :meth:`to_xarray`.
        """
        import pandas as pd

        return pd.DataFrame(
            {
                "displacement_m": self.displacement,
                "velocity_m_per_s": self.velocity,
                "acceleration_m_per_s2": self.acceleration,
                "excitation_force_n": self.excitation,
                "restoring_force_n": self.restoring_force,
            },
            index=pd.Index(self.time, name="time_s"),
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the displacement against time, contact stages shaded; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Its first line is x (um) against t (ms).
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        axes.plot(self.time * 1e3, self.displacement * 1e6, color="black", lw=1.4, label="x")
        shades = {"compression": ("0.78", "//"), "tension": ("0.9", "..")}  # grey print
        labelled: set[str] = set()
        for stage in self.stages:
            if stage.name not in shades:
                continue
            colour, hatch = shades[stage.name]
            axes.axvspan(
                stage.start * 1e3,
                stage.end * 1e3,
                facecolor=colour,
                edgecolor="0.5",
                hatch=hatch,
                lw=0,
                zorder=0,
                label=None if stage.name in labelled else stage.name,
            )
            labelled.add(stage.name)
        axes.set_xlabel("time (ms)")
        axes.set_ylabel("displacement x (µm)")
        axes.legend(frameon=False, fontsize="small")
        return axes


@dataclass(frozen=True)
class SteadyState(Motion):
    """The steady periodic response: one orbit of ``period_multiple`` forcing periods.

    Adds to :class:`Motion`: ``period_multiple`` (1 for period-1, n for a
    period-n orbit), ``period`` (s, the orbit's), ``periods_to_converge`` and
    ``initial_state`` (x, v, region, slip at the orbit's start, forcing phase 0),
    from which a continuation can start.
    """

    period_multiple: int = 1
    period: float = 0.0
    periods_to_converge: int = 0
    initial_state: tuple[float, float, int, int] = (0.0, 0.0, 0, 0)
    compression_penetration: float = 0.0
    tension_penetration: float = 0.0

    def __repr__(self) -> str:
        frequency = self.period_multiple / self.period if self.period > 0.0 else math.nan
        return (
            f"SteadyState(period-{self.period_multiple} orbit at {frequency:.5g} Hz forcing, "
            f"reached after {self.periods_to_converge} periods, "
            f"A_c = {self.compression_penetration * 1e6:.4g} um, "
            f"A_t = {self.tension_penetration * 1e6:.4g} um, {self._summary()})"
        )

    def _scalars(self) -> dict[str, tuple[float | int, str]]:
        values = super()._scalars()
        values["period_multiple"] = (self.period_multiple, "1")
        values["period"] = (self.period, "s")
        values["periods_to_converge"] = (self.periods_to_converge, "1")
        values["compression_penetration"] = (self.compression_penetration, "m")
        values["tension_penetration"] = (self.tension_penetration, "m")
        return values


@dataclass(frozen=True)
class FrequencySweep:
    """Stepped-sine sweep: steady amplitude against frequency, up and down.

    ``omega`` in rad/s; ``amplitude_up`` / ``amplitude_down`` in m (NaN where a
    direction was not swept or no steady state was found); ``multiple_up`` /
    ``multiple_down`` the period multiple of each orbit (0 where none).
    """

    omega: FloatArray
    amplitude_up: FloatArray
    amplitude_down: FloatArray
    multiple_up: NDArray[np.int64]
    multiple_down: NDArray[np.int64]
    steady_up: tuple[SteadyState | None, ...] = field(repr=False, default=())
    steady_down: tuple[SteadyState | None, ...] = field(repr=False, default=())

    def __repr__(self) -> str:
        f = self.omega / (2 * math.pi)

        def largest(values: FloatArray) -> str:
            return (
                f"{float(np.nanmax(values)) * 1e6:.4g} um" if np.any(np.isfinite(values)) else "-"
            )

        return (
            f"FrequencySweep({self.omega.size} frequencies, {f.min():.4g}-{f.max():.4g} Hz, "
            f"max X up {largest(self.amplitude_up)}, down {largest(self.amplitude_down)}, "
            f"{int(np.sum(self.multiple_up > 1) + np.sum(self.multiple_down > 1))} "
            "orbits of more than one period)"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the sweep as an ``xarray.Dataset`` on ``omega``, units in attrs.

        Returns
        -------
        xarray.Dataset
            Coordinates ``omega`` (n,) rad/s and ``frequency`` (Hz); ``amplitude_up``,
            ``amplitude_down`` (m, NaN where none) and ``multiple_up``,
            ``multiple_down`` (periods of each orbit, 0 where none).
        """
        import xarray as xr

        return xr.Dataset(
            {
                "amplitude_up": ("omega", self.amplitude_up, {"units": "m"}),
                "amplitude_down": ("omega", self.amplitude_down, {"units": "m"}),
                "multiple_up": ("omega", self.multiple_up, {"units": "forcing periods"}),
                "multiple_down": ("omega", self.multiple_down, {"units": "forcing periods"}),
            },
            coords={
                "omega": ("omega", self.omega, {"units": "rad/s"}),
                "frequency": ("omega", self.omega / (2 * math.pi), {"units": "Hz"}),
            },
            attrs={"title": "clearjoint stepped-sine sweep"},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the sweep as a ``pandas.DataFrame``, one row per frequency.

        Returns
        -------
        pandas.DataFrame
            ``to_xarray().to_dataframe()``: index ``omega`` (rad/s); columns
            ``frequency`` (Hz), ``amplitude_up``, ``amplitude_down`` (m),
            ``multiple_up``, ``multiple_down``.
        """
        return self.to_xarray().to_dataframe()

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the steady amplitude X (mm) against frequency (Hz), up and down; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Two lines, "sweep up" then "sweep down" (gaps where no orbit was found).
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        f = self.omega / (2 * math.pi)
        axes.plot(f, self.amplitude_up * 1e3, "-^", color="C0", ms=3, label="sweep up")
        axes.plot(f, self.amplitude_down * 1e3, "--v", color="C3", ms=3, label="sweep down")
        axes.set_xlabel("frequency (Hz)")
        axes.set_ylabel("amplitude X (mm)")
        axes.legend(frameon=False, fontsize="small")
        return axes
