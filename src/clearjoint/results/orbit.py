"""The exact periodic orbit with its stability, the result of shooting (MODEL.md sec. 5.1).

:class:`PeriodicOrbit` is what ``clearjoint.periodic.periodic_orbit`` and
``FrequencyResponse.period_2_orbit`` return: the orbit's start at forcing phase 0,
the sampled cycle (a :class:`~clearjoint.results.motion.SteadyState`), the exact
monodromy matrix and its Floquet multipliers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from clearjoint.results.motion import SteadyState

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes

__all__ = ["PeriodicOrbit"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class PeriodicOrbit:
    """An exact periodic orbit of ``period_multiple`` forcing periods, with its stability.

    Attributes
    ----------
    initial_state : tuple of float
        (x0, x0') at forcing phase 0, m and m/s.
    cycle : SteadyState
        The orbit sampled, with its stages and energy ledger.
    monodromy : (2, 2) ndarray
        dP_p/dz0, exact (closed-form flows and saltation matrices).
    multipliers : (2,) complex ndarray
        Floquet multipliers, eig(monodromy).
    stable : bool
        Every multiplier has modulus < 1.
    omega, force_amplitude : float
        rad/s and N.
    period_multiple : int
    newton_iterations : int
    """

    initial_state: tuple[float, float]
    cycle: SteadyState = field(repr=False)
    monodromy: FloatArray = field(repr=False)
    multipliers: NDArray[np.complex128] = field(repr=False)
    stable: bool
    omega: float
    force_amplitude: float
    period_multiple: int = 1
    newton_iterations: int = 0

    @property
    def x_max(self) -> float:
        """Largest x along the orbit, m."""
        return self.cycle.x_max

    @property
    def x_min(self) -> float:
        """Smallest x along the orbit, m."""
        return self.cycle.x_min

    @property
    def amplitude(self) -> float:
        """X = (x_max - x_min) / 2, m."""
        return self.cycle.amplitude

    def __repr__(self) -> str:
        mu = float(np.max(np.abs(self.multipliers)))
        return (
            f"PeriodicOrbit(period-{self.period_multiple}, {self.omega / (2 * math.pi):.6g} Hz, "
            f"F0={self.force_amplitude:.4g} N, X={self.amplitude:.4g} m, "
            f"{'stable' if self.stable else 'unstable'}, max|mu|={mu:.4g})"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the orbit as an ``xarray.Dataset``: cycle, multipliers, monodromy, units in attrs.

        Returns
        -------
        xarray.Dataset
            The cycle's :meth:`SteadyState.to_xarray` (on ``time``, ``stage``,
            ``impact``), plus ``omega`` (rad/s), ``frequency`` (Hz),
            ``force_amplitude`` (N), ``initial_displacement`` (m),
            ``initial_velocity`` (m/s), ``stable``, ``newton_iterations``,
            ``multiplier_real`` / ``multiplier_imag`` on ``multiplier`` (2,) and
            ``monodromy`` on (``row``, ``column``) (2, 2).
        """
        data = self.cycle.to_xarray()
        data.attrs["title"] = f"clearjoint period-{self.period_multiple} orbit (exact shooting)"
        data["omega"] = ((), self.omega, {"units": "rad/s"})
        data["frequency"] = ((), self.omega / (2 * math.pi), {"units": "Hz"})
        data["force_amplitude"] = ((), self.force_amplitude, {"units": "N"})
        data["initial_displacement"] = ((), self.initial_state[0], {"units": "m"})
        data["initial_velocity"] = ((), self.initial_state[1], {"units": "m/s"})
        data["stable"] = ((), int(self.stable), {"units": "1 stable, 0 not"})
        data["newton_iterations"] = ((), self.newton_iterations, {"units": "1"})
        data["multiplier_real"] = ("multiplier", self.multipliers.real.copy(), {"units": "1"})
        data["multiplier_imag"] = ("multiplier", self.multipliers.imag.copy(), {"units": "1"})
        data["monodromy"] = (
            ("row", "column"),
            np.asarray(self.monodromy, dtype=np.float64),
            {"units": "[[1, s], [1/s, 1]]: dP/dz0 of z = (x in m, x' in m/s)"},
        )
        return data

    def to_pandas(self) -> pd.DataFrame:
        """Return the orbit's samples as a ``pandas.DataFrame``, one row per sample.

        An orbit's natural table is its cycle: this is ``cycle.to_pandas()`` (index
        ``time_s``; displacement, velocity, acceleration and forces in SI, the unit
        in each column's name). The multipliers and the monodromy are in
        :meth:`to_xarray`.
        """
        return self.cycle.to_pandas()

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the orbit's displacement over its cycle, contact stages shaded; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw; a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Its first line is x (um) against t (ms), titled with the frequency and stability.
        """
        axes = self.cycle.plot(ax)
        axes.set_title(
            f"period-{self.period_multiple} orbit, {self.omega / (2 * math.pi):.4g} Hz, "
            f"{'stable' if self.stable else 'unstable'}",
            fontsize="small",
        )
        return axes
