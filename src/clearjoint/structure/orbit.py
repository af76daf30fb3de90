"""Exact periodic orbits of a structure by shooting, and their stability (MODEL.md 5.1, 5.2).

The map P carries the state z = (u, v) at forcing phase 0 over p forcing periods with the
exact event-driven motion (``clearjoint.structure.time_response``). A periodic orbit
solves R(z) = P(z) - z = 0; Newton uses the exact Jacobian dR/dz = Phi - I, Phi the
monodromy: the ordered product of the contact patterns' exponentials over the stretches
the motion met (``clearjoint.structure.tangent``; the saltation matrices are the identity,
the clearance law's force being continuous). The Floquet multipliers are Phi's
eigenvalues: the orbit is stable when all lie inside the unit circle.

Newton starts, by default, from the harmonic-balance orbit at that frequency (H = 7,
``clearjoint.harmonic``), else from ``initial``, else from the end of a transient from
rest; it is converged when the closure abs(P(z) - z) is below ``CLOSURE`` of the orbit's
size (in the norm of (w u, v)). An orbit that does not close is an error, never a result.

The extremes x_max, x_min of each DOF are the extremes of the sampled orbit refined by
the local cubic of the exact motion about the sample nearest each turning point (velocity,
acceleration and jerk from the equations of motion in the sample's contact pattern), to
about 1e-9 of the amplitude with 512 samples a period.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.errors import ParameterError
from clearjoint.simulate.core import SimulationError
from clearjoint.structure.motion import (
    StructureMotion,
    _Flow,
    _initial,
    _run,
    _system,
    _vector,
)
from clearjoint.structure.tangent import PatternFlows, stretches
from clearjoint.system import VibrationSystem

FloatArray = NDArray[np.float64]

#: Converged when abs(P(z) - z) is below this fraction of abs(z) (norm of (w u, v)).
CLOSURE = 1e-10
#: Newton iterations at most.
MAX_ITERATIONS = 40
#: Samples a period of the orbit kept (for its extremes and its picture).
SAMPLES_PER_PERIOD = 512
#: Periods of the transient from rest that seeds Newton when nothing else does.
TRANSIENT_PERIODS = 200
#: Harmonics of the harmonic-balance seed.
SEED_HARMONICS = 7


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
        self.flows = PatternFlows(system) if flows is None else flows

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
        widths, patterns = stretches(motion, 0.0, self.duration)
        return end, self.flows.product(widths, patterns), motion

    def size(self, z: FloatArray) -> float:
        """abs(z) in the norm of (w u, v), m/s."""
        return float(np.linalg.norm(np.concatenate((self.omega * z[: self.n], z[self.n :]))))


def _newton(
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


def _state_of(coefficients: Any, h: int, n: int, omega: float) -> FloatArray:
    """(u(0), u'(0)) of the HB coefficients a_0, a_1, b_1, ..., a_H, b_H ((2H + 1) N,)."""
    coef = np.asarray(coefficients, dtype=np.float64).reshape(2 * h + 1, n)
    u0 = coef[0] + coef[1::2].sum(axis=0)
    v0 = omega * (np.arange(1, h + 1)[:, None] * coef[2::2]).sum(axis=0)
    return np.concatenate((u0, v0))


def harmonic_seed(
    system: VibrationSystem, force: FloatArray, omega: float, *, homotopy: bool = False
) -> FloatArray | None:
    """The state (u, v) at phase 0 of a harmonic-balance orbit at ``omega`` (H = 7), or None.

    Newton on the HB residual from the open and the closed linear responses (the cheap
    part of ``clearjoint.harmonic``'s start); with ``homotopy`` its whole start, the
    force homotopy included (seconds on a small chain).
    """
    from clearjoint.harmonic import aft, solve
    from clearjoint.harmonic.response import _start
    from clearjoint.harmonic.system import HarmonicError, build, scale_length

    try:
        model = build(system, None)
        h, n_t = aft.check_harmonics(SEED_HARMONICS, None)
        basis = aft.Basis.make(h, n_t)
    except (HarmonicError, ParameterError):
        return None
    k_ref = model.reference_stiffness
    if homotopy:
        try:
            return _state_of(_start(model, basis, omega, force, k_ref), h, system.n_dof, omega)
        except (HarmonicError, np.linalg.LinAlgError, ValueError):
            return None

    def function(q: FloatArray) -> tuple[FloatArray, Any]:
        ev = aft.evaluate(model, basis, q, omega, force)
        return ev.residual / k_ref, ev.jacobian / k_ref

    for stiffness in (model.open_stiffness(), model.closed_stiffness()):
        guess = solve.linear_guess(model, basis, omega, force, stiffness)
        scale = max(0.5 * scale_length(model), float(np.max(np.abs(guess))))
        try:
            found = solve.newton(function, guess, scale, max_iterations=30)
        except (HarmonicError, np.linalg.LinAlgError, ValueError):
            found = None
        if found is not None:
            return _state_of(found[0], h, system.n_dof, omega)
    return None


def _seeds(
    shoot: ShootingMap, initial: Any, use_harmonic: bool
) -> list[tuple[str, FloatArray | None]]:
    """The seeds to try, in order, as (name, z or None to be computed lazily)."""
    if initial is not None:
        u0, v0 = _initial(shoot.system, initial)
        return [("initial", np.concatenate((u0, v0)))]
    out: list[tuple[str, FloatArray | None]] = []
    if use_harmonic and shoot.p == 1:
        out.append(("harmonic balance", None))
    out.append(("transient", None))
    if use_harmonic and shoot.p == 1:
        out.append(("harmonic balance, from a force homotopy", None))
    return out


def _transient(shoot: ShootingMap, z: FloatArray | None = None) -> FloatArray:
    """The state at phase 0 after ``TRANSIENT_PERIODS`` periods from z (rest by default)."""
    start = np.zeros(2 * shoot.n) if z is None else z
    times = np.zeros(1)
    motion = _run(
        shoot.flow, start[: shoot.n], start[shoot.n :], TRANSIENT_PERIODS * shoot.period, times
    )
    return np.concatenate(motion.final_state)


def _floor(shoot: ShootingMap) -> float:
    """A size below which an orbit counts as zero: the gaps times w (m/s)."""
    gaps = np.concatenate((shoot.flow.g_c, shoot.flow.g_t))
    gaps = gaps[np.isfinite(gaps) & (gaps > 0)]
    return float(shoot.omega * (np.min(gaps) if gaps.size else 1e-6)) * 1e-3


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


def _sorted_multipliers(phi: FloatArray) -> NDArray[np.complex128]:
    mu = np.linalg.eigvals(phi)
    return np.asarray(mu[np.argsort(-np.abs(mu), kind="stable")], dtype=np.complex128)


def _check_period_multiple(period_multiple: int) -> int:
    if (
        isinstance(period_multiple, bool)
        or not isinstance(period_multiple, int | np.integer)
        or period_multiple < 1
    ):
        raise ParameterError(f"period_multiple must be an integer >= 1, got {period_multiple!r}")
    return int(period_multiple)


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
    mu = _sorted_multipliers(phi)
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


def periodic_orbit(
    structure: Any,
    force: ArrayLike,
    omega: float,
    *,
    period_multiple: int = 1,
    initial: Any = None,
) -> StructureOrbit:
    """Return the exact periodic orbit of ``structure`` under F sin(omega t), with its stability.

    MODEL.md 5.1 on the structure of 5.2: Newton on the exact p-period map with its exact
    Jacobian (module docstring).

    Parameters
    ----------
    structure : Structure or VibrationSystem
        Lumped (diagonal) mass; joints without friction and with restitution 1.
    force : (N,) array_like
        Force amplitude per DOF, N.
    omega : float
        rad/s, > 0.
    period_multiple : int
        p >= 1: seek an orbit that closes after p forcing periods.
    initial : (u0, v0), optional
        Newton's start (each (N,), m and m/s). Default: the harmonic-balance orbit at
        omega (p = 1), then the end of a transient from rest.

    Returns
    -------
    StructureOrbit

    Raises
    ------
    StructureError
        A force or initial vector of the wrong length, friction or restitution below 1.
    ParameterError
        omega not finite and positive, period_multiple not an integer >= 1.
    OrbitError
        Newton converged from none of the seeds.
    """
    system = _system(structure)
    f = _vector("force", force, system)
    w = _checks.positive("omega", omega, unit="rad/s")
    p = _check_period_multiple(period_multiple)
    shoot = ShootingMap(system, f, w, p)
    floor = _floor(shoot)
    tried: list[str] = []
    for name, z0 in _seeds(shoot, initial, use_harmonic=True):
        if z0 is None:
            if name == "transient":
                z0 = _transient(shoot)
            else:
                z0 = harmonic_seed(system, f, w, homotopy=name != "harmonic balance")
            if z0 is None:
                tried.append(f"{name} (no solution)")
                continue
        found = _newton(shoot, z0, floor)
        if found is not None:
            z, phi, closure, iterations = found
            return orbit_at(shoot, z, phi, closure, iterations, name)
        tried.append(name)
    raise OrbitError(
        f"no periodic orbit of period {p} converged at {w / (2 * math.pi):.6g} Hz from "
        f"{', '.join(tried)}; the motion there may not be periodic: run "
        "clearjoint.structure.stepped_sine to see what it does, or pass initial="
    )


__all__ = ["OrbitError", "ShootingMap", "StructureOrbit", "periodic_orbit"]
