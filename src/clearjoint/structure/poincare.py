"""The exact p-period map of a structure, Newton on it, and the orbit it closes (MODEL.md 5.1).

The map P carries the state z = (u, v) at forcing phase 0 over p forcing periods with the
exact event-driven motion (``clearjoint.structure.motion``). A periodic orbit solves
R(z) = P(z) - z = 0; Newton uses the exact Jacobian dR/dz = Phi - I, Phi the monodromy:
the ordered product of the contact patterns' exponentials over the stretches the motion
met (``clearjoint.structure.tangent``; the saltation matrices are the identity, the
clearance law's force being continuous). The Floquet multipliers are Phi's eigenvalues:
the orbit is stable when all lie inside the unit circle. Converged when the closure
abs(P(z) - z) is below ``CLOSURE`` of the orbit's size (norm of (w u, v)).

The extremes x_max, x_min of each DOF are the extremes of the sampled orbit refined by
the local cubic of the exact motion about the sample nearest each turning point (velocity,
acceleration and jerk from the equations of motion in the sample's contact pattern), to
about 1e-9 of the amplitude with 512 samples a period.

This module is the exact machinery alone (no seeds): :func:`clearjoint.structure.periodic_orbit`
seeds it, and harmonic balance checks its own orbits with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from clearjoint.simulate.core import SimulationError
from clearjoint.structure.motion import StructureMotion, _Flow, _run
from clearjoint.structure.tangent import (
    PatternFlows,
    carry,
    impact_jumps,
    pattern_history,
    refuse_restitution,
)
from clearjoint.system import VibrationSystem

FloatArray = NDArray[np.float64]

__all__ = [
    "CLOSURE",
    "OrbitError",
    "ShootingMap",
    "StructureOrbit",
    "newton_orbit",
    "orbit_at",
    "sorted_multipliers",
    "turning_extremes",
]

#: Converged when abs(P(z) - z) is below this fraction of abs(z) (norm of (w u, v)).
CLOSURE = 1e-10
#: Newton iterations at most.
MAX_ITERATIONS = 40
#: Samples a period of the orbit kept (for its extremes and its picture).
SAMPLES_PER_PERIOD = 512


class OrbitError(SimulationError):
    """No periodic orbit converged from the seeds tried."""


@dataclass(frozen=True)
class StructureOrbit:
    """An exact periodic orbit of a forced structure, with its monodromy and stability.

    Attributes
    ----------
    omega : float
        Forcing circular frequency, rad/s.
    force : (N,) ndarray
        Force amplitude per DOF, N.
    period_multiple : int
        p: the orbit closes after p forcing periods.
    initial_state : (u, v)
        The state at forcing phase 0, each (N,) in m and m/s (pass it as ``initial=`` to
        ``clearjoint.structure.time_response`` to run on from the orbit).
    x_max, x_min : (N,) ndarray
        Each DOF's extremes over the orbit, m.
    monodromy : (2N, 2N) ndarray
        d P / d z over the p periods, exact.
    multipliers : (2N,) complex ndarray
        Floquet multipliers, largest modulus first.
    stable : bool
        All multipliers inside the unit circle.
    events : int
        Gap-edge crossings over one orbit (p periods).
    motion : StructureMotion
        The orbit over p periods, sampled.
    closure : float
        abs(P(z) - z) / abs(z) reached, norm of (w u, v).
    iterations : int
        Newton iterations.
    seed : str
        Where Newton started: "harmonic balance", "initial" or "transient".
    dof_names : tuple of str
    """

    omega: float
    force: FloatArray
    period_multiple: int
    initial_state: tuple[FloatArray, FloatArray]
    x_max: FloatArray
    x_min: FloatArray
    monodromy: FloatArray = field(repr=False)
    multipliers: NDArray[np.complex128] = field(repr=False)
    stable: bool
    events: int
    motion: StructureMotion = field(repr=False)
    closure: float
    iterations: int
    seed: str
    dof_names: tuple[str, ...] = field(repr=False, default=())

    @property
    def amplitude(self) -> FloatArray:
        """(x_max - x_min) / 2 per DOF, m."""
        return np.asarray(0.5 * (self.x_max - self.x_min), dtype=np.float64)

    @property
    def largest_multiplier(self) -> float:
        """abs(mu) of the largest Floquet multiplier."""
        return float(np.abs(self.multipliers[0]))

    def __repr__(self) -> str:
        k = int(np.argmax(self.amplitude))
        name = self.dof_names[k] if self.dof_names else f"DOF {k}"
        return (
            f"StructureOrbit({self.omega / (2 * math.pi):.6g} Hz, period {self.period_multiple}, "
            f"max X={self.amplitude[k]:.4g} m at {name}, {self.events} events, "
            f"{'stable' if self.stable else 'unstable'} (|mu|max={self.largest_multiplier:.4g}), "
            f"closure {self.closure:.1e})"
        )

    def plot(self, ax: Any = None, *, dof: int | None = None) -> Any:
        """The orbit's phase portrait (u in mm, v in mm/s) of ``dof`` (default the largest)."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        if dof is None:
            dof = int(np.argmax(self.amplitude))
        m = self.motion
        u = np.append(m.u[:, dof], self.initial_state[0][dof])
        v = np.append(m.v[:, dof], self.initial_state[1][dof])
        ax.plot(1e3 * u, 1e3 * v, lw=1.0)
        ax.plot(1e3 * u[:1], 1e3 * v[:1], "o", color="k", ms=4, label="phase 0")
        name = self.dof_names[dof] if self.dof_names else f"DOF {dof}"
        ax.set_xlabel(f"{name} displacement (mm)")
        ax.set_ylabel(f"{name} velocity (mm/s)")
        ax.set_title(
            f"{self.omega / (2 * math.pi):.4g} Hz, {'stable' if self.stable else 'unstable'}"
        )
        ax.legend(frameon=False)
        return ax

    def to_xarray(self) -> Any:
        """The orbit as an xarray Dataset (extremes, initial state, multipliers), units in attrs."""
        import xarray as xr

        names = list(self.dof_names) or [f"u{k + 1}" for k in range(self.force.size)]
        mu = self.multipliers
        return xr.Dataset(
            {
                "x_max": ("dof", self.x_max, {"units": "m"}),
                "x_min": ("dof", self.x_min, {"units": "m"}),
                "u0": ("dof", self.initial_state[0], {"units": "m"}),
                "v0": ("dof", self.initial_state[1], {"units": "m/s"}),
                "force": ("dof", self.force, {"units": "N"}),
                "multiplier_real": ("multiplier", mu.real, {"units": "1"}),
                "multiplier_imag": ("multiplier", mu.imag, {"units": "1"}),
            },
            coords={"dof": names, "multiplier": np.arange(mu.size)},
            attrs={
                "frequency_Hz": self.omega / (2 * math.pi),
                "period_multiple": self.period_multiple,
                "stable": int(self.stable),
                "events": self.events,
                "closure": self.closure,
                "seed": self.seed,
            },
        )


