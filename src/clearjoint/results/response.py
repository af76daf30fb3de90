"""The frequency-response curve and its events, one result for shooting and harmonic balance.

:class:`FrequencyResponse` is what both ``clearjoint.periodic.frequency_response``
(exact shooting, MODEL.md sec. 5.1) and ``clearjoint.harmonic.frequency_response``
(harmonic balance, MODEL.md sec. 5.3-5.4) return, with ``method`` saying which;
:class:`ResponseEvent` marks a fold, period doubling, grazing... along it. This
module imports no solver: a shooting curve carries the name of the module that made it
(``solver``, "clearjoint.periodic"), and the two methods that re-run exact orbits
(:meth:`FrequencyResponse.cycle`, :meth:`FrequencyResponse.period_2_orbit`) call back
into that module's ``orbit_cycle`` and ``period_2_orbit``.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import ParameterError
from clearjoint.results.motion import SteadyState
from clearjoint.results.orbit import PeriodicOrbit

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes

__all__ = ["FrequencyResponse", "ResponseEvent"]

FloatArray = NDArray[np.float64]

#: How each kind of event is marked on a curve: (marker, colour).
_MARKERS = {
    "fold": ("o", "k"),
    "period_doubling": ("s", "C2"),
    "grazing": ("^", "C1"),
    "neimark_sacker": ("D", "C4"),
}


@dataclass(frozen=True)
class ResponseEvent:
    """A fold, period doubling, grazing or other event found along a frequency-response curve.

    Attributes
    ----------
    kind : {"fold", "period_doubling", "grazing", "neimark_sacker", "untrusted", ...}
        The last two come from harmonic balance only (clearjoint.harmonic).
    omega : float
        rad/s.
    force_amplitude : float
        N.
    amplitude : float
        X of the period-1 orbit there, m.
    note : str
        What it means (e.g. that a period-2 branch is born there).
    """

    kind: str
    omega: float
    force_amplitude: float
    amplitude: float
    note: str = ""

    def __repr__(self) -> str:
        return (
            f"ResponseEvent({self.kind}, {self.omega / (2 * math.pi):.6g} Hz, "
            f"F0={self.force_amplitude:.4g} N, X={self.amplitude:.4g} m)"
        )

    def to_xarray(self) -> xr.Dataset:
        """Return the event as an ``xarray.Dataset`` of 0-d variables, units in attrs.

        Returns
        -------
        xarray.Dataset
            ``kind``, ``omega`` (rad/s), ``frequency`` (Hz), ``force_amplitude`` (N),
            ``amplitude`` (m); ``attrs["note"]`` says what it means.
        """
        import xarray as xr

        return xr.Dataset(
            {
                "kind": ((), self.kind),
                "omega": ((), self.omega, {"units": "rad/s"}),
                "frequency": ((), self.omega / (2 * math.pi), {"units": "Hz"}),
                "force_amplitude": ((), self.force_amplitude, {"units": "N"}),
                "amplitude": ((), self.amplitude, {"units": "m"}),
            },
            attrs={"title": f"clearjoint {self.kind} event", "note": self.note},
        )

    def to_pandas(self) -> pd.DataFrame:
        """Return the event as a one-row ``pandas.DataFrame`` (an event has no longer table).

        Columns ``kind``, ``frequency_hz``, ``omega_rad_per_s``, ``force_n``,
        ``amplitude_m``, ``note``; a curve's events together are in
        :meth:`FrequencyResponse.to_xarray`.
        """
        import pandas as pd

        return pd.DataFrame(
            {
                "kind": [self.kind],
                "frequency_hz": [self.omega / (2 * math.pi)],
                "omega_rad_per_s": [self.omega],
                "force_n": [self.force_amplitude],
                "amplitude_m": [self.amplitude],
                "note": [self.note],
            }
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Mark the event at (frequency in Hz, X in mm) on ``ax``; return the Axes.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (usually a curve's plot); a new figure's Axes when None.

        Returns
        -------
        matplotlib.axes.Axes
            Its last line is the one marker, labelled with the event's kind.
        """
        from clearjoint.plotting import axes_or_new

        axes: Axes = axes_or_new(ax)
        marker, color = _MARKERS.get(self.kind, ("x", "k"))
        axes.plot(
            [self.omega / (2 * math.pi)],
            [self.amplitude * 1e3],
            marker,
            color=color,
            ls="none",
            mfc="none",
            label=self.kind,
        )
        axes.set_xlabel("frequency (Hz)")
        axes.set_ylabel("amplitude X (mm)")
        return axes


