"""Harmonic-balance orbits of a structure checked against its exact motion (MODEL.md 5.2-5.3).

A harmonic-balance orbit is periodic only up to the harmonics it drops. Started
from the orbit's state x = (u(0), u'(0)), the exact event-driven motion of
:func:`clearjoint.structure.time_response` (MODEL.md 5.2) over one period T = 2 pi / w
returns to x exactly when the orbit is the exact one. The relative miss

    r = norm(S (Phi_T(x) - x)) / norm(S x),   S = diag(1, ..., 1, 1/w, ..., 1/w),

(velocities divided by w, so both halves are lengths) is the orbit's residual in
the time domain: a few 1e-3 where the truncation is mild, of order 1 where the
exact motion is something else (e.g. joints rattling through thousands of
gap-edge events per period while the orbit crosses a few dozen). The stability
verdict of the orbit (the exact monodromy of its linearisation,
:mod:`clearjoint.harmonic.monodromy`) is only as good as the orbit: a point whose
residual exceeds the tolerance is not to be trusted. docs/harmonic.md
("The example mast at 20 N") has the measurements behind the default tolerance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.progress import silenced

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes

    from clearjoint.results import FrequencyResponse

__all__ = [
    "RESIDUAL_TOLERANCE",
    "OrbitCheck",
    "StabilityCheck",
    "check_orbits",
    "confirm_stable",
    "spread",
    "unconfirmed_events",
    "untrusted_events",
]

FloatArray = NDArray[np.float64]

#: Largest one-period residual r of an orbit whose stability verdict is trusted. The
#: example mast at 0.1 N, where 30 periods of exact motion confirm the verdicts, has r
#: up to about 1e-2; at 20 N, where they do not, r is 0.3 to 1 (docs/harmonic.md).
RESIDUAL_TOLERANCE = 0.05


@dataclass(frozen=True)
class OrbitCheck:
    """Points of a harmonic-balance curve checked against one period of exact motion.

    Attributes
    ----------
    index : (k,) ndarray of int
        The checked points, indices into the curve.
    omega : (k,) ndarray
        Their frequencies, rad/s.
    residual : (k,) ndarray
        r = abs(S (Phi_T(x) - x)) / abs(S x) (module docstring); NaN where the exact
        motion could not be computed (then ``trusted`` is False).
    exact_events : (k,) ndarray of int
        Gap-edge events of the exact motion over that period.
    orbit_crossings : (k,) ndarray of int
        Gap-edge crossings of the harmonic-balance orbit over one period.
    trusted : (k,) ndarray of bool
        residual <= tolerance.
    tolerance : float
    """

    index: NDArray[np.int64]
    omega: FloatArray = field(repr=False)
    residual: FloatArray = field(repr=False)
    exact_events: NDArray[np.int64] = field(repr=False)
    orbit_crossings: NDArray[np.int64] = field(repr=False)
    trusted: NDArray[np.bool_] = field(repr=False)
    tolerance: float = RESIDUAL_TOLERANCE

    def __repr__(self) -> str:
        worst = float(np.nanmax(self.residual)) if np.any(np.isfinite(self.residual)) else math.nan
        return (
            f"OrbitCheck({self.index.size} points, {int(np.sum(~self.trusted))} not trusted, "
            f"largest residual {worst:.2g}, tolerance {self.tolerance:g})"
        )

    def plot(self, ax: Axes | None = None) -> Axes:
        """Plot the residual against frequency (Hz), log scale, with the tolerance.

        Returns
        -------
        matplotlib.axes.Axes
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6.4, 3.6))
        hz = self.omega / (2.0 * math.pi)
        ax.semilogy(hz[self.trusted], self.residual[self.trusted], "o", color="C0", label="trusted")
        ax.semilogy(
            hz[~self.trusted], self.residual[~self.trusted], "x", color="C3", label="not trusted"
        )
        ax.axhline(self.tolerance, color="0.5", ls="--", lw=0.8, label="tolerance")
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel("one-period residual of the HB orbit")
        ax.legend()
        return ax

    def to_xarray(self) -> xr.Dataset:
        """The check as an xarray Dataset over ``point``, units in attrs."""
        import xarray as xr

        return xr.Dataset(
            {
                "omega": ("point", self.omega, {"units": "rad/s"}),
                "residual": ("point", self.residual, {"units": "1"}),
                "exact_events": ("point", self.exact_events, {"units": "1"}),
                "orbit_crossings": ("point", self.orbit_crossings, {"units": "1"}),
                "trusted": ("point", self.trusted.astype(np.int8), {"units": "1 yes"}),
            },
            coords={"point": ("point", self.index, {"units": "1"})},
            attrs={"tolerance": self.tolerance},
        )