class ShootingMap:
    """The exact p-period map of one structure at one frequency, with its exact Jacobian.

    Parameters
    ----------
    system : VibrationSystem
    force : (N,) ndarray
        N.
    omega : float
        rad/s.
    period_multiple : int
    flows : PatternFlows, optional
        The patterns' decompositions, shared between frequencies (they do not depend on w).
    """

    def __init__(
        self,
        system: VibrationSystem,
        force: FloatArray,
        omega: float,
        period_multiple: int = 1,
        flows: PatternFlows | None = None,
    ) -> None:
        self.system = system
        self.n = system.n_dof
        self.force = force
        self.omega = omega
        self.p = period_multiple
        self.period = 2.0 * math.pi / omega
        self.duration = self.p * self.period
        self.flow = _Flow(system, force, omega)
        self.impacts = bool(np.any(self.flow.restitution < 1.0))
        if self.impacts:
            refuse_restitution(system, below=0.0)  # e = 0: no saltation matrix
        self.flows = PatternFlows(system, impacts=self.impacts) if flows is None else flows

    def run(self, z: FloatArray, samples_per_period: int = 1) -> StructureMotion:
        """The exact motion from z = (u, v) over p periods."""
        count = self.p * samples_per_period
        times = np.arange(count, dtype=np.float64) * (self.duration / count)
        return _run(self.flow, z[: self.n], z[self.n :], self.duration, times)

    def __call__(
        self, z: FloatArray, samples_per_period: int = 1
    ) -> tuple[FloatArray, FloatArray, StructureMotion]:
        """Return (P(z), Phi, motion)."""
        motion = self.run(z, samples_per_period)
        end = np.concatenate(motion.final_state)
        history = pattern_history(motion)
        jumps = (
            impact_jumps(self.flow, motion, history, z[: self.n], z[self.n :], self.duration)
            if self.impacts
            else None
        )
        return end, carry(self.flows, motion, history, 0.0, self.duration, jumps=jumps), motion

    def size(self, z: FloatArray) -> float:
        """abs(z) in the norm of (w u, v), m/s."""
        return float(np.linalg.norm(np.concatenate((self.omega * z[: self.n], z[self.n :]))))


