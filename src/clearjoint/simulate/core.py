"""Exact time-domain response of the forced clearance joint, with its energy ledger.

MODEL.md sec. 2: m x'' + c_v x' + f(x) + mu_s P sgn(x') = F0 sin(w t), with
x' -> e x' on entering contact. The motion is advanced state by state in closed
form by the compiled kernel (``_kernel.py``); this module sets it up, detects the
steady state (period-1 or period-n, from the stroboscopic map at every forcing
period), samples the cycle and closes the energy balance.

The contact-friction term of MODEL.md (mu_c on the pin's contact arc) is
*evaluated along the cycle without feedback on the motion*, as the paper does:
it is reported in the ledger but is not among the losses that balance the input.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.contact import contact_friction_power, hertz_contact
from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.joint import Friction, Joint, Losses, Pin, unpack_losses

# the results moved to clearjoint.results; imported "as" themselves so that the old path
# clearjoint.simulate.core re-exports them (and the API reference documents them once)
from clearjoint.results.motion import EnergyLedger as EnergyLedger
from clearjoint.results.motion import FrequencySweep as FrequencySweep
from clearjoint.results.motion import Motion as Motion
from clearjoint.results.motion import Stage as Stage
from clearjoint.results.motion import SteadyState as SteadyState
from clearjoint.simulate import _kernel as kn
from clearjoint.simulate._shooting import newton_orbit, start_state
from clearjoint.stiffness import viscous_coefficient
from clearjoint.units import to_si

FloatArray = NDArray[np.float64]

STAGE_NAMES = {kn.FREE: "free-play", kn.COMPRESSION: "compression", kn.TENSION: "tension"}


class SimulationError(ClearjointError, RuntimeError):
    """The simulation could not do what was asked (no steady state, too many events...)."""


# ---- set-up -------------------------------------------------------------------------------


def _parameters(
    joint: Joint,
    force_amplitude: float,
    omega: float,
    damping_ratio: float,
    friction: Friction | None,
    restitution: float,
) -> FloatArray:
    f0 = _checks.positive("force_amplitude", force_amplitude, unit="N")
    w = _checks.positive("omega", omega, unit="rad/s")
    e = _checks.real_scalar("restitution", restitution)
    if not 0.0 <= e <= 1.0:
        raise ParameterError(f"restitution must satisfy 0 <= e <= 1, got {e!r}")
    if friction is not None and not isinstance(friction, Friction):
        raise ParameterError(
            f"friction must be a clearjoint.Friction(coefficient, lateral_load), got {friction!r}"
        )
    if not isinstance(joint, Joint):
        raise ParameterError(f"joint must be a clearjoint.Joint, got {joint!r}")
    p = np.zeros(kn.N_PARAMS)
    p[kn.P_MASS] = joint.mass
    p[kn.P_DAMP] = viscous_coefficient(joint, damping_ratio)
    p[kn.P_K0] = joint.gap_stiffness
    p[kn.P_KC] = joint.compression_stiffness
    p[kn.P_KT] = joint.tension_stiffness
    p[kn.P_GC] = joint.compression_gap
    p[kn.P_GT] = joint.tension_gap
    p[kn.P_F0] = f0
    p[kn.P_W] = w
    p[kn.P_E] = e
    p[kn.P_TF] = 2.0 * math.pi / w
    if friction is not None and friction.force > 0.0:
        p[kn.P_FF] = friction.force
        p[kn.P_FMODE] = (
            kn.FRICTION_EVERYWHERE if friction.region == "everywhere" else kn.FRICTION_FREE_PLAY
        )
    return p


def _initial_state(p: FloatArray, initial: ArrayLike | None) -> FloatArray:
    if initial is None:
        x0, v0 = 0.0, 0.0
        values: Sequence[float] = (0.0, 0.0)
    else:
        values = [float(v) for v in np.ravel(np.asarray(initial, dtype=np.float64))]
        if len(values) not in (2, 4) or not all(math.isfinite(v) for v in values):
            raise ParameterError(f"initial must be (x0, v0) in m and m/s, finite, got {initial!r}")
        x0, v0 = values[0], values[1]
    state = np.zeros(4)
    state[kn.S_X] = x0
    state[kn.S_V] = v0
    if len(values) == 4:  # a state handed back by a SteadyState: keep its region and slip
        state[kn.S_REGION] = values[2]
        state[kn.S_SLIP] = values[3]
        return state
    region = kn.region_of(p, x0, v0)
    state[kn.S_REGION] = region
    state[kn.S_SLIP] = (1 if v0 > 0 else -1) if v0 != 0.0 else kn.decide_slip(p, region, x0, 0.0)
    return state


# ---- running the kernel and turning its records into a Motion ----------------------------


@dataclass
class _Run:
    segments: FloatArray
    impacts: FloatArray
    strobe: FloatArray
    ledger: FloatArray
    events: int


def _run(p: FloatArray, state: FloatArray, n_periods: int, t_last: float, record: bool) -> _Run:
    if n_periods < 1:
        raise ParameterError("the duration must cover a positive time")
    strobe = np.zeros((n_periods, 4))
    ledger = np.zeros((n_periods, kn.LEDGER_WIDTH))
    capacity = 64 * n_periods if record else 1
    while True:
        segments = np.zeros((capacity, kn.SEG_WIDTH))
        impacts = np.zeros((capacity, kn.IMP_WIDTH))
        start = state.copy()
        n_seg, n_imp, events, status = kn.advance(
            p, start, n_periods, t_last, record, segments, impacts, strobe, ledger
        )
        if status == kn.STATUS_SEGMENTS_FULL:
            capacity *= 4
            continue
        if status == kn.STATUS_TOO_MANY_EVENTS:
            raise SimulationError(
                f"more than {kn.MAX_EVENTS_PER_PERIOD} events in one forcing period "
                "(chattering); add damping or a restitution below 1"
            )
        if status == kn.STATUS_MARCH_FAILED:
            raise SimulationError(
                f"an event was not reached in {kn.MAX_MARCH_STEPS} certified steps at "
                f"x = {start[kn.S_X]!r} m (a near-grazing state the marching cannot resolve); "
                "change omega or the force amplitude slightly"
            )
        state[:] = start
        return _Run(segments[:n_seg], impacts[:n_imp], strobe, ledger, events)


def _mechanical_energy(joint: Joint, x: float, v: float) -> float:
    return 0.5 * joint.mass * v * v + float(joint.potential_energy(x))


def _contact_friction(
    p: FloatArray,
    joint: Joint,
    run: _Run,
    pin: Pin | None,
    friction_coefficient: float,
) -> float:
    """MODEL.md eq 14-15 along the recorded motion: the integral of the arc friction power.

    :func:`clearjoint.contact.contact_friction_power` at the pin's normal force
    (:meth:`ClearanceJoint.contact_force`), by Gauss-Legendre over each contact segment.
    """
    if pin is None or friction_coefficient == 0.0:
        return 0.0
    nodes, weights = np.polynomial.legendre.leggauss(64)
    tf = p[kn.P_TF]
    total = 0.0
    peak = 0.0
    for row in run.segments:
        region = int(row[kn.SEG_REGION])
        if region == kn.FREE or row[kn.SEG_DT] <= 0.0 or row[kn.SEG_SLIP] == 0:
            continue
        start = row[kn.SEG_PERIOD] * tf + row[kn.SEG_T0]
        times = start + 0.5 * row[kn.SEG_DT] * (nodes + 1.0)
        out = np.zeros((times.size, 3))
        kn.sample(p, row[None, :], 1, times, out)
        force = joint.element.contact_force(out[:, 0])
        power = contact_friction_power(pin, friction_coefficient, force, out[:, 1])
        total += 0.5 * row[kn.SEG_DT] * float(np.sum(weights * power))
        peak = max(peak, float(force.max()))
    hertz_contact(pin, peak)  # warns when the arc is too wide for Hertz
    return total


def _stages(regions: NDArray[np.int64], starts: FloatArray, ends: FloatArray) -> tuple[Stage, ...]:
    """Merge consecutive segments of one region into stages; drop empty ones between others.

    A segment of zero length (an event at the very instant another ended) opens no
    stage of its own unless it is the first; one in the region of the stage before
    it extends that stage to its end. Vectorised: one Stage per stage, not per segment.
    """
    n = regions.size
    if n == 0:
        return ()
    index = np.arange(n)
    opens = (ends > starts) | (index == 0)
    # the last segment before each one that had a length (or the first): the stage it is in
    before = np.maximum.accumulate(np.where(opens, index, 0))
    before = np.concatenate(([0], before[:-1]))
    keep = opens | (regions == regions[before])
    kept_regions = regions[keep]
    first = np.flatnonzero(np.concatenate(([True], kept_regions[1:] != kept_regions[:-1])))
    last = np.concatenate((first[1:] - 1, [kept_regions.size - 1]))
    kept_starts = starts[keep][first].tolist()
    kept_ends = ends[keep][last].tolist()
    return tuple(
        Stage(STAGE_NAMES[region], start, end)
        for region, start, end in zip(
            kept_regions[first].tolist(), kept_starts, kept_ends, strict=True
        )
    )


def _motion_fields(
    p: FloatArray,
    joint: Joint,
    run: _Run,
    start_state: FloatArray,
    time: FloatArray,
    pin: Pin | None,
    contact_friction_coefficient: float,
) -> dict[str, object]:
    tf = p[kn.P_TF]
    out = np.zeros((time.size, 3))
    kn.sample(p, run.segments, run.segments.shape[0], time, out)
    x, v, a = out[:, 0], out[:, 1], out[:, 2]
    seg = run.segments
    starts = seg[:, kn.SEG_PERIOD] * tf + seg[:, kn.SEG_T0]
    ends = starts + seg[:, kn.SEG_DT]
    stages = _stages(seg[:, kn.SEG_REGION].astype(np.int64), starts, ends)
    # extremes: v never changes sign inside a state, so they sit at state boundaries
    end_state = run.strobe[-1]
    boundary_x = np.concatenate((seg[:, kn.SEG_X0], [end_state[kn.S_X]]))
    ledger = run.ledger.sum(axis=0)
    energy = EnergyLedger(
        input=float(ledger[kn.L_INPUT]),
        viscous=float(ledger[kn.L_VISCOUS]),
        sliding_friction=float(ledger[kn.L_SLIDING]),
        impact=float(ledger[kn.L_IMPACT]),
        contact_friction=_contact_friction(p, joint, run, pin, contact_friction_coefficient),
        mechanical_energy_change=_mechanical_energy(joint, end_state[kn.S_X], end_state[kn.S_V])
        - _mechanical_energy(joint, start_state[kn.S_X], start_state[kn.S_V]),
    )
    imp = run.impacts
    return {
        "time": time,
        "displacement": x,
        "velocity": v,
        "acceleration": a,
        "excitation": p[kn.P_F0] * np.sin(p[kn.P_W] * time),
        "restoring_force": joint.restoring_force(x),
        "stages": tuple(stages),
        "impact_times": imp[:, 0] * tf + imp[:, 1],
        "impact_velocities": imp[:, 2] * imp[:, 3],
        "energy": energy,
        "events": run.events,
        "x_max": float(boundary_x.max()),
        "x_min": float(boundary_x.min()),
        "stick_time": float(np.sum(seg[:, kn.SEG_DT][seg[:, kn.SEG_SLIP] == 0])),
        "final_state": (float(end_state[kn.S_X]), float(end_state[kn.S_V])),
    }


# ---- public API ---------------------------------------------------------------------------


def time_response(
    joint: Joint,
    force_amplitude: float,
    omega: float,
    duration: float,
    *,
    initial: ArrayLike | None = None,
    damping_ratio: float = 0.0,
    friction: Friction | None = None,
    restitution: float = 1.0,
    pin: Pin | None = None,
    contact_friction_coefficient: float = 0.0,
    samples_per_period: int = 256,
    sampling_rate: float | None = None,
    losses: Losses | None = None,
) -> Motion:
    """Return the exact transient response from ``initial`` = (x0, v0) over ``duration`` s.

    The forcing is F0 sin(omega t) from t = 0 (omega in rad/s). The ledger covers
    the whole run, so input = losses + mechanical_energy_change. The motion is
    sampled ``samples_per_period`` times per forcing period, or at
    ``sampling_rate`` (Hz) when that is given.
    """
    damping_ratio, friction, restitution, pin, contact_friction_coefficient = unpack_losses(
        losses, damping_ratio, friction, restitution, pin, contact_friction_coefficient
    )
    p = _parameters(joint, force_amplitude, omega, damping_ratio, friction, restitution)
    duration = _checks.positive("duration", duration, unit="s")
    time = _sample_times(duration, p[kn.P_TF], samples_per_period, sampling_rate)
    mu_c = _checks.non_negative("contact_friction_coefficient", contact_friction_coefficient)
    state = _initial_state(p, initial)
    start = state.copy()
    tf = p[kn.P_TF]
    n_full = int(duration // tf)
    remainder = duration - n_full * tf
    if remainder <= 1e-12 * tf and n_full > 0:
        n_periods, t_last = n_full, tf
    else:
        n_periods, t_last = n_full + 1, remainder
    run = _run(p, state, n_periods, t_last, record=True)
    fields = _motion_fields(p, joint, run, start, time, pin, mu_c)
    return Motion(**fields)  # type: ignore[arg-type]


def _sample_times(
    duration: float, period: float, samples_per_period: int, sampling_rate: float | None
) -> FloatArray:
    """Uniform sample times over [0, duration): per forcing period, or at a rate in Hz."""
    if sampling_rate is not None:
        rate = _checks.positive("sampling_rate", sampling_rate, unit="Hz")
        n = max(math.floor(duration * rate * (1.0 + 1e-12)), 2)
        return np.arange(n) / rate
    _check_samples(samples_per_period)
    n = max(round(samples_per_period * duration / period), 2)
    if duration >= period:
        return np.linspace(0.0, duration, n + 1)[:-1]
    return np.linspace(0.0, duration, n)


def _check_samples(samples_per_period: int) -> None:
    if (
        isinstance(samples_per_period, bool)
        or not isinstance(samples_per_period, int)
        or (samples_per_period < 8)
    ):
        raise ParameterError(
            f"samples_per_period must be an integer >= 8, got {samples_per_period!r}"
        )


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
        start_state(p, float(z[0]), float(z[1]), state)
        return d
    return multiple


def steady_state(
    joint: Joint,
    force_amplitude: float,
    omega: float,
    *,
    damping_ratio: float = 0.0,
    friction: Friction | None = None,
    restitution: float = 1.0,
    pin: Pin | None = None,
    contact_friction_coefficient: float = 0.0,
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
    joint : Joint
    force_amplitude : float
        F0 > 0, N.
    omega : float
        Forcing circular frequency w > 0, rad/s.
    damping_ratio : float
        zeta >= 0 of the linear part: c_v = 2 zeta sqrt(m k_c), held fixed.
    friction : Friction, optional
        Coulomb sliding friction mu_s P sign(x').
    restitution : float
        Coefficient of restitution e in [0, 1] on entering contact; each impact
        removes beta m v^2 with beta = (1 - e^2)/2 (MODEL.md eq 16).
    pin : Pin, optional
        With ``contact_friction_coefficient`` > 0, eq 15 is evaluated along the cycle.
    contact_friction_coefficient : float
        mu_c on the pin's contact arc.

    Raises
    ------
    SimulationError
        No periodic orbit was found within ``max_periods`` (e.g. a lossless
        system, which never settles, or a chaotic response).
    """
    damping_ratio, friction, restitution, pin, contact_friction_coefficient = unpack_losses(
        losses, damping_ratio, friction, restitution, pin, contact_friction_coefficient
    )
    p = _parameters(joint, force_amplitude, omega, damping_ratio, friction, restitution)
    _check_samples(samples_per_period)
    mu_c = _checks.non_negative("contact_friction_coefficient", contact_friction_coefficient)
    if max_periods < 1 or max_multiple < 1:
        raise ParameterError("max_periods and max_multiple must be >= 1")
    tol = _checks.positive("tolerance", tolerance)
    lossless = p[kn.P_DAMP] == 0.0 and p[kn.P_FF] == 0.0 and p[kn.P_E] == 1.0
    state = _initial_state(p, initial)
    history: list[FloatArray] = []
    done = 0
    chunk = 16
    multiple = 0
    while done < max_periods:
        n = min(chunk, max_periods - done)
        run = _run(p, state, n, p[kn.P_TF], record=False)
        history.append(run.strobe.copy())
        done += n
        strobe = np.concatenate(history[-4:]) if len(history) > 1 else history[-1]
        x_scale = max(float(np.ptp(strobe[:, 0])), joint.clearance, 1e-300)
        x_scale = max(x_scale, float(np.max(np.abs(strobe[:, 0]))))
        v_scale = max(float(np.max(np.abs(strobe[:, 1]))), x_scale * p[kn.P_W])
        multiple = _periodic_multiple(strobe, max_multiple, tol, x_scale, v_scale)
        if multiple:
            break
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
    return _orbit_from(p, joint, state, multiple, done, pin, mu_c, samples_per_period)