def spread(n_points: int, count: int) -> NDArray[np.int64]:
    """Return ``count`` indices spread evenly over a curve of ``n_points`` (ends included)."""
    if count <= 0 or n_points == 0:
        return np.zeros(0, dtype=np.int64)
    return np.unique(np.round(np.linspace(0, n_points - 1, count)).astype(np.int64))


def check_orbits(
    response: FrequencyResponse,
    points: ArrayLike | None = None,
    *,
    tolerance: float = RESIDUAL_TOLERANCE,
) -> OrbitCheck:
    """Return the one-period residual of a structure's harmonic-balance orbits (MODEL.md 5.2).

    Each checked orbit's state is run through one forcing period of the exact
    motion (:func:`clearjoint.structure.time_response`); see the module docstring.

    Parameters
    ----------
    response : FrequencyResponse
        From :func:`clearjoint.harmonic.frequency_response` on a Structure or a VibrationSystem.
    points : (k,) array_like of int, optional
        Indices into the curve; default every point.
    tolerance : float
        Largest residual of a trusted point, > 0.

    Returns
    -------
    OrbitCheck

    Raises
    ------
    ParameterError
        Not a harmonic-balance curve of a Structure or VibrationSystem, an index off
        the curve, a bad tolerance.
    HarmonicError
        A structure with Coulomb friction in a joint: its exact motion does not carry
        friction, so there is nothing exact to check against.
    """
    from clearjoint.harmonic import aft, monodromy
    from clearjoint.harmonic.system import build
    from clearjoint.structure import Structure, time_response
    from clearjoint.system import VibrationSystem, as_system

    settings = response.settings
    source = settings.get("system")
    if response.method != "harmonic" or not isinstance(source, Structure | VibrationSystem):
        raise ParameterError(
            "check_orbits needs a curve of clearjoint.harmonic.frequency_response on a "
            "Structure or a VibrationSystem; a Joint's orbits are checked by "
            "clearjoint.periodic's exact shooting"
        )
    structure = as_system(source)
    if np.any(structure.friction_force() > 0.0):
        from clearjoint.harmonic.system import HarmonicError

        raise HarmonicError(
            "check_orbits cannot check a structure with Coulomb friction in a joint: its exact "
            "motion (clearjoint.structure.time_response) does not carry friction; "
            "frequency_response skips the check there (pass check_points=0 to say so)"
        )
    if not (isinstance(tolerance, float | int) and math.isfinite(tolerance) and tolerance > 0):
        raise ParameterError(f"tolerance must be a finite number > 0, got {tolerance!r}")
    n_pts = response.omega.size
    index = (
        np.arange(n_pts, dtype=np.int64)
        if points is None
        else np.atleast_1d(np.asarray(points, dtype=np.int64))
    )
    if index.size and (index.min() < 0 or index.max() >= n_pts):
        raise ParameterError(
            f"points must be indices 0 to {n_pts - 1} of the curve, got {index.min()} to "
            f"{index.max()}"
        )
    model = build(structure, None)
    basis = aft.Basis.make(int(settings["harmonics"]), int(settings["samples"]))
    pattern = np.asarray(settings["force_pattern"], dtype=np.float64)
    coefficients = response.coefficients
    assert coefficients is not None
    n = structure.n_dof
    k = index.size
    residual = np.full(k, math.nan)
    events = np.zeros(k, dtype=np.int64)
    crossings = np.zeros(k, dtype=np.int64)
    for m, i in enumerate(index):
        w = float(response.omega[i])
        x = response.initial_state[i]
        scale = np.concatenate((np.ones(n), np.full(n, 1.0 / w)))
        crossings[m] = monodromy.crossings(model, basis, coefficients[i]).size
        try:
            with silenced():  # its seconds of motion are not the curve's progress
                motion = time_response(
                    structure,
                    pattern * float(response.force_amplitude[i]),
                    w,
                    2.0 * math.pi / w,
                    initial=(x[:n], x[n:]),
                    samples_per_period=8,
                )
        except ClearjointError:  # e.g. chattering: the orbit is not the motion
            continue
        end = np.concatenate(motion.final_state)
        residual[m] = float(np.linalg.norm(scale * (end - x)) / np.linalg.norm(scale * x))
        events[m] = motion.events
    trusted = np.isfinite(residual) & (residual <= tolerance)
    return OrbitCheck(
        index=index,
        omega=np.asarray(response.omega[index], dtype=np.float64),
        residual=residual,
        exact_events=events,
        orbit_crossings=crossings,
        trusted=trusted,
        tolerance=float(tolerance),
    )


