"""The single joint's exact motion: the kernel set up, run, and turned into a Motion.

MODEL.md sec. 2: m x'' + c_v x' + f(x) + mu_s P sgn(x') = F0 sin(w t), with x' -> e x'
on entering contact. These are the building blocks that the public solvers
(:mod:`clearjoint.simulate` for time responses and steady states,
:mod:`clearjoint.periodic` for exact orbits and curves) share: the kernel's parameter
vector of a joint (:func:`parameters`), its start state (:func:`initial_state`), a run of
the compiled kernel (:func:`run_kernel`), its records sampled into the fields of a
:class:`~clearjoint.results.Motion` (:func:`motion_fields`) and the SteadyState of an
orbit (:func:`orbit_from`).

The contact-friction term of MODEL.md (mu_c on the pin's contact arc) is *evaluated
along the cycle without feedback on the motion*, as the paper does: it is reported in
the ledger but is not among the losses that balance the input.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.contact import contact_friction_power, hertz_contact
from clearjoint.errors import ParameterError, SimulationError
from clearjoint.exact import kernel as kn
from clearjoint.joint import Friction, Joint, Losses, Pin
from clearjoint.progress import report
from clearjoint.results.motion import EnergyLedger, Stage, SteadyState
from clearjoint.stiffness import viscous_coefficient
from clearjoint.system import as_joint

# the kernels as compiled at install where that is usable (clearjoint.compiled)
_region_of = prefer(kn.region_of)
_decide_slip = prefer(kn.decide_slip)
_advance = prefer(kn.advance)
_sample = prefer(kn.sample)

FloatArray = NDArray[np.float64]

STAGE_NAMES = {kn.FREE: "free-play", kn.COMPRESSION: "compression", kn.TENSION: "tension"}

#: Pieces of whole forcing periods a recorded transient is run in, each ending in a progress
#: report (clearjoint.progress): every period is the kernel's same arithmetic from the same
#: state, so the motion is the one run's to the bit (:func:`run_kernel_in_pieces`).
PROGRESS_PIECES = 100


def parameters(
    joint: Joint,
    force_amplitude: float,
    omega: float,
    damping_ratio: float,
    friction: Friction | None,
    restitution: float,
) -> FloatArray:
    """Return the kernel's parameter vector of ``joint`` forced at F0 sin(omega t) (MODEL.md 2)."""
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


def setup(
    joint: Any, force_amplitude: float, omega: float, losses: Losses | None
) -> tuple[Joint, Losses, FloatArray]:
    """Return the joint, its losses and the kernel's parameter vector of a solver's input.

    ``joint`` is a Joint (with ``losses``, None for none) or a one-DOF
    VibrationSystem (which carries its own): :func:`clearjoint.system.as_joint`.
    """
    joint, losses = as_joint(joint, losses)
    p = parameters(
        joint, force_amplitude, omega, losses.damping_ratio, losses.friction, losses.restitution
    )
    return joint, losses, p


def initial_state(p: FloatArray, initial: ArrayLike | None) -> FloatArray:
    """Return the kernel's state (x, v, region, slip) at ``initial`` = (x0, v0) (default rest)."""
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
    region = _region_of(p, x0, v0)
    state[kn.S_REGION] = region
    state[kn.S_SLIP] = (1 if v0 > 0 else -1) if v0 != 0.0 else _decide_slip(p, region, x0, 0.0)
    return state


@dataclass
class Run:
    """The records of one kernel run: segments, impacts, stroboscopic states, ledger, events."""

    segments: FloatArray
    impacts: FloatArray
    strobe: FloatArray
    ledger: FloatArray
    events: int


