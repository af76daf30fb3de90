"""Exact time-domain response of the forced clearance joint, with its energy ledger.

MODEL.md sec. 2: m x'' + c_v x' + f(x) + mu_s P sgn(x') = F0 sin(w t), with
x' -> e x' on entering contact. The motion is advanced state by state in closed
form by the compiled kernel (``clearjoint.exact.kernel``); this module sets it up,
detects the steady state (period-1 or period-n, from the stroboscopic map at every forcing
period), samples the cycle and closes the energy balance.

The contact-friction term of MODEL.md (mu_c on the pin's contact arc) is
*evaluated along the cycle without feedback on the motion*, as the paper does:
it is reported in the ledger but is not among the losses that balance the input.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.errors import ParameterError
from clearjoint.errors import SimulationError as SimulationError
from clearjoint.exact import kernel as kn
from clearjoint.exact.shooting import newton_orbit, start_state
from clearjoint.exact.single import (
    check_samples,
    initial_state,
    motion_fields,
    orbit_from,
    run_kernel,
    run_kernel_in_pieces,
    sample_times,
    setup,
)
from clearjoint.joint import Joint, Losses, takes_losses
from clearjoint.progress import report, silenced

# the results moved to clearjoint.results; imported "as" themselves so that the old path
# clearjoint.simulate.core re-exports them (and the API reference documents them once)
from clearjoint.results.motion import EnergyLedger as EnergyLedger
from clearjoint.results.motion import FrequencySweep as FrequencySweep
from clearjoint.results.motion import Motion as Motion
from clearjoint.results.motion import Stage as Stage
from clearjoint.results.motion import SteadyState as SteadyState
from clearjoint.system import VibrationSystem, as_joint
from clearjoint.units import to_si

FloatArray = NDArray[np.float64]


# ---- set-up -------------------------------------------------------------------------------


# ---- running the kernel and turning its records into a Motion ----------------------------


# ---- public API ---------------------------------------------------------------------------


@takes_losses
def time_response(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega: float,
    duration: float,
    *,
    initial: ArrayLike | None = None,
    samples_per_period: int = 256,
    sampling_rate: float | None = None,
    losses: Losses | None = None,
) -> Motion:
    """Return the exact transient response from ``initial`` = (x0, v0) over ``duration`` s.

    The forcing is F0 sin(omega t) from t = 0 (omega in rad/s). The ledger covers
    the whole run, so input = losses + mechanical_energy_change. The motion is
    sampled ``samples_per_period`` times per forcing period, or at
    ``sampling_rate`` (Hz) when that is given. ``losses`` (:class:`~clearjoint.Losses`,
    default none) or the one-DOF system given as ``joint`` carry the damping, friction,
    restitution and the pin. The kernel runs in pieces of whole forcing periods and reports
    the seconds done after each (:func:`clearjoint.progress.report`); the motion is the same.
    """
    joint, losses, p = setup(joint, force_amplitude, omega, losses)
    duration = _checks.positive("duration", duration, unit="s")
    time = sample_times(duration, p[kn.P_TF], samples_per_period, sampling_rate)
    pin, mu_c = losses.pin, losses.contact_friction_coefficient
    state = initial_state(p, initial)
    start = state.copy()
    tf = p[kn.P_TF]
    n_full = int(duration // tf)
    remainder = duration - n_full * tf
    if remainder <= 1e-12 * tf and n_full > 0:
        n_periods, t_last = n_full, tf
    else:
        n_periods, t_last = n_full + 1, remainder
    run = run_kernel_in_pieces(p, state, n_periods, t_last)  # reports its progress
    fields = motion_fields(p, joint, run, start, time, pin, mu_c)
    return Motion(**fields)  # type: ignore[arg-type]


def _periodic_multiple(
    strobe: FloatArray, max_multiple: int, tolerance: float, x_scale: float, v_scale: float
) -> int:
    """Smallest p such that the last 2p stroboscopic states repeat with period p (0 if none)."""
    n = strobe.shape[0]
    for mult in range(1, max_multiple + 1):
        if n < 3 * mult:
            break
        recent = strobe[-2 * mult :]
        before = strobe[-3 * mult : -mult]
        dx = np.max(np.abs(recent[:, kn.S_X] - before[:, kn.S_X])) / x_scale
        dv = np.max(np.abs(recent[:, kn.S_V] - before[:, kn.S_V])) / v_scale
        same_discrete = np.array_equal(recent[:, 2:], before[:, 2:])
        if dx <= tolerance and dv <= tolerance and same_discrete:
            return mult
    return 0


def periods_left(
    strobe: FloatArray, max_multiple: int, tolerance: float, x_scale: float, v_scale: float
) -> float | None:
    """How many more forcing periods the transient needs to settle, from its own decay.

    The distance between stroboscopic states ``m`` periods apart (``m`` <= ``max_multiple``,
    scaled as :func:`_periodic_multiple` scales it) shrinks about geometrically while the
    transient dies away, by the largest Floquet multiplier's modulus a period, and swings
    as the transient's oscillation turns. A straight line fitted to its logarithm over the
    latter half of ``strobe`` gives the rate; the line's end, raised by the largest swing
    above it, the level now; the periods left are those that bring that level down to
    ``tolerance``, for the lag whose level is least. None where the fitted distance does
    not shrink or fewer than sixteen periods are known. An estimate, not a verdict: a motion
    that never settles (lossless, chaotic) may still give a number, by the fit's noise,
    though one of a million periods and more (``tests/test_simulate_progress.py``); the
    caller caps it at the most it will run.
    """
    best: tuple[float, float] | None = None
    for lag in range(1, max_multiple + 1):
        if strobe.shape[0] < lag + 16:
            break
        dx = np.abs(strobe[lag:, kn.S_X] - strobe[:-lag, kn.S_X]) / x_scale
        dv = np.abs(strobe[lag:, kn.S_V] - strobe[:-lag, kn.S_V]) / v_scale
        distance = np.maximum(dx, dv)[(strobe.shape[0] - lag) // 2 :]  # the latter half
        if not np.all(distance > 0.0) or not np.all(np.isfinite(distance)):
            continue
        periods = np.arange(distance.size, dtype=np.float64)
        slope, intercept = np.polyfit(periods, np.log(distance), 1)
        if not slope < 0.0:
            continue
        # the envelope's level now: the fitted line at the end, raised by its largest swing
        swing = float(np.max(np.log(distance) - (slope * periods + intercept)))
        level = slope * periods[-1] + intercept + swing
        left = max((math.log(tolerance) - level) / slope, 0.0) + 2 * lag
        if best is None or level < best[0]:
            best = (level, left)
    return None if best is None else best[1]


def _smallest_multiple(
    p: FloatArray,
    state: FloatArray,
    multiple: int,
    strobe: FloatArray,
    tolerance: float,
    x_scale: float,
    v_scale: float,
) -> int:
    """Test each multiple below the detected one against the orbit itself.

    A transient that converges with alternating sign (a multiplier near -1, or
    a complex pair whose angle is near 2 pi/n) repeats sooner over n periods
    than over one. For each d < ``multiple``, Newton's method on the exact
    d-period map (``_shooting.newton_orbit``) from the current state looks for a
    d-periodic orbit; it is accepted when it is stable and the recent states
    approach it (their distance to it shrinks), and ``state`` is moved onto it.
    Returns the smallest multiple that holds.
    """
    scale = np.array([x_scale, v_scale])
    for d in range(1, multiple):
        found = newton_orbit(p, state[:2], d, scale, tolerance=tolerance)
        if found is None:
            continue
        z, shot, _ = found
        if np.max(np.abs(np.linalg.eigvals(shot.monodromy))) >= 1.0:
            continue  # an unstable d-orbit (e.g. past a period doubling): not where we converge
        dist = np.max(np.abs(strobe[:, :2] - z) / scale, axis=1)
        if dist[-1] > 10.0 * tolerance and dist[-1] > 0.9 * float(np.max(dist[:-multiple])):
            continue  # the states circle the d-orbit instead of approaching it
        prefer(start_state)(p, float(z[0]), float(z[1]), state)
        return d
    return multiple


@takes_losses
def steady_state(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omega: float,
    *,
    initial: ArrayLike | None = None,
    max_periods: int = 20_000,
    max_multiple: int = 8,
    tolerance: float = 1e-11,
    samples_per_period: int = 256,
    losses: Losses | None = None,
) -> SteadyState:
    """Return the steady periodic response of the forced joint (MODEL.md sec. 2).

    Integrates exactly, from ``initial`` (x0, v0; default at rest at x = 0),
    until the state at the start of each forcing period repeats with some period
    p <= ``max_multiple`` forcing periods, to ``tolerance`` relative to the
    motion's size; then returns that orbit (p = 1: period-1; p > 1: period-p,
    detected, not assumed). Its energy ledger is summed over the orbit's p
    periods.

    Parameters
    ----------
    joint : Joint or VibrationSystem
        The joint, or a system of one DOF and one joint (``VibrationSystem.to_joint``).
    force_amplitude : float
        F0 > 0, N.
    omega : float
        Forcing circular frequency w > 0, rad/s.
    losses : Losses, optional
        Viscous damping ratio, Coulomb friction, restitution (each impact removes
        beta m v^2 with beta = (1 - e^2)/2, MODEL.md eq 16) and the pin with its
        contact friction coefficient (eq 15, evaluated along the cycle). Default none.
        A one-DOF :class:`~clearjoint.system.VibrationSystem` given as ``joint``
        carries its own.

    Raises
    ------
    SimulationError
        No periodic orbit was found within ``max_periods`` (e.g. a lossless
        system, which never settles, or a chaotic response).
    """
    joint, losses, p = setup(joint, force_amplitude, omega, losses)
    check_samples(samples_per_period)
    pin, mu_c = losses.pin, losses.contact_friction_coefficient
    if max_periods < 1 or max_multiple < 1:
        raise ParameterError("max_periods and max_multiple must be >= 1")
    tol = _checks.positive("tolerance", tolerance)
    lossless = p[kn.P_DAMP] == 0.0 and p[kn.P_FF] == 0.0 and p[kn.P_E] == 1.0
    state = initial_state(p, initial)
    history: list[FloatArray] = []
    done = 0
    chunk = 16
    multiple = 0
    while done < max_periods:
        n = min(chunk, max_periods - done)
        run = run_kernel(p, state, n, p[kn.P_TF], record=False)
        history.append(run.strobe.copy())
        done += n
        strobe = np.concatenate(history[-4:]) if len(history) > 1 else history[-1]
        x_scale = max(float(np.ptp(strobe[:, 0])), joint.clearance, 1e-300)
        x_scale = max(x_scale, float(np.max(np.abs(strobe[:, 0]))))
        v_scale = max(float(np.max(np.abs(strobe[:, 1]))), x_scale * p[kn.P_W])
        multiple = _periodic_multiple(strobe, max_multiple, tol, x_scale, v_scale)
        if multiple:
            report(done, done)
            break
        # a listening bar shows the periods done and an estimate of the total; without an
        # estimate it counts them against the most it will run (max_periods), never less
        left = periods_left(strobe, max_multiple, tol, x_scale, v_scale)
        report(done, max_periods if left is None else min(done + left, max_periods))
        chunk = min(2 * chunk, 1024)
    if not multiple:
        hint = (
            "the system has no damping, friction or impact loss, so it never settles; "
            "give damping_ratio > 0, friction or restitution < 1"
            if lossless
            else "raise max_periods, or the response may be chaotic"
        )
        raise SimulationError(f"no periodic orbit within {max_periods} forcing periods: {hint}")
    if multiple > 1:
        multiple = _smallest_multiple(p, state, multiple, strobe, tol, x_scale, v_scale)
    return orbit_from(p, joint, state, multiple, done, pin, mu_c, samples_per_period)


@takes_losses
def frequency_sweep(
    joint: Joint | VibrationSystem,
    force_amplitude: float,
    omegas: ArrayLike,
    *,
    direction: Literal["up", "down", "both"] = "both",
    losses: Losses | None = None,
    max_periods: int = 20_000,
    keep_cycles: bool = False,
) -> FrequencySweep:
    """Return the stepped-sine amplitude-frequency curve, swept up and/or down.

    Each step starts from the previous step's steady state, so the jump and the
    hysteresis of the amplitude-frequency curve show up as they do on a shaker.
    ``omegas`` (rad/s) are sorted ascending; the down sweep visits them in reverse.
    A step with no steady state gives NaN rather than stopping the sweep.
    ``losses`` as for :func:`steady_state`.
    """
    joint, losses = as_joint(joint, losses)
    w = np.sort(np.atleast_1d(np.asarray(to_si(omegas, "rad/s", name="omegas"), dtype=float)))
    if w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0.0):
        raise ParameterError("omegas must be a non-empty array of finite values > 0 (rad/s)")
    if direction not in ("up", "down", "both"):
        raise ParameterError(f"direction must be 'up', 'down' or 'both', got {direction!r}")

    def sweep(order: FloatArray) -> tuple[FloatArray, NDArray[np.int64], list[SteadyState | None]]:
        amps = np.full(order.size, np.nan)
        mults = np.zeros(order.size, dtype=np.int64)
        cycles: list[SteadyState | None] = []
        initial: tuple[float, float, int, int] | None = None
        for i, omega in enumerate(order):
            try:
                with silenced():  # the sweep reports its steps, not each step's periods
                    ss = steady_state(
                        joint,
                        force_amplitude,
                        float(omega),
                        losses=losses,
                        initial=initial,
                        max_periods=max_periods,
                        samples_per_period=16,
                    )
            except SimulationError:
                cycles.append(None)
                continue
            finally:
                steps[0] += 1
                report(steps[0], steps[1])
            amps[i] = ss.amplitude
            mults[i] = ss.period_multiple
            initial = ss.initial_state
            cycles.append(ss if keep_cycles else None)
        return amps, mults, cycles

    nan = np.full(w.size, np.nan)
    zeros = np.zeros(w.size, dtype=np.int64)
    steps = [0, w.size * (2 if direction == "both" else 1)]  # done, to do
    up, m_up, c_up = sweep(w) if direction in ("up", "both") else (nan, zeros, [])
    if direction in ("down", "both"):
        down_r, m_down_r, c_down_r = sweep(w[::-1])
        down, m_down, c_down = down_r[::-1], m_down_r[::-1], c_down_r[::-1]
    else:
        down, m_down, c_down = nan.copy(), zeros.copy(), []
    return FrequencySweep(w, up, down, m_up, m_down, tuple(c_up), tuple(c_down))