def newton_orbit(
    shoot: ShootingMap, z0: FloatArray, floor: float
) -> tuple[FloatArray, FloatArray, float, int] | None:
    """Newton on P(z) - z from z0, backtracking; (z, Phi, closure, iterations) or None."""
    n2 = 2 * shoot.n
    z = z0.copy()
    try:
        end, phi, _ = shoot(z)
    except SimulationError:
        return None
    r = end - z
    for iteration in range(1, MAX_ITERATIONS + 1):
        scale = max(shoot.size(z), floor)
        closure = shoot.size(r) / scale
        if closure <= CLOSURE:
            return z, phi, closure, iteration - 1
        jac = phi - np.eye(n2)
        try:
            dz = -scipy.linalg.solve(jac, r)
        except (scipy.linalg.LinAlgError, ValueError):
            dz = -np.linalg.lstsq(jac, r, rcond=None)[0]
        step = 1.0
        accepted = False
        for _ in range(12):
            trial = z + step * dz
            try:
                end_t, phi_t, _ = shoot(trial)
            except SimulationError:
                step *= 0.5
                continue
            r_t = end_t - trial
            if shoot.size(r_t) < shoot.size(r) or step < 1e-3:
                z, r, phi = trial, r_t, phi_t
                accepted = True
                break
            step *= 0.5
        if not accepted:
            return None
    scale = max(shoot.size(z), floor)
    closure = shoot.size(r) / scale
    return (z, phi, closure, MAX_ITERATIONS) if closure <= CLOSURE else None


def turning_extremes(
    motion: StructureMotion, system: VibrationSystem, force: FloatArray, rows: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The extremes over the sampled motion of each combination ``rows @ u``, refined.

    About each sample the motion is the cubic u + v s + a s^2/2 + j s^3/6 (a and j from
    the equations of motion in the sample's contact pattern); where its velocity turns
    within half a sample interval the turning value counts.

    Parameters
    ----------
    motion : StructureMotion
    system : VibrationSystem
    force : (N,) ndarray
    rows : (k, N) ndarray
        The combinations (identity for the DOFs, the joint directions for the shortenings).

    Returns
    -------
    (k,) and (k,) ndarrays: max and min.
    """
    u, v, t = motion.u, motion.v, motion.t
    w = motion.omega
    m = system.mass_diagonal()
    k_lin = system.stiffness
    c = system.damping
    b = system.directions
    delta = u @ b.T
    f_j, k_j = system.joint_forces(delta)
    restoring = np.asarray(k_lin @ u.T).T + f_j @ b
    drive = np.outer(np.sin(w * t), force)
    acc = (drive - np.asarray(c @ v.T).T - restoring) / m
    stiff_v = np.asarray(k_lin @ v.T).T + ((v @ b.T) * k_j) @ b
    jerk = (np.outer(w * np.cos(w * t), force) - np.asarray(c @ acc.T).T - stiff_v) / m
    x, x1, x2, x3 = u @ rows.T, v @ rows.T, acc @ rows.T, jerk @ rows.T
    dt = float(t[1] - t[0]) if t.size > 1 else 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        s0 = -x1 / x2
        s1 = s0 - (x1 + x2 * s0 + 0.5 * x3 * s0**2) / (x2 + x3 * s0)
        inside = np.isfinite(s1) & (np.abs(s1) <= 0.5 * dt)
        turned = x + x1 * s1 + 0.5 * x2 * s1**2 + x3 * s1**3 / 6.0
    top = np.where(inside & (x2 < 0), turned, -np.inf)
    bottom = np.where(inside & (x2 > 0), turned, np.inf)
    x_max = np.maximum(np.max(x, axis=0), np.max(top, axis=0))
    x_min = np.minimum(np.min(x, axis=0), np.min(bottom, axis=0))
    return np.asarray(x_max, dtype=np.float64), np.asarray(x_min, dtype=np.float64)


def sorted_multipliers(phi: FloatArray) -> NDArray[np.complex128]:
    mu = np.linalg.eigvals(phi)
    return np.asarray(mu[np.argsort(-np.abs(mu), kind="stable")], dtype=np.complex128)


def orbit_at(
    shoot: ShootingMap,
    z: FloatArray,
    phi: FloatArray,
    closure: float,
    iterations: int,
    seed: str,
) -> StructureOrbit:
    """The converged orbit z of ``shoot`` as a result (sampled once more for its extremes)."""
    motion = shoot.run(z, SAMPLES_PER_PERIOD)
    eye = np.eye(shoot.n)
    x_max, x_min = turning_extremes(motion, shoot.system, shoot.force, eye)
    mu = sorted_multipliers(phi)
    return StructureOrbit(
        omega=shoot.omega,
        force=shoot.force,
        period_multiple=shoot.p,
        initial_state=(z[: shoot.n].copy(), z[shoot.n :].copy()),
        x_max=x_max,
        x_min=x_min,
        monodromy=phi,
        multipliers=mu,
        stable=bool(np.all(np.abs(mu) < 1.0)),
        events=motion.events,
        motion=motion,
        closure=closure,
        iterations=iterations,
        seed=seed,
        dof_names=shoot.system.dof_names,
    )
