"""Amplitude-dependent frequency and damping from a free decay, cycle by cycle (MODEL.md 5.4).

Method: per-cycle peaks. Each maximum of the signal is located where its velocity
crosses zero downward (a quadratic through three velocity samples, then the cubic
Hermite interpolant of u, which uses u and v at both ends); cycle k runs from maximum k
to maximum k+1. Its frequency is 2 pi / (t_(k+1) - t_k), its amplitude half the
peak-to-valley height (u_max,k - u_min,k) / 2 (so a mean offset from an off-centre gap
drops out), and its damping ratio comes from the logarithmic decrement of successive
amplitudes, zeta = d / sqrt(4 pi^2 + d^2), d = ln(a_k / a_(k+1)).

Why peaks rather than the Hilbert transform: a clearance joint's ring-down is far
from sinusoidal (flat free-play stretches, stiff contact caps, an offset mean), so the
analytic signal's phase wobbles within a cycle and its envelope carries the harmonics;
the Hilbert route then needs band-pass filtering and loses the first and last cycles
to end effects. Peaks and their spacing are what a lab reads off a ring-down, need no
filter, and for a linear system are exact: successive maxima of
e^(-zeta w t) cos(w_d t) are exactly 2 pi / w_d apart and decay by exp(-zeta w 2 pi / w_d).
With ``mode`` the signal is first projected on a closed-pattern mode, q = phi^T M u,
which removes the other modes' contributions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.structure.model import StructureError, system_modes
from clearjoint.structure.motion import StructureMotion

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Backbone:
    """Per-cycle amplitude, frequency and damping ratio of a free decay.

    Attributes
    ----------
    time : (K,) ndarray
        Middle of each cycle, s.
    amplitude : (K,) ndarray
        Half the peak-to-valley displacement of the cycle at ``dof``, m.
    omega : (K,) ndarray
        2 pi / cycle duration, rad/s.
    damping_ratio : (K,) ndarray
        From the decrement between this cycle's amplitude and the next (NaN on the last).
    dof : int
    mode : int or None
    """

    time: FloatArray
    amplitude: FloatArray
    omega: FloatArray
    damping_ratio: FloatArray
    dof: int
    mode: int | None

    def __repr__(self) -> str:
        if self.amplitude.size == 0:
            return "Backbone(no complete cycle)"
        f = self.omega / (2.0 * math.pi)
        return (
            f"Backbone({self.amplitude.size} cycles, amplitude {self.amplitude[0]:.3g} -> "
            f"{self.amplitude[-1]:.3g} m, f {f[0]:.4g} -> {f[-1]:.4g} Hz)"
        )

    def plot(self, ax: Any = None) -> Any:
        """Frequency (Hz) against amplitude (mm), damping ratio on a twin axis; return the Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        ax.plot(1e3 * self.amplitude, self.omega / (2.0 * math.pi), "o-", ms=3, label="frequency")
        ax.set_xlabel("amplitude (mm)")
        ax.set_ylabel("frequency (Hz)")
        twin = ax.twinx()
        twin.plot(1e3 * self.amplitude, 100.0 * self.damping_ratio, "s--", ms=3, color="C1")
        twin.set_ylabel("damping ratio (%)", color="C1")
        return ax

    def to_xarray(self) -> Any:
        """The backbone as an xarray Dataset, units in attrs."""
        import xarray as xr

        return xr.Dataset(
            {
                "amplitude": ("cycle", self.amplitude, {"units": "m"}),
                "omega": ("cycle", self.omega, {"units": "rad/s"}),
                "damping_ratio": ("cycle", self.damping_ratio, {"units": "1"}),
                "cycle_time": ("cycle", self.time, {"units": "s"}),
            },
            attrs={
                "dof": self.dof,
                "mode": -1 if self.mode is None else self.mode,
                "method": "per-cycle peaks",
            },
        )

    def to_pandas(self) -> Any:
        """Return the backbone as a ``pandas.DataFrame``, one row per cycle.

        Returns
        -------
        pandas.DataFrame
            Index ``cycle_time_s`` (the middle of each cycle); columns ``amplitude_m``,
            ``omega_rad_per_s``, ``frequency_hz`` and ``damping_ratio``.
        """
        import pandas as pd

        return pd.DataFrame(
            {
                "amplitude_m": self.amplitude,
                "omega_rad_per_s": self.omega,
                "frequency_hz": self.omega / (2.0 * math.pi),
                "damping_ratio": self.damping_ratio,
            },
            index=pd.Index(self.time, name="cycle_time_s"),
        )