#: A Structure's curve labels the DOFs with the largest amplitude, this many (C0 to C7).
_LABELLED = 8


@dataclass(frozen=True)
class FrequencyResponse:
    """A whole frequency-response curve of exact period-1 orbits, stable and unstable.

    Attributes
    ----------
    omega, force_amplitude : (n,) ndarray
        rad/s and N at each point (one of them is constant).
    x_max, x_min, amplitude : (n,) ndarray
        Extremes and X = (x_max - x_min)/2 of each orbit, m.
    stable : (n,) ndarray of bool
    multipliers : (n, 2) complex ndarray
        Floquet multipliers of each orbit.
    initial_state : (n, 2) ndarray
        (x, x') at forcing phase 0, m and m/s.
    events : list of ResponseEvent
    parameter : {"omega", "force"}
    stop_reason : str
        Why the continuation stopped ("reached" when it got to the end).
    coefficients : ndarray, optional
        Harmonic balance only (``method == "harmonic"``): the harmonic coefficients
        a_0, a_1, b_1, ..., a_H, b_H of each point, m, (n, 2H + 1) for a Joint and
        (n, 2H + 1, N) for a Structure (whose x_max, x_min, amplitude are then (n, N)).
    method : {"shooting", "harmonic"}
        Exact shooting (``clearjoint.periodic``) or harmonic balance (``clearjoint.harmonic``).
    free_play : (n,) ndarray of bool, optional
        True where the orbit stays inside the gap with gap_stiffness 0: one of a
        continuum of orbits (any mean position that keeps it off the edges; Floquet
        multiplier exactly 1, so ``stable`` is False), of which the curve shows the one
        centred in the gap. Its amplitude is set by the dynamics, its position is not.
        None for harmonic balance.
    dof_names : tuple of str, optional
        A Structure's curve (harmonic balance): the name of each DOF, in the order of
        the last axis of x_max, x_min, amplitude and coefficients (``Structure.dof_names``);
        the plot's legend and the ``dof`` coordinate of :meth:`to_xarray`. None for a
        Joint's curve.
    """

    omega: FloatArray
    force_amplitude: FloatArray
    x_max: FloatArray
    x_min: FloatArray
    amplitude: FloatArray
    stable: NDArray[np.bool_]
    multipliers: NDArray[np.complex128]
    initial_state: FloatArray
    events: list[ResponseEvent]
    parameter: str
    stop_reason: str
    settings: dict[str, Any] = field(repr=False, default_factory=dict)
    coefficients: FloatArray | None = field(repr=False, default=None)
    method: str = "shooting"
    free_play: NDArray[np.bool_] | None = field(repr=False, default=None)
    dof_names: tuple[str, ...] | None = field(repr=False, default=None)
    solver: str | None = field(repr=False, default=None)

    def __repr__(self) -> str:
        kinds = ", ".join(
            f"{sum(e.kind == k for e in self.events)} {k}"
            for k in ("fold", "period_doubling", "grazing")
        )
        others = sorted({e.kind for e in self.events} - {"fold", "period_doubling", "grazing"})
        kinds += "".join(f", {sum(e.kind == k for e in self.events)} {k}" for k in others)
        f = self.omega / (2 * math.pi)
        if self.free_play is not None and self.free_play.any():
            kinds += f", {int(np.sum(self.free_play))} free play"
        return (
            f"FrequencyResponse({self.omega.size} points, {f.min():.4g}-{f.max():.4g} Hz, "
            f"F0 {self.force_amplitude.min():.4g}-{self.force_amplitude.max():.4g} N, "
            f"max X={self.amplitude.max():.4g} m, {int(np.sum(~self.stable))} unstable, "
            f"{kinds}, {self.stop_reason})"
        )

    def _solver(self, what: str) -> Any:
        """The module that made this shooting curve, which re-runs its orbits."""
        if self.method == "shooting" and self.solver is None:
            raise ParameterError(
                f"{what} re-runs a single joint's orbits; for a point of a structure's curve "
                "use clearjoint.structure.periodic_orbit(structure, force, omega[index], "
                "initial=(u0, v0)) with initial_state[index] split into u(0) and u'(0)"
            )
        if self.method != "shooting" or self.solver is None:
            raise ParameterError(
                f"{what} re-runs exact orbits of a shooting curve, and this is a "
                f"{self.method!r} curve; for one of its points use "
                "clearjoint.periodic.periodic_orbit(..., initial=initial_state[index])"
            )
        return importlib.import_module(self.solver)

    def cycle(self, index: int) -> SteadyState:
        """Return the orbit at point ``index`` as a SteadyState (stages, ledger), re-run exactly.

        MODEL.md sec. 5.1; by the solver that made the curve (``solver``).
        """
        solver = self._solver("cycle()")
        return solver.orbit_cycle(  # type: ignore[no-any-return]
            self.settings["joint"],
            float(self.force_amplitude[index]),
            float(self.omega[index]),
            self.initial_state[index],
            losses=self.settings["losses"],
        )

    def period_2_orbit(self, event: ResponseEvent) -> PeriodicOrbit:
        """Switch branches at a period doubling: the period-2 orbit born there (MODEL.md sec. 5.1).

        By the solver that made the curve (``solver``): see
        :func:`clearjoint.periodic.period_2_orbit`, whose errors it raises (and
        ParameterError for a curve not from shooting).
        """
        solver = self._solver("period_2_orbit")
        return solver.period_2_orbit(self, event)  # type: ignore[no-any-return]

    def plot(self, ax: Axes | None = None) -> Axes:
        """Plot X against frequency (Hz) or force (N): stable solid, unstable dashed, events marked.

        Free-play orbits (``free_play``: a continuum inside the gap) are dotted grey. A
        Structure's curve (X of shape (n, N)) draws one curve per DOF: the 8 that move
        most in their own colours, labelled (``dof_names`` or "DOF k"),
        the others light grey.

        Returns
        -------
        matplotlib.axes.Axes
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6.4, 4.0))
        if self.parameter == "force":
            xs, label = self.force_amplitude, "force amplitude F0 (N)"
        else:
            xs, label = self.omega / (2 * math.pi), "frequency (Hz)"
        ys = self.amplitude * 1e3
        free = np.zeros(self.stable.size, dtype=bool) if self.free_play is None else self.free_play
        style = np.where(free, 2, self.stable.astype(int))  # 0 unstable, 1 stable, 2 free play
        looks = {0: ("--", "C3"), 1: ("-", "C0"), 2: (":", "0.4")}
        columns = ys.reshape(ys.shape[0], -1)
        per_dof = ys.ndim == 2  # a Structure by harmonic balance: one curve per DOF
        names = self._dof_labels()
        # the _LABELLED DOFs that move most get their own colour and legend entry
        peak = np.nan_to_num(np.nanmax(np.abs(columns), axis=0, initial=0.0))
        labelled = np.argsort(-peak, kind="stable")[:_LABELLED].tolist()
        for k in range(columns.shape[1]):
            own = f"C{labelled.index(k)}" if k in labelled else "0.75"
            start = 0
            for i in range(1, style.size + 1):
                if i == style.size or style[i] != style[start]:
                    end = min(i + 1, style.size)
                    line, color = looks[int(style[start])]
                    if per_dof and style[start] != 2:
                        color = own
                    ax.plot(xs[start:end], columns[start:end, k], line, color=color, lw=1.5)
                    start = i
        if per_dof:
            for k in labelled:
                ax.plot([], [], "-", color=f"C{labelled.index(k)}", label=names[k])
            if columns.shape[1] > len(labelled):
                ax.plot([], [], "-", color="0.75", label="other DOFs")
            ax.plot([], [], "-", color="k", label="stable (solid)")
            ax.plot([], [], "--", color="k", label="unstable (dashed)")
        else:
            ax.plot([], [], "-", color="C0", label="stable")
            ax.plot([], [], "--", color="C3", label="unstable")
        if free.any():
            ax.plot([], [], ":", color="0.4", label="free play (centred; position not set)")
        for kind, (marker, color) in _MARKERS.items():
            chosen = [e for e in self.events if e.kind == kind]
            if chosen:
                ex = [
                    e.force_amplitude if self.parameter == "force" else e.omega / (2 * math.pi)
                    for e in chosen
                ]
                ey = [e.amplitude * 1e3 for e in chosen]
                ax.plot(ex, ey, marker, color=color, ls="none", mfc="none", label=kind)
        ax.set_xlabel(label)
        ax.set_ylabel("amplitude X (mm)")
        ax.legend(frameon=False, fontsize="small")
        return ax

    def to_xarray(self) -> xr.Dataset:
        """The curve as an xarray Dataset over ``point`` (and ``event``), units in attrs."""
        import xarray as xr

        # harmonic balance of a Structure: per-DOF extremes (n, N), u(0) then u'(0) (n, 2N)
        per = ("point",) if self.x_max.ndim == 1 else ("point", "dof")
        n_dof = 1 if self.x_max.ndim == 1 else self.x_max.shape[1]
        x0 = self.initial_state[:, :n_dof].reshape(self.x_max.shape)
        v0 = self.initial_state[:, n_dof:].reshape(self.x_max.shape)
        ds = xr.Dataset(
            {
                "x_max": (per, self.x_max, {"units": "m"}),
                "x_min": (per, self.x_min, {"units": "m"}),
                "amplitude": (per, self.amplitude, {"units": "m"}),
                "stable": ("point", self.stable.astype(np.int8), {"units": "1 stable, 0 not"}),
                "multiplier_real": (("point", "multiplier"), self.multipliers.real.copy()),
                "multiplier_imag": (("point", "multiplier"), self.multipliers.imag.copy()),
                "initial_displacement": (per, x0, {"units": "m"}),
                "initial_velocity": (per, v0, {"units": "m/s"}),
                **(
                    {}
                    if self.free_play is None
                    else {
                        "free_play": (
                            "point",
                            self.free_play.astype(np.int8),
                            {
                                "units": "1 in the gap (k0 = 0), 0 not",
                                "note": "1: one of a continuum of orbits; the position is not "
                                "set by the dynamics, the one centred in the gap is given",
                            },
                        )
                    }
                ),
                "event_kind": ("event", np.array([e.kind for e in self.events], dtype=str)),
                "event_frequency": (
                    "event",
                    np.array([e.omega / (2 * math.pi) for e in self.events]),
                    {"units": "Hz"},
                ),
                "event_force": (
                    "event",
                    np.array([e.force_amplitude for e in self.events]),
                    {"units": "N"},
                ),
                "event_amplitude": (
                    "event",
                    np.array([e.amplitude for e in self.events]),
                    {"units": "m"},
                ),
            },
            coords={
                "omega": ("point", self.omega, {"units": "rad/s"}),
                "frequency": ("point", self.omega / (2 * math.pi), {"units": "Hz"}),
                "force_amplitude": ("point", self.force_amplitude, {"units": "N"}),
            },
            attrs={
                "title": "clearjoint frequency response (exact periodic orbits, continuation)",
                "parameter": self.parameter,
                "stop_reason": self.stop_reason,
                "method": self.method,
            },
        )
        if self.coefficients is not None:
            dims = ("point", "coefficient", "dof")[: self.coefficients.ndim]
            ds["coefficients"] = (
                dims,
                self.coefficients,
                {"units": "m", "order": "a_0, a_1, b_1, ..., a_H, b_H of cos/sin(h w t)"},
            )
            ds.attrs["title"] = "clearjoint frequency response (harmonic balance, continuation)"
        if self.dof_names is not None and ds.sizes.get("dof") == len(self.dof_names):
            ds = ds.assign_coords(dof=("dof", list(self.dof_names)))
        return ds

    def to_pandas(self) -> pd.DataFrame:
        """Return the curve as a ``pandas.DataFrame``, one row per point.

        Returns
        -------
        pandas.DataFrame
            Index ``point``; columns ``frequency_hz``, ``omega_rad_per_s``, ``force_n``,
            ``amplitude_m``, ``x_max_m``, ``x_min_m``, ``stable`` (and ``free_play``
            when set). A Structure's curve has one amplitude, x_max and x_min column
            per DOF, named ``amplitude_m[<dof name>]``. Events, multipliers and
            coefficients are in :meth:`to_xarray`.
        """
        import pandas as pd

        columns: dict[str, Any] = {
            "frequency_hz": self.omega / (2 * math.pi),
            "omega_rad_per_s": self.omega,
            "force_n": self.force_amplitude,
        }
        names = self._dof_labels()
        for key, values in (
            ("amplitude", self.amplitude),
            ("x_max", self.x_max),
            ("x_min", self.x_min),
        ):
            if values.ndim == 1:
                columns[f"{key}_m"] = values
            else:
                columns.update({f"{key}_m[{name}]": values[:, k] for k, name in enumerate(names)})
        columns["stable"] = self.stable
        if self.free_play is not None:
            columns["free_play"] = self.free_play
        return pd.DataFrame(columns, index=pd.RangeIndex(self.omega.size, name="point"))

    def _dof_labels(self) -> list[str]:
        """Return the name of each DOF of a Structure's curve (``dof_names`` or "DOF k")."""
        n = 1 if self.amplitude.ndim == 1 else self.amplitude.shape[1]
        # settings["dof_names"]: the curves made before dof_names was an attribute
        given = self.dof_names if self.dof_names is not None else self.settings.get("dof_names")
        names = list(given or [])
        return names if len(names) == n else [f"DOF {k}" for k in range(n)]
