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


@dataclass(frozen=True)
class Stage:
    """One stage of the motion: ``name`` in {"free-play", "compression", "tension"}, times in s."""

    name: str
    start: float
    end: float


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