def run_kernel(
    p: FloatArray, state: FloatArray, n_periods: int, t_last: float, record: bool
) -> Run:
    """Run the compiled kernel over ``n_periods`` (the last one ``t_last`` s long) from ``state``.

    ``state`` is advanced in place; the records (segments and impacts when ``record``,
    the stroboscopic states and the per-period ledger) are returned.

    Raises
    ------
    SimulationError
        Chattering (too many events in a period) or a march that ran out of steps.
    """
    if n_periods < 1:
        raise ParameterError("the duration must cover a positive time")
    strobe = np.zeros((n_periods, 4))
    ledger = np.zeros((n_periods, kn.LEDGER_WIDTH))
    capacity = 64 * n_periods if record else 1
    while True:
        segments = np.zeros((capacity, kn.SEG_WIDTH))
        impacts = np.zeros((capacity, kn.IMP_WIDTH))
        start = state.copy()
        n_seg, n_imp, events, status = _advance(
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
        return Run(segments[:n_seg], impacts[:n_imp], strobe, ledger, events)


def run_kernel_in_pieces(p: FloatArray, state: FloatArray, n_periods: int, t_last: float) -> Run:
    """:func:`run_kernel` with ``record``, in up to :data:`PROGRESS_PIECES` runs of whole periods.

    After each piece the seconds of motion done (of ``(n_periods - 1) T + t_last``) are
    reported (:func:`clearjoint.progress.report`). A period always starts at forcing phase 0
    from the state the last one ended in, and its records are numbered from the run's first
    period, so the records are those of one run to the bit (tests/test_simulate_progress.py).
    """
    pieces = max(1, min(PROGRESS_PIECES, n_periods))
    if pieces == 1:
        return run_kernel(p, state, n_periods, t_last, record=True)
    tf = p[kn.P_TF]
    total = (n_periods - 1) * tf + t_last
    runs: list[Run] = []
    first = 0
    for piece in range(pieces):
        last = n_periods * (piece + 1) // pieces  # periods [first, last) in this piece
        run = run_kernel(p, state, last - first, t_last if last == n_periods else tf, True)
        run.segments[:, kn.SEG_PERIOD] += first
        run.impacts[:, 0] += first
        runs.append(run)
        first = last
        report(min(last * tf, total), total)
    return Run(
        np.concatenate([run.segments for run in runs]),
        np.concatenate([run.impacts for run in runs]),
        np.concatenate([run.strobe for run in runs]),
        np.concatenate([run.ledger for run in runs]),
        sum(run.events for run in runs),
    )


def _mechanical_energy(joint: Joint, x: float, v: float) -> float:
    return 0.5 * joint.mass * v * v + float(joint.potential_energy(x))


def _contact_friction(
    p: FloatArray,
    joint: Joint,
    run: Run,
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
        _sample(p, row[None, :], 1, times, out)
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


def motion_fields(
    p: FloatArray,
    joint: Joint,
    run: Run,
    start_state: FloatArray,
    time: FloatArray,
    pin: Pin | None,
    contact_friction_coefficient: float,
) -> dict[str, object]:
    """Return the fields of a Motion sampled at ``time`` from a recorded run (MODEL.md sec. 2)."""
    tf = p[kn.P_TF]
    out = np.zeros((time.size, 3))
    _sample(p, run.segments, run.segments.shape[0], time, out)
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


def sample_times(
    duration: float, period: float, samples_per_period: int, sampling_rate: float | None
) -> FloatArray:
    """Uniform sample times over [0, duration): per forcing period, or at a rate in Hz."""
    if sampling_rate is not None:
        rate = _checks.positive("sampling_rate", sampling_rate, unit="Hz")
        n = max(math.floor(duration * rate * (1.0 + 1e-12)), 2)
        return np.arange(n) / rate
    check_samples(samples_per_period)
    n = max(round(samples_per_period * duration / period), 2)
    if duration >= period:
        return np.linspace(0.0, duration, n + 1)[:-1]
    return np.linspace(0.0, duration, n)


def check_samples(samples_per_period: int) -> None:
    """Refuse a samples_per_period that is not an integer >= 8."""
    if (
        isinstance(samples_per_period, bool)
        or not isinstance(samples_per_period, int)
        or (samples_per_period < 8)
    ):
        raise ParameterError(
            f"samples_per_period must be an integer >= 8, got {samples_per_period!r}"
        )


def orbit_from(
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
    run = run_kernel(p, state, multiple, p[kn.P_TF], record=True)
    duration = multiple * p[kn.P_TF]
    time = sample_times(duration, p[kn.P_TF], samples_per_period, None)
    fields = motion_fields(p, joint, run, start, time, pin, mu_c)
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