def untrusted(omega: ArrayLike, force: ArrayLike, amplitude: ArrayLike, i: int, note: str) -> Any:
    """Return an ``"untrusted"`` ResponseEvent at point ``i`` of a curve (w in rad/s, the
    force in N, per-point amplitudes in m, per DOF or not: their largest), saying why."""
    from clearjoint.results import ResponseEvent

    return ResponseEvent(
        "untrusted",
        float(np.asarray(omega)[i]),
        float(np.asarray(force)[i]),
        float(np.max(np.asarray(amplitude)[i])),
        note,
    )


def untrusted_events(response: FrequencyResponse, check: OrbitCheck) -> list[Any]:
    """Return one ``"untrusted"`` ResponseEvent per checked point whose residual is too large."""
    out = []
    for m in np.flatnonzero(~check.trusted):
        r = check.residual[m]
        what = (
            f"one period of exact motion misses it by {r:.2g} of its state"
            if math.isfinite(r)
            else "the exact motion from it could not be computed"
        )
        out.append(
            untrusted(
                response.omega,
                response.force_amplitude,
                response.amplitude,
                int(check.index[m]),
                f"the harmonic-balance orbit is not the exact motion here ({what}; exact "
                f"{int(check.exact_events[m])} gap-edge events against the orbit's "
                f"{int(check.orbit_crossings[m])}): its stability verdict is not to be "
                "trusted; raise harmonics= or lower the force",
            )
        )
    return out


#: An exact orbit found by Newton from a harmonic-balance orbit is "nearby" when it lies
#: within this fraction of the orbit's state (norm of (w u, v)).
NEARBY = 0.2
#: Periods the exact motion is run from an orbit Newton could not close, to see whether it
#: stays (each period's phase-0 state within ``NEARBY`` of the orbit's).
STAY_PERIODS = 30
#: At most this many stable points of one curve are confirmed (spread evenly over them);
#: the others are left unconfirmed, and so not stable.
CONFIRM_LIMIT = 400


@dataclass(frozen=True)
class StabilityCheck:
    """Harmonic balance's "stable" points of a structure, confirmed (or not) by the exact motion.

    MODEL.md 5.1 on 5.2: from each point's state, Newton on the exact one-period map
    (:class:`clearjoint.structure.orbit.ShootingMap`); an exact orbit within ``NEARBY`` of
    it whose Floquet multipliers all lie inside the unit circle confirms the verdict.
    Where Newton does not close, the exact motion is run ``STAY_PERIODS`` periods from
    the state: staying within ``NEARBY`` confirms it, leaving refutes it.

    Attributes
    ----------
    index : (k,) ndarray of int
        The points checked (harmonic balance called them stable).
    verdict : (k,) ndarray of str
        "confirmed", "exact orbit unstable", "exact orbit far", "motion leaves",
        "motion stays" (confirmed without a closed orbit) or "not computable".
    multiplier : (k,) ndarray
        max abs(mu) of the exact orbit found (NaN where none).
    confirmed : (k,) ndarray of bool
    unchecked : (m,) ndarray of int
        Stable points beyond ``CONFIRM_LIMIT``, not checked (so not stable).
    """

    index: NDArray[np.int64]
    verdict: NDArray[np.str_] = field(repr=False)
    multiplier: FloatArray = field(repr=False)
    confirmed: NDArray[np.bool_] = field(repr=False)
    unchecked: NDArray[np.int64] = field(repr=False)

    def __repr__(self) -> str:
        return (
            f"StabilityCheck({self.index.size} stable points checked, "
            f"{int(np.sum(self.confirmed))} confirmed, {self.unchecked.size} not checked)"
        )