def _maxima(t: FloatArray, u: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Times and values of the maxima: v crossing zero downward, refined between samples."""
    idx = np.flatnonzero((v[:-1] > 0.0) & (v[1:] <= 0.0))
    times = np.empty(idx.size)
    values = np.empty(idx.size)
    for n, i in enumerate(idx):
        j = min(max(int(i), 1), t.size - 2)  # quadratic through v at j-1, j, j+1
        coef = np.polyfit(t[j - 1 : j + 2] - t[i], v[j - 1 : j + 2], 2)
        roots = np.roots(coef)
        h = t[i + 1] - t[i]
        good = [r.real for r in roots if abs(r.imag) < 1e-12 * h and -1e-9 * h <= r.real <= h]
        s = min(good) if good else h * v[i] / (v[i] - v[i + 1])
        # cubic Hermite of u on [t_i, t_i+1] from u and v at both ends
        x = s / h
        h00 = 2 * x**3 - 3 * x**2 + 1
        h10 = x**3 - 2 * x**2 + x
        h01 = -2 * x**3 + 3 * x**2
        h11 = x**3 - x**2
        times[n] = t[i] + s
        values[n] = h00 * u[i] + h10 * h * v[i] + h01 * u[i + 1] + h11 * h * v[i + 1]
    return times, values


def decay_backbone(motion: StructureMotion, dof: int, mode: int | None = None) -> Backbone:
    """Return amplitude (m), frequency (rad/s) and damping ratio per cycle of a free decay.

    MODEL.md 5.4, by per-cycle peaks (see the module docstring for the method and why).

    Parameters
    ----------
    motion : StructureMotion
        A free decay (``free_decay``), sampled finely enough to resolve each cycle; a
        forced motion (input work not 0) is refused.
    dof : int
        The DOF whose displacement is measured (index into ``motion.dof_names``).
    mode : int, optional
        1-based closed-pattern mode to project the motion on first; the amplitude is
        then that mode's contribution at ``dof``.

    Returns
    -------
    Backbone
    """
    n_dof = motion.u.shape[1]
    if motion.energy.input != 0.0:  # a forced response's decrement is no damping ratio
        raise StructureError(
            f"decay_backbone reads a free decay, but this motion was forced (input work "
            f"{motion.energy.input:.3g} J); use structure.free_decay for the ring-down"
        )
    if isinstance(dof, bool) or not isinstance(dof, int | np.integer) or not 0 <= dof < n_dof:
        raise StructureError(f"dof must be an index from 0 to {n_dof - 1}, got {dof!r}")
    u = motion.u[:, dof]
    v = motion.v[:, dof]
    if mode is not None:
        s = motion.structure
        if s is not None:  # the structure's own modes, in its arithmetic order
            modes, masses = s.modes("closed"), s.mass_diagonal()
        elif motion.system is not None:
            modes, masses = system_modes(motion.system), motion.system.mass_diagonal()
        else:
            raise StructureError("mode= needs the motion's structure or system; it has neither")
        if isinstance(mode, bool) or not isinstance(mode, int) or not 1 <= mode <= modes.omega.size:
            raise StructureError(f"mode must be from 1 to {modes.omega.size}, got {mode!r}")
        phi = modes.shapes[:, mode - 1]
        weight = phi * masses
        u = (motion.u @ weight) * phi[dof]
        v = (motion.v @ weight) * phi[dof]
        if phi[dof] < 0.0:
            u, v = -u, -v
    t_max, u_max = _maxima(motion.t, u, v)
    t_min, u_min = _maxima(motion.t, -u, -v)
    u_min = -u_min
    times, amps, omegas = [], [], []
    for k in range(t_max.size - 1):
        inside = (t_min > t_max[k]) & (t_min < t_max[k + 1])
        if not inside.any():
            continue
        valley = float(u_min[inside][0])
        amps.append(0.5 * (u_max[k] - valley))
        omegas.append(2.0 * math.pi / (t_max[k + 1] - t_max[k]))
        times.append(0.5 * (t_max[k] + t_max[k + 1]))
    amplitude = np.array(amps)
    zeta = np.full(amplitude.size, np.nan)
    if amplitude.size > 1:
        with np.errstate(divide="ignore", invalid="ignore"):
            d = np.log(amplitude[:-1] / amplitude[1:])
        zeta[:-1] = d / np.sqrt(4.0 * math.pi**2 + d**2)
    return Backbone(
        time=np.array(times),
        amplitude=amplitude,
        omega=np.array(omegas),
        damping_ratio=zeta,
        dof=int(dof),
        mode=mode,
    )