def _orbit_from(
    p: FloatArray,
    joint: Joint,
    state: FloatArray,
    multiple: int,
    periods_to_converge: int,
    pin: Pin | None,
    mu_c: float,
    samples_per_period: int,
) -> SteadyState:
    """The SteadyState of the orbit of ``multiple`` periods that starts at ``state`` (phase 0)."""
    start = state.copy()
    run = _run(p, state, multiple, p[kn.P_TF], record=True)
    duration = multiple * p[kn.P_TF]
    time = _sample_times(duration, p[kn.P_TF], samples_per_period, None)
    fields = _motion_fields(p, joint, run, start, time, pin, mu_c)
    x_max = float(fields["x_max"])  # type: ignore[arg-type]
    x_min = float(fields["x_min"])  # type: ignore[arg-type]
    return SteadyState(
        **fields,  # type: ignore[arg-type]
        period_multiple=multiple,
        period=duration,
        periods_to_converge=periods_to_converge,
        initial_state=(
            float(start[0]),
            float(start[1]),
            int(start[2]),
            int(start[3]),
        ),
        compression_penetration=max(x_max - joint.compression_gap, 0.0),
        tension_penetration=max(-joint.tension_gap - x_min, 0.0),
    )


def frequency_sweep(
    joint: Joint,
    force_amplitude: float,
    omegas: ArrayLike,
    *,
    direction: Literal["up", "down", "both"] = "both",
    damping_ratio: float = 0.0,
    friction: Friction | None = None,
    restitution: float = 1.0,
    max_periods: int = 20_000,
    keep_cycles: bool = False,
) -> FrequencySweep:
    """Return the stepped-sine amplitude-frequency curve, swept up and/or down.

    Each step starts from the previous step's steady state, so the jump and the
    hysteresis of the amplitude-frequency curve show up as they do on a shaker.
    ``omegas`` (rad/s) are sorted ascending; the down sweep visits them in reverse.
    A step with no steady state gives NaN rather than stopping the sweep.
    """
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
                ss = steady_state(
                    joint,
                    force_amplitude,
                    float(omega),
                    damping_ratio=damping_ratio,
                    friction=friction,
                    restitution=restitution,
                    initial=initial,
                    max_periods=max_periods,
                    samples_per_period=16,
                )
            except SimulationError:
                cycles.append(None)
                continue
            amps[i] = ss.amplitude
            mults[i] = ss.period_multiple
            initial = ss.initial_state
            cycles.append(ss if keep_cycles else None)
        return amps, mults, cycles

    nan = np.full(w.size, np.nan)
    zeros = np.zeros(w.size, dtype=np.int64)
    up, m_up, c_up = sweep(w) if direction in ("up", "both") else (nan, zeros, [])
    if direction in ("down", "both"):
        down_r, m_down_r, c_down_r = sweep(w[::-1])
        down, m_down, c_down = down_r[::-1], m_down_r[::-1], c_down_r[::-1]
    else:
        down, m_down, c_down = nan.copy(), zeros.copy(), []
    return FrequencySweep(w, up, down, m_up, m_down, tuple(c_up), tuple(c_down))
