"""Exact periodic orbits, their stability, and whole frequency-response curves (MODEL.md sec. 5.1).

A periodic orbit of p forcing periods is a fixed point of the exact stroboscopic
map, P_p(z0) = z0 with z0 = (x, x') at forcing phase 0 (the force is
F0 sin(omega t)). It is found by Newton's method with the *exact* monodromy
matrix M = dP_p/dz0, built from the closed-form flow of each state and the
saltation matrix of each event (``simulate._shooting``). The Floquet multipliers
are eig(M); the orbit is stable when every multiplier has modulus < 1.

``frequency_response`` follows the period-1 orbit with pseudo-arclength
continuation (``clearjoint.continuation``) in omega (or in F0), stable and
unstable alike, through folds. The derivative of the map in the parameter is
a finite difference of the exact map; the one in the state is exact. Events:

- fold: the parameter component of the tangent changes sign (a multiplier
  passes +1); it is placed at the bracketing point where the parameter is extreme;
- period doubling: 1 + tr M + det M (the characteristic polynomial at -1)
  changes sign (a multiplier passes -1); a period-2 branch is born there and is
  not followed;
- grazing: the orbit starts or stops touching a gap edge (x_max - g_c or
  -g_t - x_min changes sign); the branch has a kink there;
- free_play (k0 = 0 only): the branch meets the orbits that never touch an edge.
  Inside the gap the force does not depend on x, so such an orbit shifted by any
  constant is an orbit too (a continuum, multiplier exactly 1, Newton singular): the
  branch stops where it meets them (its orbit touches an edge there) and the curve
  goes on along the member centred in the gap, flagged ``free_play``: its amplitude is
  set by the dynamics, its position is not.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.continuation import (
    Branch,
    ContinuationSettings,
    continue_branch,
    parameter_range,
)
from clearjoint.errors import ParameterError, SimulationError
from clearjoint.exact import kernel as kn
from clearjoint.exact.shooting import (
    N_RES,
    R_DLAM,
    R_EVALS,
    R_EVENTS,
    R_JAC,
    R_RES,
    R_XMAX,
    R_XMIN,
    Shot,
    arclength_step,
    correct_orbit,
    map_residual,
    newton_orbit,
    set_parameter,
    shoot,
    start_state,
)
from clearjoint.exact.single import initial_state, orbit_from, run_kernel, setup
from clearjoint.joint import Joint, Losses, takes_losses
from clearjoint.results.motion import SteadyState

# the results moved to clearjoint.results; imported "as" themselves so that the old path
# clearjoint.periodic re-exports them (and the API reference documents them once)
from clearjoint.results.orbit import PeriodicOrbit as PeriodicOrbit
from clearjoint.results.response import FrequencyResponse as FrequencyResponse
from clearjoint.results.response import ResponseEvent as ResponseEvent
from clearjoint.system import VibrationSystem

# the kernels as compiled at install where that is usable (clearjoint.compiled)
_start_state = prefer(start_state)
_correct_orbit = prefer(correct_orbit)
_arclength_step = prefer(arclength_step)

__all__ = [
    "frequency_response",
    "orbit_cycle",
    "orbit_monodromy",
    "period_2_orbit",
    "periodic_orbit",
]

FloatArray = NDArray[np.float64]

#: Transient periods run before Newton when no starting point is given, per attempt.
_TRANSIENT_PERIODS = 32
_TOLERANCE = 1e-12
#: Times the continuation goes on past a point where it stopped, from an orbit further on.
_REJOINS = 12
#: Where the orbit further on is sought: these fractions of the way from the furthest
#: parameter reached to the end of the range.
_SEED_FACTORS = (0.003, 0.006, 0.01, 0.02)
#: Points at most on the way back from such an orbit (a seed on a branch that does not
#: lead back to the stop is given up after them).
_BACK_POINTS = 500
#: Smallest arclength step (scaled units) of the curve.
_MIN_STEP = 1e-6
#: Points in a row at tiny steps after which a jump across the kink ahead is tried.
_CRAWL_POINTS = 20


def _scales(joint: Joint, p: FloatArray, z: FloatArray) -> FloatArray:
    x_scale = max(joint.clearance, abs(float(z[0])), 1e-300)
    v_scale = max(abs(float(z[1])), x_scale * p[kn.P_W])
    return np.array([x_scale, v_scale])


@takes_losses
def periodic_orbit(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega: float,
    *,
    losses: Losses | None = None,
    period_multiple: int = 1,
    initial: ArrayLike | None = None,
) -> PeriodicOrbit:
    """Return the exact periodic orbit by Newton's method on the exact map (MODEL.md sec. 5.1).

    Parameters
    ----------
    joint : Joint
    force_amplitude : float
        F0 > 0, N.
    omega : float
        Forcing circular frequency > 0, rad/s.
    losses : Losses, optional
        As for :func:`clearjoint.simulate.steady_state` (a one-DOF VibrationSystem given
        as ``joint`` carries its own).
    period_multiple : int
        p >= 1: the orbit closes after p forcing periods.
    initial : (2,) array_like, optional
        (x0, x0') at forcing phase 0 to start Newton from; by default a short
        transient from rest provides it (and more transient if Newton fails).

    Returns
    -------
    PeriodicOrbit

    Raises
    ------
    SimulationError
        Newton's method found no orbit.
    """
    joint, losses, p = setup(joint, force_amplitude, omega, losses)
    if isinstance(period_multiple, bool) or not isinstance(period_multiple, int | np.integer):
        raise ParameterError(f"period_multiple must be an integer >= 1, got {period_multiple!r}")
    n = int(period_multiple)
    if n < 1:
        raise ParameterError(f"period_multiple must be an integer >= 1, got {period_multiple!r}")
    state = initial_state(p, initial)
    attempts = 1 if initial is not None else 6
    for attempt in range(attempts):
        if initial is None:
            run_kernel(p, state, _TRANSIENT_PERIODS * 2**attempt, p[kn.P_TF], record=False)
        found = newton_orbit(p, state[:2], n, _scales(joint, p, state[:2]), tolerance=_TOLERANCE)
        if found is not None:
            z, shot, iterations = found
            return _orbit(joint, losses, p, z, shot, n, iterations)
    raise SimulationError(
        f"Newton's method found no period-{n} orbit at omega = {omega!r} rad/s; "
        "give initial=(x0, v0) near the orbit, or another period_multiple"
    )


def _orbit(
    joint: Joint, losses: Losses, p: FloatArray, z: FloatArray, shot: Shot, n: int, iterations: int
) -> PeriodicOrbit:
    state = np.zeros(4)
    _start_state(p, float(z[0]), float(z[1]), state)
    cycle = orbit_from(p, joint, state, n, 0, losses.pin, losses.contact_friction_coefficient, 256)
    mu = np.linalg.eigvals(shot.monodromy).astype(np.complex128)
    return PeriodicOrbit(
        initial_state=(float(z[0]), float(z[1])),
        cycle=cycle,
        monodromy=shot.monodromy,
        multipliers=mu,
        stable=bool(np.max(np.abs(mu)) < 1.0),
        omega=float(p[kn.P_W]),
        force_amplitude=float(p[kn.P_F0]),
        period_multiple=n,
        newton_iterations=iterations,
    )


@takes_losses
def orbit_cycle(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega: float,
    initial_state: ArrayLike,
    *,
    losses: Losses | None = None,
) -> SteadyState:
    """Return the period-1 orbit from ``initial_state`` re-run exactly, as a SteadyState.

    MODEL.md sec. 5.1: one forcing period of the exact flow from (x0, x0') at forcing
    phase 0, sampled (64 samples) with its stages and energy ledger; what
    :meth:`FrequencyResponse.cycle` gives for a point of a shooting curve.

    Parameters
    ----------
    joint : Joint
    force_amplitude, omega : float
        F0 (N) and the forcing circular frequency (rad/s).
    initial_state : (2,) array_like
        (x0, x0') at forcing phase 0, m and m/s: a point of the orbit.
    losses : Losses, optional
        As for :func:`clearjoint.simulate.steady_state` (a one-DOF VibrationSystem given
        as ``joint`` carries its own).

    Returns
    -------
    SteadyState
    """
    joint, losses, p = setup(joint, force_amplitude, omega, losses)
    z = np.asarray(initial_state, dtype=np.float64)
    state = np.zeros(4)
    _start_state(p, float(z[0]), float(z[1]), state)
    return orbit_from(p, joint, state, 1, 0, losses.pin, losses.contact_friction_coefficient, 64)


@takes_losses
def orbit_monodromy(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega: float,
    initial_state: ArrayLike,
    *,
    losses: Losses | None = None,
) -> FloatArray:
    """Return the exact monodromy matrix dP/dz0 (2, 2) of one forcing period from ``initial_state``.

    MODEL.md sec. 5.1: the closed-form flows and saltation matrices of the period-1
    map from (x0, x0') at forcing phase 0; arguments as for :func:`orbit_cycle`.
    """
    p = setup(joint, force_amplitude, omega, losses)[2]
    return shoot(p, np.asarray(initial_state, dtype=np.float64), 1).monodromy


def period_2_orbit(curve: FrequencyResponse, event: ResponseEvent) -> PeriodicOrbit:
    """Switch branches at a period doubling: the period-2 orbit born there (MODEL.md sec. 5.1).

    At a period doubling a Floquet multiplier of the period-1 orbit passes -1 and a
    period-2 orbit branches off along its eigenvector w. From the curve's points
    around the event (a multiplier below -0.5), nearest first, on either side, Newton
    on the two-period map P_2 starts at z* +- eps w (eps from 1e-3 to 0.3 of the
    orbit's size); the first fixed point of P_2 that is not the period-1 orbit z*
    (further than 1e-6 of its size) is returned.

    Parameters
    ----------
    curve : FrequencyResponse
        A shooting curve (``curve.period_2_orbit(event)`` calls this).
    event : ResponseEvent
        One of ``events`` with ``kind == "period_doubling"``.

    Returns
    -------
    PeriodicOrbit
        ``period_multiple == 2``, at the frequency (or force) of the curve point it
        branched from.

    Raises
    ------
    ParameterError
        The event is not a period doubling, or the curve is not from shooting.
    SimulationError
        No period-2 orbit was found near the event.
    """
    if curve.method != "shooting" or event.kind != "period_doubling":
        raise ParameterError(
            "period_2_orbit takes a 'period_doubling' event of a shooting curve, got "
            f"{event.kind!r} of a {curve.method!r} curve"
        )
    s = curve.settings
    lam = curve.omega if curve.parameter == "omega" else curve.force_amplitude
    at = event.omega if curve.parameter == "omega" else event.force_amplitude
    # both sides: past a supercritical doubling the period-2 orbit lies where the
    # period-1 orbit is unstable, past a subcritical one where it is stable
    beyond = np.nonzero(curve.multipliers.real.min(axis=1) < -0.5)[0]
    beyond = beyond[np.argsort(np.abs(lam[beyond] - at))][:16]
    for i in beyond:
        w, f = float(curve.omega[i]), float(curve.force_amplitude[i])
        z = curve.initial_state[i]
        mono = orbit_monodromy(s["joint"], f, w, z, losses=s["losses"])
        mu, vectors = np.linalg.eig(mono)
        direction = np.real(vectors[:, int(np.argmin(mu.real))])
        size = np.array([max(curve.amplitude[i], 1e-300), max(curve.amplitude[i], 1e-300) * w])
        direction = direction / np.max(np.abs(direction) / size)
        for eps in (1e-3, 1e-2, 3e-2, 1e-1, 3e-1):
            for sign in (1.0, -1.0):
                try:
                    orbit = periodic_orbit(
                        s["joint"],
                        f,
                        w,
                        period_multiple=2,
                        initial=z + sign * eps * direction,
                        losses=s["losses"],
                    )
                except SimulationError:
                    continue
                if np.max(np.abs(np.array(orbit.initial_state) - z) / size) > 1e-6:
                    return orbit
    raise SimulationError(
        f"no period-2 orbit found near the period doubling at {event!r}; try "
        "periodic_orbit(..., period_multiple=2, initial=...) from a steady_state"
    )


# ---- frequency response ---------------------------------------------------------------------


class _MapResidual:
    """The continuation's residual R(z, lam) = P_1(z; lam) - z, closed over ``p``.

    Called as ``residual(u, lam, derivative=True)`` it returns what
    ``continuation.Residual`` asks for; its ``corrector`` runs the whole
    arclength Newton correction compiled (``_shooting.correct_orbit``), which
    ``continuation`` uses in place of its own loop when it finds one.
    """

    def __init__(self, p: FloatArray, parameter: str, free_play_stop: bool = False) -> None:
        self.p = p
        self.code = 0 if parameter == "omega" else 1
        #: evaluations of the exact map so far (a cost that does not depend on the load)
        self.evaluations = 0
        #: refuse orbits that never touch an edge (with k0 = 0: a continuum, see _in_gap)
        self.free_play_stop = free_play_stop
        #: the parameters at which such an orbit was refused
        self.refused_at: list[float] = []

    def _refused(self, out: FloatArray) -> bool:
        return self.free_play_stop and _in_gap(self.p, out, _TOUCH)

    def _corrected(
        self, its: int, y: FloatArray, system: FloatArray, out: FloatArray, scale: FloatArray
    ) -> tuple[FloatArray, FloatArray, Any, int] | None:
        """A compiled correction's outcome: (y, [R_u, R_lam], data, its), or None (failed or
        refused, counting its map evaluations either way)."""
        self.evaluations += int(out[R_EVALS])
        if its < 0:
            return None
        if self._refused(out):
            self.refused_at.append(float(y[-1] * scale[-1]))
            return None
        return y, system[:2].copy(), out, int(its)

    def __call__(
        self, u: FloatArray, lam: float, derivative: bool = True
    ) -> tuple[FloatArray, FloatArray, FloatArray, Any]:
        if not lam > 0.0:
            raise SimulationError(f"the parameter left the positive range ({lam!r})")
        out = np.zeros(N_RES)
        status = map_residual(self.p, self.code, float(u[0]), float(u[1]), lam, out, derivative)
        self.evaluations += int(out[R_EVALS])
        if status != kn.STATUS_OK:
            raise SimulationError(f"the exact map failed (kernel status {status})")
        if self._refused(out):
            self.refused_at.append(float(lam))
            raise SimulationError("the orbit stays inside the gap: one of a continuum")
        return out[R_RES : R_RES + 2], out[R_JAC : R_JAC + 4].reshape(2, 2), out[R_DLAM:R_XMAX], out

    def corrector(
        self,
        y0: FloatArray,
        tangent: FloatArray,
        scale: FloatArray,
        settings: ContinuationSettings,
        fixed_lambda: bool,
    ) -> tuple[FloatArray, FloatArray, Any, int] | None:
        """``continuation._correct`` for this residual, compiled: (y, [R_u, R_lam], data, its)."""
        y = np.empty(3)
        system = np.empty((3, 3))
        out = np.zeros(N_RES)
        its = _correct_orbit(
            self.p,
            self.code,
            y0,
            tangent,
            scale,
            fixed_lambda,
            settings.tolerance,
            settings.max_iterations,
            y,
            system,
            out,
        )
        return self._corrected(its, y, system, out, scale)

    def step(
        self,
        points: FloatArray,
        h: float,
        tangent: FloatArray,
        curvature: FloatArray,
        scale: FloatArray,
        settings: ContinuationSettings,
    ) -> tuple[tuple[FloatArray, FloatArray, Any, int], FloatArray] | None:
        """``continuation``'s ordinary step, compiled (``_shooting.arclength_step``).

        Predicts from ``points`` (the last points, or the last one with the
        ``tangent`` and ``curvature``), corrects as ``corrector`` does, and returns
        ((y, [R_u, R_lam], data, its), the new unit tangent), or None.
        """
        y = np.empty(3)
        system = np.empty((3, 3))
        out = np.zeros(N_RES)
        t_new = np.empty(3)
        its = _arclength_step(
            self.p,
            self.code,
            points,
            h,
            tangent,
            curvature,
            scale,
            settings.tolerance,
            settings.max_iterations,
            y,
            system,
            out,
            t_new,
        )
        corrected = self._corrected(its, y, system, out, scale)
        return None if corrected is None else (corrected, t_new)


def _map_residual(p: FloatArray, parameter: str, free_play_stop: bool = False) -> _MapResidual:
    """The continuation's residual R(z, lam) = P_1(z; lam) - z, closed over ``p``."""
    return _MapResidual(p, parameter, free_play_stop)


#: An orbit reaching past an edge by less than this fraction of the clearance counts as
#: not touching it (with restitution 1 such orbits are the continuum's members pushed
#: against an edge: a family the continuation would otherwise creep along).
_TOUCH = 1e-7


def _in_gap(p: FloatArray, out: FloatArray, slack: float = 0.0) -> bool:
    """With k0 = 0, an orbit that never reaches a gap edge (``out``: a map_residual row).

    Inside the gap the force does not depend on x, so the orbit shifted by any
    constant is an orbit too: a continuum, with a Floquet multiplier exactly 1.
    """
    tol = slack * (p[kn.P_GC] + p[kn.P_GT])
    return bool(
        p[kn.P_K0] == 0.0 and out[R_XMAX] < p[kn.P_GC] + tol and out[R_XMIN] > -p[kn.P_GT] - tol
    )


def _free_play_orbit(p: FloatArray, omega: float, code: int = 0) -> FloatArray | None:
    """The member centred in the gap of the continuum of in-gap orbits at ``omega`` (k0 = 0).

    ``omega`` is the continuation parameter's value: the forcing frequency (rad/s)
    with ``code`` 0, the force amplitude F0 (N) with ``code`` 1 (``p`` giving the other).

    Inside the gap with k0 = 0 the velocity obeys m v' + c v + friction(v) = F0 sin(w t)
    whatever x is: its periodic solution v* is found by Newton on the velocity
    component of the exact map alone (the position's direction, the multiplier 1,
    left out); the symmetric orbit (v(t + T/2) = -v(t)) has no drift over a period,
    so x closes for every starting position, and the one whose extremes sit
    symmetrically in the gap ((x_max + x_min)/2 = the gap's centre) is returned.

    Returns
    -------
    (N_RES,) ndarray or None
        The map_residual row of that orbit with (x0, v0) in its first two places
        replaced, i.e. ``[x0, v0, M - I (4), dR/dlam (2), x_max, x_min, edge, events]``;
        None when the orbit does not fit inside the gap or Newton fails.
    """
    q = p.copy()
    lam = omega
    set_parameter(q, code, lam)
    m, c, f0, omega = q[kn.P_MASS], q[kn.P_DAMP], q[kn.P_F0], q[kn.P_W]
    v = -f0 * m * omega / (c * c + (m * omega) ** 2)  # v(0) of the viscous free mass
    # the velocity orbit does not depend on where the edges are: solve it with them far off
    far = q.copy()
    far[kn.P_GC] = far[kn.P_GT] = 1e6 * (q[kn.P_GC] + q[kn.P_GT] + f0 / (m * omega**2))
    out = np.zeros(N_RES)
    for _ in range(30):
        if map_residual(far, code, 0.0, v, lam, out, False) != kn.STATUS_OK:
            return None
        dv = -out[R_RES + 1] / out[R_JAC + 3]
        v += dv
        if abs(dv) <= 1e-14 * max(abs(v), f0 / (m * omega)):
            break
    else:
        return None
    x0 = (q[kn.P_GC] - q[kn.P_GT]) / 2.0 - 0.5 * (out[R_XMAX] + out[R_XMIN])
    if map_residual(q, code, x0, v, lam, out, True) != kn.STATUS_OK or not _in_gap(q, out):
        return None
    size = out[R_XMAX] - out[R_XMIN]
    if abs(out[R_RES]) > 1e-9 * size or abs(out[R_RES + 1]) > 1e-9 * size * omega:
        return None  # the velocity orbit drifts: not a closed orbit
    out[R_RES], out[R_RES + 1] = x0, v
    return out


@takes_losses
def frequency_response(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega_start: float,
    omega_stop: float | None,
    *,
    losses: Losses | None = None,
    parameter: Literal["omega", "force"] = "omega",
    force_stop: float | None = None,
    max_points: int = 2000,
) -> FrequencyResponse:
    """Return the whole frequency-response curve of exact period-1 orbits (MODEL.md sec. 5.1).

    Pseudo-arclength continuation of the periodic orbit from ``omega_start`` to
    ``omega_stop`` (rad/s), through folds, stable and unstable branches alike,
    with folds, period doublings and grazings reported as ``events``. Where the
    continuation stops short of the end (no step converges, or it runs back along
    itself), a period-1 orbit is sought further on and the branch followed from it
    back to that point, then on: the curve stays one ordered path. With
    ``parameter="force"`` it continues in F0 from ``force_amplitude`` to
    ``force_stop`` (N) at the fixed ``omega_start`` (``omega_stop`` is then
    ignored and may be None).

    With gap_stiffness 0, the branch stops where it meets the orbits that stay
    inside the gap (a continuum: any mean position) and goes on along the one
    centred in the gap (``free_play``); a start on such an orbit is followed from
    the other end of the range and turned round.

    Parameters
    ----------
    joint : Joint
    force_amplitude : float
        F0 > 0, N (the start of the range with ``parameter="force"``).
    omega_start, omega_stop : float
        Forcing circular frequencies > 0, rad/s, either order.
    losses : Losses, optional
        As for :func:`clearjoint.simulate.steady_state` (a one-DOF VibrationSystem given
        as ``joint`` carries its own).
    parameter : {"omega", "force"}
    force_stop : float, optional
        End of the force range, N (required with ``parameter="force"``).
    max_points : int
        Largest number of points on the curve.

    Returns
    -------
    FrequencyResponse

    Raises
    ------
    ParameterError
        A range of zero width, a value that is not finite and positive, or
        ``force_stop`` missing with ``parameter="force"``.
    SimulationError
        No periodic orbit at the start, or (gap_stiffness 0) orbits inside the gap at
        both ends of the range.
    """
    if parameter not in ("omega", "force"):
        raise ParameterError(f"parameter must be 'omega' or 'force', got {parameter!r}")
    w0 = _checks.positive("omega_start", omega_start, unit="rad/s")
    f0 = _checks.positive("force_amplitude", force_amplitude, unit="N")
    start, stop = parameter_range(parameter, f0, w0, omega_stop, force_stop)
    if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 2:
        raise ParameterError(f"max_points must be an integer >= 2, got {max_points!r}")
    joint, losses, p = setup(joint, f0, w0, losses)
    first = periodic_orbit(joint, f0, w0, losses=losses)
    if np.min(np.abs(first.multipliers - 1.0)) < 1e-9:
        refusal = SimulationError(
            f"the orbit at the start ({first!r}) has a multiplier of exactly 1: it is one of a "
            "continuum of orbits (it stays in the gap with gap_stiffness = 0, or sticks), so "
            "no single curve exists; give gap_stiffness > 0 or start where the joint is in contact"
        )
        inside = joint.compression_gap > first.x_max and first.x_min > -joint.tension_gap
        undamped = losses.damping_ratio == 0.0 and losses.friction is None
        if inside and joint.gap_stiffness > 0.0 and undamped:
            # undamped inside the gap: the linear orbit's multipliers are exp(+-2 pi i w_g / w),
            # exactly 1 where omega divides w_g, and any free oscillation can be added to it
            w_g = math.sqrt(joint.gap_stiffness / joint.mass)
            refusal = SimulationError(
                f"the orbit at the start ({first!r}) has a multiplier of exactly 1: without "
                f"damping, omega_start = {w0!r} rad/s divides the gap's natural frequency "
                f"sqrt(k0/m) = {w_g!r} rad/s, so a free oscillation can be added to the orbit "
                "(a continuum, no single curve); give damping_ratio > 0 or another omega_start"
            )
        if joint.gap_stiffness != 0.0:
            raise refusal
        # a free-play orbit at the start: follow the curve from the other end, which ends on
        # the free-play orbits (if that end is not one too), and turn it round
        force_mode = parameter == "force"
        try:
            other = periodic_orbit(
                joint,
                stop if force_mode else f0,
                w0 if force_mode else stop,
                losses=losses,
            )
        except SimulationError:
            raise refusal from None
        if np.min(np.abs(other.multipliers - 1.0)) < 1e-9:
            raise refusal
        if force_mode:
            turned = frequency_response(
                joint,
                stop,
                w0,
                None,
                parameter="force",
                force_stop=f0,
                max_points=max_points,
                losses=losses,
            )
        else:
            turned = frequency_response(joint, f0, stop, w0, max_points=max_points, losses=losses)
        return _turned_round(turned)
    x_scale = max(joint.clearance / 2.0, first.amplitude)
    v_scale = x_scale * max(w0, stop if parameter == "omega" else w0)
    code = 0 if parameter == "omega" else 1

    def restart(u: FloatArray, lam: float) -> FloatArray | None:
        """A short transient at ``lam`` from ``u``: the start of Newton across a kink."""
        q = p.copy()
        set_parameter(q, code, lam)
        state = initial_state(q, u)
        try:
            run_kernel(q, state, _TRANSIENT_PERIODS, q[kn.P_TF], record=False)
        except SimulationError:
            return None
        return np.asarray(state[:2], dtype=np.float64)

    def differs(last: FloatArray, new: FloatArray) -> bool:
        """Another smooth piece of the branch: the orbit meets a different number of events."""
        return bool(last[R_EVENTS] != new[R_EVENTS])

    edges = (joint.compression_gap, -joint.tension_gap)
    e = losses.restitution

    def equivalents(u: FloatArray) -> list[FloatArray]:
        """At a gap edge the section may sit on an impact: the state before and after it."""
        x, v = float(u[0]), float(u[1])
        if e <= 0.0 or min(abs(x - edge) for edge in edges) > 1e-6 * x_scale:
            return []
        return [np.array([x, e * v]), np.array([x, v / e])]  # v+ = e v- on entering contact

    # k0 = 0: orbits that stay inside the gap are a continuum; the branch stops where it
    # meets them and the member centred in the gap is followed instead (_free_play_tail)
    free_play_stop = joint.gap_stiffness == 0.0
    residual = _map_residual(p, parameter, free_play_stop)

    def follow(
        u0: FloatArray,
        lam0: float,
        lam1: float,
        points: int,
        join: tuple[FloatArray, float, Any] | None = None,
    ) -> Branch:
        return continue_branch(
            residual,
            u0,
            lam0,
            lam1,
            u_scale=np.array([x_scale, v_scale]),
            lam_scale=abs(stop - start),
            settings=ContinuationSettings(
                step=0.002,
                min_step=_MIN_STEP,
                max_step=0.023,
                max_points=points,
                tolerance=1e-11,
                chord_parameter=True,
                predictor_degree=5,  # pyHarm curve: 72 of 323 points need 2+ iterations, 105 with 3
                crawl_points=_CRAWL_POINTS,
            ),
            restart=restart,
            differs=differs,
            equivalents=equivalents,
            join=join,
        )

    branch = follow(np.array(first.initial_state), start, stop, max_points)
    tail = None
    for _ in range(_REJOINS + 1):
        if not branch.reason.startswith(("step too small", "ran back")):
            break
        if free_play_stop:
            tail = _free_play_tail(
                p, branch, residual.refused_at, stop, max_points - branch.lam.size, code
            )
            if tail is not None:
                break
        if _ == _REJOINS:
            break
        joined = _rejoin(
            branch,
            follow,
            lambda lam: _seed(joint, f0, w0, lam, parameter, losses),
            start,
            stop,
            max_points,
        )
        if joined is None:
            break
        branch = joined
    rows = np.array(branch.data)
    lam_all = branch.lam
    lam_tangent = branch.tangent[:, -1]
    start_states = branch.u.copy()
    free_play = np.zeros(branch.lam.size, dtype=bool)
    reason = branch.reason
    if tail is not None:
        lam_all = np.concatenate((lam_all, tail[:, N_RES]))
        rows = np.concatenate((rows, tail[:, :N_RES]))
        lam_tangent = np.concatenate((lam_tangent, np.full(len(tail), np.sign(stop - start))))
        start_states = np.concatenate((start_states, tail[:, R_RES : R_RES + 2]))
        free_play = np.concatenate((free_play, np.ones(len(tail), dtype=bool)))
        reason = "reached" if tail[-1, N_RES] == stop else "max_points"
    short = reason.startswith("passed the end")  # continue_branch says so itself
    if short or (reason == "reached" and abs(lam_all[-1] - stop) > 1e-12 * abs(stop - start)):
        # a step passed the end but no orbit converged at the end itself (e.g. a continuum
        # of sticking orbits there): the curve is short of the range, so say so
        unit = "rad/s" if parameter == "omega" else "N"
        reason = (
            f"passed the end of the range ({stop:.6g} {unit}) but no orbit converged there; "
            f"the curve ends at {lam_all[-1]:.6g} {unit}"
        )
    n = lam_all.size
    omega = lam_all.copy() if parameter == "omega" else np.full(n, w0)
    force = lam_all.copy() if parameter == "force" else np.full(n, f0)
    x_max = rows[:, R_XMAX]
    x_min = rows[:, R_XMIN]
    mono = rows[:, R_JAC : R_JAC + 4].reshape(n, 2, 2) + np.eye(2)
    mu = np.linalg.eigvals(mono).astype(np.complex128)
    mu = np.take_along_axis(mu, np.argsort(-np.abs(mu), axis=1), axis=1)
    # a free-play orbit is one of a continuum (multiplier 1): not asymptotically stable
    stable = (np.max(np.abs(mu), axis=1) < 1.0) & ~free_play
    amplitude = 0.5 * (x_max - x_min)
    sticking = []
    for k in branch.kinks:
        stuck = []
        for i in (int(k) - 1, int(k)):
            q = p.copy()
            set_parameter(q, code, float(branch.lam[i]))
            state = np.zeros(4)
            _start_state(q, float(branch.u[i, 0]), float(branch.u[i, 1]), state)
            stuck.append(orbit_from(q, joint, state, 1, 0, None, 0.0, 8).stick_time > 0.0)
        sticking.append(stuck[0] != stuck[1])
    events = _events(
        joint,
        lam_tangent,
        mono,
        x_max,
        x_min,
        omega,
        force,
        amplitude,
        branch.kinks,
        np.array(sticking, dtype=bool),
    )
    if tail is not None:
        i = branch.lam.size
        events.append(
            ResponseEvent(
                "free_play",
                float(omega[i]),
                float(force[i]),
                float(amplitude[i]),
                "the junction of the branch with contact and the orbits that stay inside the gap "
                "(gap_stiffness 0): a continuum of orbits, one for each mean position, the "
                "position not set by the dynamics; the curve (free_play True) shows the one "
                "centred in the gap",
            )
        )
    return FrequencyResponse(
        omega=omega,
        force_amplitude=force,
        x_max=x_max,
        x_min=x_min,
        amplitude=amplitude,
        stable=stable,
        multipliers=mu,
        initial_state=start_states,
        events=events,
        parameter=parameter,
        stop_reason=reason,
        free_play=free_play,
        solver=__name__,
        settings={
            "joint": joint,
            "losses": losses,
        },
    )


def _turned_round(curve: FrequencyResponse) -> FrequencyResponse:
    """``curve`` from its last point to its first (followed from the other end)."""
    reason = curve.stop_reason
    if reason != "reached":
        reason = (
            f"followed from the other end (the start is a free-play orbit), which stopped: {reason}"
        )
    return FrequencyResponse(
        omega=curve.omega[::-1].copy(),
        force_amplitude=curve.force_amplitude[::-1].copy(),
        x_max=curve.x_max[::-1].copy(),
        x_min=curve.x_min[::-1].copy(),
        amplitude=curve.amplitude[::-1].copy(),
        stable=curve.stable[::-1].copy(),
        multipliers=curve.multipliers[::-1].copy(),
        initial_state=curve.initial_state[::-1].copy(),
        events=curve.events[::-1],
        parameter=curve.parameter,
        stop_reason=reason,
        settings=curve.settings,
        free_play=None if curve.free_play is None else curve.free_play[::-1].copy(),
        solver=curve.solver,
    )


def _free_play_tail(
    p: FloatArray,
    branch: Branch,
    refused_at: list[float],
    stop: float,
    points: int,
    code: int = 0,
) -> NDArray[np.float64] | None:
    """The centred in-gap orbits from where ``branch`` stopped on to ``stop`` (k0 = 0), or None.

    Only when the branch stopped on an orbit that touches a gap edge within 1e-3 of
    the clearance (where the contact branch meets the continuum of in-gap orbits,
    whose widest members touch an edge), the continuation's steps there converged onto
    in-gap orbits (``refused_at``: within 1e-3 of the range of the stop), and the
    centred member (``_free_play_orbit``)
    exists close to that frequency (at 0.001, 0.01 or 0.1 of the first grid step on).
    The grid is uniform in the parameter (omega with ``code`` 0, F0 with 1), 0.5 %
    of the range a step (at most ``points`` points in all). Rows: a map_residual
    row (x0, v0 in the first two places) and the parameter.
    """
    last = branch.data[-1]
    gap = p[kn.P_GC] + p[kn.P_GT]
    touching = min(abs(last[R_XMAX] - p[kn.P_GC]), abs(-p[kn.P_GT] - last[R_XMIN]))
    lam = float(branch.lam[-1])
    reach = 1e-3 * abs(stop - float(branch.lam[0]))
    if touching > 1e-3 * gap or points < 1 or lam == stop:
        return None
    if not any(abs(w - lam) <= reach for w in refused_at):
        return None  # the steps there did not meet in-gap orbits: another kind of stop
    count = min(points, max(2, math.ceil(abs(stop - lam) / (0.005 * abs(stop - branch.lam[0])))))
    grid = np.linspace(lam, stop, count + 1)[1:]
    # close to the junction first (the widest orbit that fits), then the grid
    near = lam + np.array([1e-3, 1e-2, 1e-1]) * (grid[0] - lam)
    rows: list[FloatArray] = []
    for w in np.concatenate((near, grid)):
        orbit = _free_play_orbit(p, float(w), code)
        if orbit is None:
            if rows or w > near[-1]:
                break
            continue
        rows.append(np.append(orbit, w))
    return np.array(rows[:points]) if rows else None


def _seed(
    joint: Joint,
    force: float,
    omega: float,
    lam: float,
    parameter: str,
    losses: Losses,
) -> FloatArray | None:
    """A period-1 orbit at parameter ``lam`` from a transient (``periodic_orbit``), or None.

    None too when its multiplier is 1 (a continuum of orbits: no single branch).
    """
    w, f = (lam, force) if parameter == "omega" else (omega, lam)
    try:
        orbit = periodic_orbit(joint, f, w, losses=losses)
    except SimulationError:
        return None
    if np.min(np.abs(orbit.multipliers - 1.0)) < 1e-9:
        return None
    return np.array(orbit.initial_state, dtype=np.float64)


def _rejoin(
    branch: Branch,
    follow: Callable[..., Branch],
    seed: Callable[[float], FloatArray | None],
    start: float,
    stop: float,
    max_points: int,
) -> Branch | None:
    """Go on past a point where the continuation stopped, from a period-1 orbit further on.

    At parameters beyond the furthest one the branch reached (``_SEED_FACTORS``
    of the way on to ``stop``), a period-1 orbit is sought by a transient and
    Newton; from the first one found the branch is followed back towards
    ``start`` until it reaches the point where ``branch`` stopped ("joined":
    the crossing the stopped branch could not make, made from the other side),
    then on to ``stop``. Returns the branch followed through, in order (``branch``,
    the way back reversed, the way on), with a kink where the two meet; None when
    no seed's branch joins it.
    """
    direction = 1.0 if stop > start else -1.0
    furthest = float(np.max(direction * branch.lam)) * direction
    left = max_points - branch.lam.size
    for factor in _SEED_FACTORS:
        lam = furthest + factor * (stop - furthest)
        u0 = seed(lam)
        if u0 is None or left < 4:
            continue
        back = follow(
            u0,
            lam,
            start,
            min(left, _BACK_POINTS),
            (branch.u[-1], float(branch.lam[-1]), branch.data[-1]),
        )
        if back.reason != "joined":
            continue
        on = follow(back.u[0], float(back.lam[0]), stop, max(2, left - back.lam.size + 1))
        n, m = branch.lam.size, back.lam.size
        kinks = [
            *branch.kinks,
            n,
            *(n + m - k for k in back.kinks),
            *(n + m - 1 + k for k in on.kinks),
        ]
        return Branch(
            u=np.concatenate((branch.u, back.u[::-1], on.u[1:])),
            lam=np.concatenate((branch.lam, back.lam[::-1], on.lam[1:])),
            tangent=np.concatenate((branch.tangent, -back.tangent[::-1], on.tangent[1:])),
            iterations=np.concatenate(
                (branch.iterations, back.iterations[::-1], on.iterations[1:])
            ),
            data=[*branch.data, *back.data[::-1], *on.data[1:]],
            reason=on.reason,
            kinks=np.array(kinks, dtype=np.int64),
        )
    return None


def _events(
    joint: Joint,
    lam_tangent: FloatArray,
    mono: FloatArray,
    x_max: FloatArray,
    x_min: FloatArray,
    omega: FloatArray,
    force: FloatArray,
    amplitude: FloatArray,
    kinks: NDArray[np.int64] | None = None,
    sticking: NDArray[np.bool_] | None = None,
) -> list[ResponseEvent]:
    """Folds, period doublings and grazings between successive points, located linearly.

    A kink the continuation crossed by a parameter step (``kinks``: the index of
    the point after it) is a grazing too: where no edge crossing of x_max or x_min
    explains it, the orbit grazed an edge from inside contact (a short stage
    appears or vanishes) or began to stick; it is placed at the last point before.
    ``sticking`` (one per kink) says where the orbits on the two sides differ in
    whether they stick: a corner at a sticking onset, named so in the note.
    """
    trace = mono[:, 0, 0] + mono[:, 1, 1]
    det = mono[:, 0, 0] * mono[:, 1, 1] - mono[:, 0, 1] * mono[:, 1, 0]
    tests = {
        "fold": (lam_tangent, ""),
        "period_doubling": (
            1.0 + trace + det,
            "a multiplier passes -1: a period-2 branch is born here (not followed)",
        ),
        "grazing": (x_max - joint.compression_gap, "the orbit touches the compression edge"),
        "grazing_t": (-joint.tension_gap - x_min, "the orbit touches the tension edge"),
    }
    events: list[tuple[int, ResponseEvent]] = []
    for name, (g, note) in tests.items():
        kind = "grazing" if name.startswith("grazing") else name
        for i in np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]:
            frac = float(g[i] / (g[i] - g[i + 1]))
            if kind == "fold":
                # the parameter is extreme at a fold: take the bracketing point that is further
                # out (a linear interpolation of the tangent is wrong at a grazing kink)
                lam = omega if np.ptp(omega) > 0.0 else force
                steps = np.sign(np.diff(lam[max(i - 1, 0) : i + 3]))
                if steps.size and np.all(steps == steps[0]):
                    # the parameter goes on the same way through: the tangent flipped at a
                    # point where the section sits on an impact (the state jumps), no fold
                    continue
                turn = float(np.sign(lam[i + 1] - lam[i]) * np.sign(g[i]))
                frac = 1.0 if turn > 0 else 0.0

            def at(a: FloatArray, i: int = int(i), frac: float = frac) -> float:
                return float(a[i] + frac * (a[i + 1] - a[i]))

            said = note
            if kind == "period_doubling" and kinks is not None and int(i) + 1 in kinks:
                # across a kink the multiplier jumps over -1 rather than passing it: a
                # nonsmooth bifurcation, after which no period-2 branch need exist
                said = (
                    "a multiplier jumps across -1 at a kink of the branch (a nonsmooth "
                    "bifurcation): a period-2 branch may or may not be born here (not checked)"
                )
            events.append((int(i), ResponseEvent(kind, at(omega), at(force), at(amplitude), said)))
    for n, k in enumerate(kinks if kinks is not None else []):
        before = int(k) - 1
        if not any(index == before and e.kind == "grazing" for index, e in events):
            if sticking is not None and sticking[n]:
                note = (
                    "a corner of the branch where sticking begins or ends (a velocity zero "
                    "of the orbit becomes tangent): the map is continuous, its Jacobian jumps"
                )
            else:
                note = (
                    "a kink crossed by a parameter step: a stage appears or vanishes (the orbit "
                    "grazes a gap edge from inside contact) or sticking begins"
                )
            lam = omega if np.ptp(omega) > 0.0 else force
            if before >= 1 and (lam[before] - lam[before - 1]) * (lam[k] - lam[before]) < 0.0:
                note += "; the branch turns back here (a nonsmooth fold)"
            where = (float(omega[before]), float(force[before]), float(amplitude[before]))
            events.append((before, ResponseEvent("grazing", *where, note)))
    events.sort(key=lambda item: item[0])
    merged: list[tuple[int, ResponseEvent]] = []
    for index, event in events:
        if (
            merged
            and event.kind == "grazing"
            and merged[-1][1].kind == "grazing"
            and merged[-1][0] == index
        ):
            merged[-1] = (
                index,
                ResponseEvent(
                    "grazing",
                    event.omega,
                    event.force_amplitude,
                    event.amplitude,
                    "the orbit touches both gap edges",
                ),
            )
            continue
        merged.append((index, event))
    return [e for _, e in merged]