def confirm_stable(response: FrequencyResponse) -> StabilityCheck:
    """Confirm (or refute) by the exact motion each point harmonic balance calls stable.

    See :class:`StabilityCheck`. ``response`` is a harmonic-balance curve of a Structure
    or VibrationSystem without friction (lumped mass).
    """
    from clearjoint.structure.poincare import ShootingMap, newton_orbit
    from clearjoint.structure.tangent import PatternFlows
    from clearjoint.system import as_system

    system = as_system(response.settings["system"])
    pattern = np.asarray(response.settings["force_pattern"], dtype=np.float64)
    stable = np.flatnonzero(response.stable)
    chosen = stable
    if stable.size > CONFIRM_LIMIT:
        chosen = stable[spread(stable.size, CONFIRM_LIMIT)]
    unchecked = np.setdiff1d(stable, chosen)
    verdict = np.full(chosen.size, "not computable", dtype=object)
    multiplier = np.full(chosen.size, math.nan)
    try:
        flows: Any = PatternFlows(system)
    except ClearjointError:
        flows = None
    for m, i in enumerate(chosen):
        if flows is None:
            break
        w = float(response.omega[i])
        z = np.asarray(response.initial_state[i], dtype=np.float64)
        try:
            shoot = ShootingMap(system, pattern * float(response.force_amplitude[i]), w, 1, flows)
            size = shoot.size(z)
            found = newton_orbit(shoot, z, 1e-12 * size)
            if found is not None:
                mu = np.abs(np.linalg.eigvals(found[1]))
                multiplier[m] = float(np.max(mu))
                if shoot.size(found[0] - z) > NEARBY * size:
                    verdict[m] = "exact orbit far"
                elif np.all(mu < 1.0):
                    verdict[m] = "confirmed"
                else:
                    verdict[m] = "exact orbit unstable"
                continue
            stay = ShootingMap(shoot.system, shoot.force, w, STAY_PERIODS, flows)
            motion = stay.run(z, 1)  # the state at phase 0 of each period
            states = np.concatenate((motion.u, motion.v), axis=1)
            away = max(shoot.size(s - z) for s in states)
            verdict[m] = "motion stays" if away <= NEARBY * size else "motion leaves"
        except ClearjointError:
            verdict[m] = "not computable"
    confirmed = np.isin(verdict, ("confirmed", "motion stays"))
    return StabilityCheck(
        index=np.asarray(chosen, dtype=np.int64),
        verdict=verdict.astype(str),
        multiplier=multiplier,
        confirmed=np.asarray(confirmed, dtype=bool),
        unchecked=np.asarray(unchecked, dtype=np.int64),
    )


_SAYS = {
    "exact orbit unstable": "the exact orbit nearby is unstable",
    "exact orbit far": "Newton on the exact map reaches only an orbit far from it",
    "motion leaves": "the exact motion started on it leaves it",
    "not computable": "the exact motion could not be computed from it",
}


def unconfirmed_events(response: FrequencyResponse, found: StabilityCheck) -> list[Any]:
    """One ``"untrusted"`` event per run of neighbouring points whose "stable" is refuted."""
    out = []
    bad = [
        (int(i), str(v))
        for i, v, ok in zip(found.index, found.verdict, found.confirmed, strict=True)
        if not ok
    ]
    bad += [(int(i), "not checked") for i in found.unchecked]
    bad.sort()
    start = 0
    for k in range(1, len(bad) + 1):
        if k < len(bad) and bad[k][0] == bad[k - 1][0] + 1 and bad[k][1] == bad[start][1]:
            continue
        i0, what = bad[start]
        i1 = bad[k - 1][0]
        hz = response.omega[[i0, i1]] / (2 * math.pi)
        said = _SAYS.get(what, f"not checked (more than {CONFIRM_LIMIT} stable points)")
        out.append(
            untrusted(
                response.omega,
                response.force_amplitude,
                response.amplitude,
                i0,
                f"harmonic balance calls {i1 - i0 + 1} point(s) at {hz[0]:.6g}-{hz[1]:.6g} Hz "
                f"stable, but {said}: they are not stable here",
            )
        )
        start = k
    return out
