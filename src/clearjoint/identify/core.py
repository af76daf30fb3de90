"""Identify one record: cycles, model choice, the fit, standard errors and flags.

MODEL.md section 3. The steps:

1. the excitation frequency (the displacement spectrum's peak, interpolated);
2. the cycles, cut at the minima of the fundamental, and the steady ones by the one
   rule of :func:`clearjoint.identify.cycles.steady_rule`;
3. the steady cycles stacked on one phase grid and averaged: the average is the latent
   periodic signal, with 1/sqrt(n) of one cycle's noise in every channel;
4. the model, chosen on that average (so on all the steady cycles): a friction damper
   with backlash when a displacement-controlled loop's branches end on slip plateaus;
   else a clearance joint (steep, flat, steep stages, found on both branches or lent by
   one to the other, better than a straight line by BIC); else a straight line;
5. the joint's parameters by the weak form (:mod:`clearjoint.identify.weak`: no
   derivative of the displacement, test functions that stop at the contact instants)
   without an acceleration channel, when the cycles were stacked by interpolation (a
   period that is not a whole number of samples), or when the average's displacement
   noise exceeds ``SAMPLE_FIT_NOISE`` of the amplitude; else (an acceleration on a
   whole-sample stack of a quiet average), or when a contact lasts too few samples for
   test functions, by robust least squares over the average's samples (the velocity's
   sign and drag from its spectral derivative); the damper's and the line's by their
   per-sample fits;
6. a jackknife over the cycles (the average without each of at most eight contiguous
   groups of cycles in turn, all replicates fitted in one batched solve, each with the
   sign of its own velocity for the friction term) for every standard error; the energy
   per cycle is each cycle's own loop area (the closed integral of F dx, in which the
   inertia term cancels);
7. a flag per quantity: ``rejected`` for a clearance whose two-standard-error interval
   spans zero, ``doubtful`` for a stiffness, friction or energy whose standard error
   exceeds a quarter of it, a fit residual above three times its noise floor (the weak
   form's equation residual; the damper model's residual on the loop and the joint's or
   the line's per-sample fit's; the floor errors-in-variables, per sample: the force's
   noise, the displacement's times the model's slope and the velocity sign's flips,
   :mod:`clearjoint.identify.loopcheck`), a fit whose velocity sign is a toss-up on more
   than ``UNSURE_SHARE`` of its samples, a force-controlled
   record without a mass (then estimated from the record, with a warning), or a damper
   whose backlash reads more than twice as long on one branch as on the other.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from clearjoint import stiffness
from clearjoint.errors import ClearjointError
from clearjoint.identify._stats import median
from clearjoint.identify.cycles import (
    MIN_STEADY,
    IdentificationError,
    Stack,
    cycle_bounds,
    excitation_frequency,
    stack,
    steady,
    steady_rule,
)
from clearjoint.identify.damper import BRANCH_RATIO, _damper_fit
from clearjoint.identify.loopcheck import (
    NO_STAGE,
    UNSURE_SIGN,
    Reading,
    channel_noise,
    damper_residual,
    jackknife_noise,
    sample_fit_residual,
    scatter,
    weak_residual,
)
from clearjoint.identify.result import QUANTITIES, CycleResult, Identification, damper_stages
from clearjoint.identify.segments import (
    STAGE_COMPRESSION,
    STAGE_FREE,
    STAGE_TENSION,
    Window,
    _Fit,
    _is_joint,
    _joint_fit,
    _joint_fits,
    _line_fit,
    _line_fits,
    _windows,
)
from clearjoint.records import Record, import_readers, mass_advice

FloatArray = NDArray[np.float64]

#: The force's noise in the floor is at least this part of its standard deviation (the
#: resolution of a record's digits and ADC): a noise-free record is not held to zero residual.
RESOLUTION = 1e-3
#: A fit whose velocity sign is unsure (a flip by the noise more likely than
#: ``loopcheck.UNSURE_SIGN``) on more than this share of its samples rests on noise: the
#: independent simulator's 40 Hz joint at 1 % noise and 6-24 cycles shows 0.14-0.50, the
#: Bouc-Wen loop read as a line or a joint at 1 % noise 0.68-0.91 (docs/identify.md, Flags).
UNSURE_SHARE = 0.6
#: A fit residual this many times its noise floor (errors-in-variables, per sample:
#: :mod:`clearjoint.identify.loopcheck`) on the cycle average makes a value doubtful.
RESIDUAL_FACTOR = 3.0
#: Samples this close to a gap edge (a fraction of the clearance) belong to no stage's
#: test functions: the contact instants are where the stages' laws switch.
EDGE_MARGIN = 0.05
#: The sample-by-sample fit of a joint needs a cycle average whose displacement noise
#: (scatter over the cycles / sqrt(n)) is below this part of the amplitude; noisier, the
#: weak form (the rig's records: 1.5e-4..4.1e-4; the independent simulator's at 1 % noise
#: and 24 cycles: 1.5e-3, at 6 cycles 3.2e-3).
SAMPLE_FIT_NOISE = 1e-3
#: Equations each stage needs for the weak form (else the stages are fitted sample by
#: sample on the cycle average, as when a contact lasts only a few samples).
MIN_EQUATIONS = 4
#: A value whose standard error exceeds this part of it is doubtful (for these quantities).
RELATIVE_ERROR = 0.25
CREDIBLE = (
    "compression_stiffness_n_per_m",
    "tension_stiffness_n_per_m",
    "friction_force_n",
    "energy_per_cycle_j",
)
#: Groups of the jackknife (contiguous blocks of cycles; one cycle each up to this many).
JACKKNIFE_GROUPS = 8
#: Quantities taken per cycle (the cycle's own), not from the fit.
PER_CYCLE = ("amplitude_m", "energy_per_cycle_j", "secant_stiffness_n_per_m")


def restoring_force(
    record: Record, acceleration: FloatArray, mass: float | None = None
) -> FloatArray:
    """Force minus m x'' (force control, MODEL.md sec. 3) or the measured force."""
    m = record.mass if mass is None else mass
    if record.control == "displacement" or not m:
        return record.force
    return record.force - m * acceleration


def _harmonic_cut(x: FloatArray, noise: float) -> NDArray[np.int64]:
    """The last harmonic of each row of ``x`` (M,) or (R, M) whose amplitude exceeds three
    times that of the noise (``noise``: rms per sample), at least the first, (R,)."""
    rows = np.atleast_2d(x)
    spectrum = np.abs(np.fft.rfft(rows, axis=1))
    above = spectrum > 3.0 * noise * math.sqrt(rows.shape[1] / 2.0)
    last = spectrum.shape[1] - 1 - np.argmax(above[:, ::-1], axis=1)
    out: NDArray[np.int64] = np.where(above.any(axis=1), last, 1)
    return out


def _periodic_derivatives(
    x: FloatArray, step: float, noise: float = 0.0, cut: int | None = None
) -> tuple[FloatArray, FloatArray]:
    """Velocity and acceleration of periodic cycles, spectrally, harmonics above the noise.

    ``x`` is one cycle (M,) or one cycle per row (R, M), each row treated on its own
    (in one batched FFT). The harmonics kept are those up to the last one whose
    amplitude exceeds three times the noise's (``noise``: the rms noise per sample of
    ``x``). Used only to place the stages, choose the model and take the sign of the
    velocity; the joint's parameters never use them (the weak form needs no derivative).
    ``cut``, when given, is the last harmonic kept in every row (the jackknife's
    replicates keep the average's, so their velocities are one linear filter of the data).
    """
    rows = np.atleast_2d(x)
    m = rows.shape[1]
    spectrum = np.fft.rfft(rows, axis=1)
    k = np.arange(spectrum.shape[1])
    last = _harmonic_cut(rows, noise) if cut is None else np.full(rows.shape[0], cut)
    spectrum[k[None, :] > last[:, None]] = 0.0
    w = 2.0 * math.pi * k / (m * step)
    v = np.fft.irfft(1j * w * spectrum, n=m, axis=1)
    a = np.fft.irfft(-(w**2) * spectrum, n=m, axis=1)
    if x.ndim == 1:
        return v[0], a[0]
    return v, a


def _estimate_mass(x: FloatArray, f: FloatArray, v: FloatArray, a: FloatArray) -> float:
    """The moving mass from F = m x'' + g(x) + c x' + F_f sgn x', g piecewise linear (hinges)."""
    knots = np.linspace(x.min(), x.max(), 18)[1:-1]
    design = np.column_stack(
        (a, np.ones_like(x), x, np.maximum(x[:, None] - knots[None, :], 0.0), v, np.sign(v))
    )
    coef = np.linalg.lstsq(design, f, rcond=None)[0]
    return float(coef[0])


def _derived(x: FloatArray, fit: _Fit, mass: float | None) -> dict[str, float]:
    """The quantities of one fit on one cycle average ``x`` (M,)."""
    x_max, x_min = float(x.max()), float(x.min())
    clearance = fit.upper_edge - fit.lower_edge
    a_c, a_t = x_max - fit.upper_edge, fit.lower_edge - x_min
    return {
        "amplitude_m": 0.5 * (x_max - x_min),
        "clearance_m": clearance,
        "compression_stiffness_n_per_m": fit.k_compression,
        "tension_stiffness_n_per_m": fit.k_tension,
        "friction_force_n": fit.friction,
        "compression_penetration_m": a_c,
        "tension_penetration_m": a_t,
        "gap_stiffness_n_per_m": fit.k_gap,
        "dynamic_stiffness_n_per_m": _dynamic(fit, clearance, a_c, mass),
        "mass_kg": math.nan if mass is None else mass,
    }


class _Spring(NamedTuple):
    """A joint's values as :class:`Joint` would store them, for ``stiffness._period``."""

    mass: float
    gap_stiffness: float
    compression_stiffness: float
    tension_stiffness: float
    compression_gap: float
    tension_gap: float


def _finite(value: float, low: float, strict: bool) -> float | None:
    """``float(value)`` when finite and above ``low`` (or at it, not ``strict``), else None."""
    v = float(value)
    return v if math.isfinite(v) and (v > low or (not strict and v == low)) else None


def _dynamic(fit: _Fit, clearance: float, a_c: float, mass: float | None) -> float:
    """k_d of the fitted joint at penetration ``a_c`` (MODEL.md eq 8), NaN where undefined.

    The values :class:`Joint` and ``dynamic_stiffness`` would give, through the same
    kernel (``stiffness._period``) and the same checks (a value that ``Joint`` would refuse
    gives NaN), without building a validated ``Joint`` for every jackknife replicate.
    """
    k0 = fit.k_gap
    if not mass or not (fit.k_compression > k0 and fit.k_tension > k0 and a_c > 0):
        return math.nan
    m = _finite(mass, 0.0, True)
    c = _finite(max(clearance, 0.0), 0.0, False)
    k_c = _finite(fit.k_compression - k0, 0.0, True)
    k_t = _finite(fit.k_tension - k0, 0.0, True)
    g = _finite(k0, 0.0, False)
    if m is None or c is None or k_c is None or k_t is None or g is None:
        return math.nan
    if not math.isfinite(a_c):
        return math.nan
    spring = _Spring(m, g, k_c, k_t, 0.5 * c + 0.0, 0.5 * c - 0.0)
    omega_n = (2.0 * math.pi) / stiffness._period(spring, np.asarray(a_c, dtype=np.float64))
    return float(m * omega_n * omega_n)


def _groups(n: int) -> list[NDArray[np.int64]]:
    """The jackknife's groups of cycles: contiguous blocks, at most JACKKNIFE_GROUPS."""
    return [
        np.asarray(g, dtype=np.int64)
        for g in np.array_split(np.arange(n), min(n, JACKKNIFE_GROUPS))
    ]


def _leave_one_out(values: FloatArray, groups: list[NDArray[np.int64]]) -> FloatArray:
    """The averages of the (n, M) rows without each group in turn, (G, M).

    The groups are contiguous (:func:`_groups`): each is summed as a slice of the rows
    (the same additions in the same order as over a copy of them, without the copy).
    """
    n = values.shape[0]
    total = values.sum(axis=0)
    out: FloatArray = np.array(
        [(total - values[g[0] : g[-1] + 1].sum(axis=0)) / (n - g.size) for g in groups]
    )
    return out


def _loop_areas(x: FloatArray, f: FloatArray) -> FloatArray:
    """Each row's closed loop area, the integral of F dx round the cycle (trapezoids), (n,)."""
    dx = np.roll(x, -1, axis=1) - x
    out: FloatArray = np.abs(np.sum(0.5 * (f + np.roll(f, -1, axis=1)) * dx, axis=1))
    return out


def _secants(x: FloatArray, f: FloatArray) -> FloatArray:
    """(F at x_max - F at x_min) / (x_max - x_min) of each row, F averaged over 5 samples."""
    n, m = x.shape
    rows = np.arange(n)
    out = np.empty(n)
    for name, sign in (("top", 1), ("bottom", -1)):
        i = np.argmax(sign * x, axis=1)
        near = (i[:, None] + np.arange(-2, 3)[None, :]) % m
        value = f[rows[:, None], near].mean(axis=1)
        if name == "top":
            top = value
        else:
            out = (top - value) / np.ptp(x, axis=1)
    return out


def _branches_of(m: int, x: FloatArray) -> tuple[slice, slice] | None:
    top = int(np.argmax(x))
    if top < 8 or m - top < 8:
        return None
    return slice(0, top + 1), slice(top, m)


def _window_stages(
    x: FloatArray, parts: tuple[slice, slice], windows: tuple[list[Window], list[Window]]
) -> NDArray[np.int8]:
    """The stage of each sample of the average as the joint's per-sample fit had it: the
    stage of the window of its branch it lies in, ``NO_STAGE`` in none, (M,)."""
    stage = np.full(x.size, NO_STAGE, dtype=np.int8)
    for part, branch in zip(parts, windows, strict=True):
        xb = x[part]
        own = np.full(xb.size, NO_STAGE, dtype=np.int8)
        for code, (_, low, high) in zip(
            (STAGE_TENSION, STAGE_FREE, STAGE_COMPRESSION), branch, strict=True
        ):
            own[(xb >= low) & (xb <= high)] = code
        stage[part] = np.where(own != NO_STAGE, own, stage[part])
    return stage


def identify(record: Record, *, tolerance: float = 0.03) -> Identification:
    """Return the identification of one record (see the module's docstring for the steps).

    Parameters
    ----------
    record : Record
        The test record (SI).
    tolerance : float
        Relative tolerance of the steady-cycle rule
        (:func:`~clearjoint.identify.cycles.steady_rule`).

    Returns
    -------
    Identification

    Raises
    ------
    IdentificationError
        Fewer than three steady cycles (the message states the rule), or a frequency far
        from the record's nominal one.
    """
    where = record.source or "record"
    x_all = record.displacement
    frequency = excitation_frequency(record)
    if record.frequency_hz and abs(frequency / record.frequency_hz - 1.0) > 0.05:
        raise IdentificationError(
            f"{where}: the displacement's frequency is {frequency:.4g} Hz, not the nominal "
            f"{record.frequency_hz:g} Hz; check the record"
        )
    bounds = cycle_bounds(record, frequency)
    kept = steady(x_all, bounds, tolerance)
    if len(kept) < MIN_STEADY:
        raise IdentificationError(
            f"{where}: {len(kept)} steady cycles of {len(bounds)}; {steady_rule(tolerance)} "
            "(a larger --tolerance admits more)"
        )
    channels = {"x": x_all, "f": record.force}
    if record.acceleration is not None:
        channels["a"] = record.acceleration
    if record.velocity is not None:
        channels["v"] = record.velocity
    st = stack(record, frequency, bounds, kept, {"x": x_all})
    # start every cycle at the minimum of the average (rising branch first), in time order
    shift = int(np.argmin(st.channels["x"].mean(axis=0)))
    if shift > st.samples // 2 and bounds[kept[0]][0] - (st.samples - shift) >= 0:
        shift -= st.samples
    st = stack(record, frequency, bounds, kept, channels, shift)
    if st.cycles < MIN_STEADY:
        raise IdentificationError(
            f"{where}: {st.cycles} steady cycles lie wholly inside the record; "
            f"{steady_rule(tolerance)}"
        )
    return _identify_stack(record, where, frequency, len(bounds), st)


def _identify_stack(
    record: Record, where: str, frequency: float, total: int, st: Stack
) -> Identification:
    n, m = st.cycles, st.samples
    xs, fs = st.channels["x"], st.channels["f"]
    x = xs.mean(axis=0)
    f = fs.mean(axis=0)
    noise_x = scatter(xs)
    warnings: list[str] = []
    force_control = record.control == "force"
    # the average's acceleration is used only under force control: with a measured
    # velocity and no acceleration needed (a displacement-controlled BRFD record) the
    # spectral derivatives are not taken; a is then the measured one or unused zeros
    measured = "v" in st.channels and ("a" in st.channels or not force_control)
    if measured:
        v = st.channels["v"].mean(axis=0)
        a = st.channels["a"].mean(axis=0) if "a" in st.channels else np.zeros_like(x)
    else:
        v_crude, a_crude = _periodic_derivatives(x, st.step, noise_x)
        v = st.channels["v"].mean(axis=0) if "v" in st.channels else v_crude
        a = st.channels["a"].mean(axis=0) if "a" in st.channels else a_crude
    mass: float | None = record.mass if force_control and record.mass else None
    mass_missing = force_control and mass is None
    m_guess = _estimate_mass(x, f, v, a) if mass_missing else (mass or 0.0)
    r = f - m_guess * a if force_control else f
    # the floor's channels: the restoring force (with a measured acceleration its noise
    # times m is the force's too) and the displacement, each cycle's scatter
    rs = fs - m_guess * st.channels["a"] if force_control and "a" in st.channels else fs
    parts = _branches_of(m, x)
    if parts is None:
        raise IdentificationError(f"{where}: the steady cycles' average has no rising branch")
    model = "line"
    system = None
    # a displacement-controlled loop whose branches end on slip plateaus is a damper
    head_damper = _damper_fit(x, f, parts) if record.control == "displacement" else None
    damper = head_damper is not None
    first_fit = None
    if not damper:  # the stages are looked for only where a joint may be
        windows = (
            _windows(x[parts[0]], r[parts[0]], 3),
            _windows(x[parts[1]], r[parts[1]], 3),
        )
        if _is_joint(windows[0]) != _is_joint(windows[1]):
            # a stage too short to be found on one branch (e.g. a brief contact at a low
            # force): the stages are places in x, the same on both branches, so the branch
            # that shows all three lends them to the other
            shown = windows[0] if _is_joint(windows[0]) else windows[1]
            windows = (shown, shown)
        if _is_joint(windows[0]) and _is_joint(windows[1]):
            first_fit = _joint_fit(x, r, v, parts, windows)
    if damper:
        model = "damper"
    elif first_fit is not None:
        edges = (first_fit.lower_edge, first_fit.upper_edge)
        margin = EDGE_MARGIN * (edges[1] - edges[0])
        model = "joint"
        # the weak form without a measured acceleration, when the cycles were stacked by
        # interpolation (a period that is not a whole number of samples: averaging cycles
        # sampled at different phases smooths the contact corners and the friction
        # reversals by about a sample, which biases a sample-by-sample fit, friction 5-20 %
        # low; the weak form uses only integrals of x, F and a against test functions that
        # stop before the contact instants), or when the cycle average is too noisy for
        # the sample fit (its velocity's sign follows the noise near the reversals: an
        # errors-in-variables bias of the friction, 10-50 % low with 6-16 cycles at 1 %
        # noise, not covered by its standard error; docs/identify.md, measured by
        # docs/identify_bias.py --cycles)
        noisy = noise_x > SAMPLE_FIT_NOISE * 0.5 * float(np.ptp(x))
        if "a" not in st.channels or not st.exact or noisy:
            # imported here: a damper or a line (the BRFD folder) never needs the weak form
            from clearjoint.identify.weak import stage_runs, weak_system

            system = weak_system(x, v, st.step, stage_runs(x, edges, margin))
        if system is not None and np.bincount(system.stage).min() < MIN_EQUATIONS:
            system = None  # a contact too short for the weak form: fit sample by sample

    # every replicate: row 0 the average of all cycles, then the averages without one
    groups = _groups(n)
    reps_x = np.vstack((x[None, :], _leave_one_out(xs, groups)))
    reps_f = np.vstack((f[None, :], _leave_one_out(fs, groups)))
    reps_a = (
        np.vstack(
            (st.channels["a"].mean(axis=0)[None, :], _leave_one_out(st.channels["a"], groups))
        )
        if "a" in st.channels
        else None
    )
    # and the noise of the velocity whose sign the friction term takes: a measured one's
    # scatter, a derived one's jackknife over the replicates' spectral velocities (taken
    # below where the fit needs them; the damper's residual takes no sign)
    noise = channel_noise(
        rs, noise_x, RESOLUTION, scatter(st.channels["v"]) if "v" in st.channels else math.nan
    )
    derived_v = "v" not in st.channels
    fits: list[_Fit]
    masses: FloatArray
    residual = Reading(math.nan, math.nan, math.nan)
    if model == "joint" and system is not None:
        from clearjoint.identify.weak import weak_fit

        # each replicate's friction term follows its own velocity's sign (the sign's flips
        # by the noise are then in the jackknife's spread: the friction's standard error);
        # replicate 0, the average itself, keeps the velocity the system was built with
        if derived_v:
            cut = int(_harmonic_cut(x, noise_x)[0])
            spectral = _periodic_derivatives(reps_x, st.step, noise_x, cut)[0]
            own_v = np.vstack((v[None, :], spectral[1:]))
        else:
            own_v = np.vstack((v[None, :], _leave_one_out(st.channels["v"], groups)))
        weak = weak_fit(
            system,
            reps_x,
            reps_f,
            mass=mass if force_control else 0.0,
            acceleration=reps_a,
            velocity=own_v,
        )
        fits = []
        for (lt, lf, lc), c_f in zip(weak.lines, weak.friction, strict=True):
            (a_t, k_t), (a_f, k_f), (a_c, k_c) = lt, lf, lc
            upper = (a_f - a_c) / (k_c - k_f) if k_c != k_f else math.nan
            lower = (a_f - a_t) / (k_t - k_f) if k_t != k_f else math.nan
            lines = ((float(a_t), float(k_t)), (float(a_f), float(k_f)), (float(a_c), float(k_c)))
            fits.append(
                _Fit(
                    upper,
                    lower,
                    float(k_c),
                    float(k_t),
                    max(float(k_f), 0.0),
                    abs(float(c_f)),
                    lines,
                )
            )
        masses = weak.mass
        if derived_v:  # the floor's sign noise: each replicate's velocity with its own cut
            crude = _periodic_derivatives(reps_x, st.step, noise_x)[0]
            noise = replace(noise, velocity=jackknife_noise(crude))
        residual = weak_residual(
            system, weak, v, noise, inertia_from_x=force_control and reps_a is None
        )
    else:
        # every replicate's velocity and restoring force, (G + 1, M), then the fits of all
        # replicates in one batched solve (row by row only if that solve is singular)
        if measured:  # as for the average: no spectral derivative is used
            reps_ad = reps_a if reps_a is not None else np.zeros_like(reps_x)
            reps_v = np.broadcast_to(v, reps_x.shape)
        else:
            reps_v, reps_ad = _periodic_derivatives(reps_x, st.step, noise_x)
            if derived_v:
                noise = replace(noise, velocity=jackknife_noise(reps_v))
            if reps_a is not None:
                reps_ad = reps_a
            if "v" in st.channels:
                reps_v = np.broadcast_to(v, reps_x.shape)
        masses = np.full(len(groups) + 1, m_guess if force_control else math.nan)
        if mass_missing:  # each replicate's own estimate, as the weak form's: a fitted mass
            # has a standard error (the jackknife's), and its doubt reaches every replicate
            for i in range(1, len(groups) + 1):
                masses[i] = _estimate_mass(reps_x[i], reps_f[i], reps_v[i], reps_ad[i])
        reps_r = reps_f - masses[:, None] * reps_ad if force_control else reps_f
        fits = []
        if model == "joint":
            assert first_fit is not None
            batch = _joint_fits(reps_x, reps_r, reps_v, parts, windows)
            if batch is None:
                batch = [
                    _joint_fit(xr_, rr_, vr_, parts, windows, compete=False)
                    for xr_, rr_, vr_ in zip(reps_x, reps_r, reps_v, strict=True)
                ]
            fits = [fit or first_fit for fit in batch]
            residual = sample_fit_residual(
                reps_x[0], reps_r[0], reps_v[0], fits[0], noise, _window_stages(x, parts, windows)
            )
        elif model == "damper":
            assert head_damper is not None
            residual = damper_residual(x, f, parts, head_damper, noise)
            fits.append(head_damper)  # replicate 0 is the average itself: fitted above
            for xr_, fr_, rr_, vr_ in zip(
                reps_x[1:], reps_f[1:], reps_r[1:], reps_v[1:], strict=True
            ):
                fits.append(_damper_fit(xr_, fr_, parts) or _line_fit(xr_, rr_, vr_))
        else:
            line_fits = _line_fits(reps_x, reps_r, reps_v)
            fits = (
                line_fits
                if line_fits is not None
                else [
                    _line_fit(xr_, rr_, vr_)
                    for xr_, rr_, vr_ in zip(reps_x, reps_r, reps_v, strict=True)
                ]
            )
            residual = sample_fit_residual(reps_x[0], reps_r[0], reps_v[0], fits[0], noise)
    values = [
        _derived(reps_x[i], fits[i], float(masses[i]) if force_control else None)
        for i in range(len(groups) + 1)
    ]
    for vals, fit in zip(values, fits, strict=True):
        symmetric = math.isnan(fit.level_positive)
        vals["friction_force_positive_n"] = fit.friction if symmetric else fit.level_positive
        vals["friction_force_negative_n"] = -fit.friction if symmetric else fit.level_negative
    full, loo = values[0], values[1:]
    summary: dict[str, float] = {}
    spread: dict[str, float] = {}
    stderr: dict[str, float] = {}
    per_cycle: dict[str, FloatArray] = {}
    own = {
        "amplitude_m": 0.5 * np.ptp(xs, axis=1),
        "energy_per_cycle_j": _loop_areas(xs, fs),
        "secant_stiffness_n_per_m": _secants(
            xs, fs - (m_guess * st.channels["a"] if force_control and "a" in st.channels else 0.0)
        ),
    }
    g = len(groups)
    member = np.empty(n, dtype=np.int64)
    for k, group in enumerate(groups):
        member[group] = k
    for q in QUANTITIES:
        if q in own:
            cyc = own[q]
            est = float(np.mean(cyc))
            finite = np.isfinite(cyc)
            se = float(np.std(cyc[finite], ddof=1)) / math.sqrt(n) if finite.sum() > 1 else math.nan
        else:
            est = full.get(q, math.nan)
            pseudo = g * est - (g - 1) * np.array([vv.get(q, math.nan) for vv in loo])
            cyc = pseudo[member]
            finite = np.isfinite(pseudo)
            se = (
                float(np.std(pseudo[finite], ddof=1)) / math.sqrt(g)
                if finite.sum() > 1
                else math.nan
            )
        per_cycle[q] = cyc
        summary[q] = est if q != "amplitude_m" else 0.5 * float(np.ptp(x))
        stderr[q] = se
        spread[q] = se * math.sqrt(n)
    if model == "line":
        for q in ("clearance_m",):
            summary[q], spread[q], stderr[q] = 0.0, 0.0, 0.0
            per_cycle[q] = np.zeros(n)
    flags = _flags(
        model,
        summary,
        stderr,
        residual,
        mass_missing,
        summary["mass_kg"],
    )
    if model == "joint" and system is None and not st.exact:
        reason = (
            f"{_rate_note(record, frequency)}: the cycles were stacked by interpolation and a "
            "contact is too short for the weak form, so the fit is sample by sample on a "
            "stack smoothed by about a sample (friction may read low)"
        )
        for q in (*CREDIBLE, "clearance_m"):
            _doubt(flags, q, reason)  # beside the residual's doubt, which it often explains
    if model == "damper":
        b_rise, b_fall = fits[0].backlash_branches
        low, high = min(b_rise, b_fall), max(b_rise, b_fall)
        apart = high > BRANCH_RATIO * low  # False when a reading is missing (NaN)
        if apart:
            _doubt(
                flags,
                "clearance_m",
                f"backlash {b_rise * 1e3:.3g} mm on the rising branch and {b_fall * 1e3:.3g} mm "
                f"on the falling one (more than {BRANCH_RATIO:g} times apart): not one gap "
                "crossed both ways",
            )
    if mass_missing:
        warnings.append(
            f"{where}: force-controlled record without a mass: the mass was estimated from the "
            f"record as {summary['mass_kg']:.4g} kg; to use the known one, "
            f"{mass_advice(record.source)}"
        )
    head = fits[0]
    # each quantity's per-cycle values as Python floats at once (the same doubles as
    # float() of each element, without a numpy scalar per value)
    columns = {q: np.asarray(per_cycle[q], dtype=np.float64).tolist() for q in QUANTITIES}
    cycles = tuple(
        CycleResult(
            int(st.starts[j]),
            int(st.starts[j]) + m,
            {q: columns[q][j] for q in QUANTITIES},
            head.upper_edge,
            head.lower_edge,
            model,
            head.lines,
        )
        for j in range(n)
    )
    force_all = restoring_force(record, _record_acceleration(record, frequency), m_guess)
    stage = np.zeros(record.time.size, dtype=np.int8)
    if model == "damper":  # it plays free after each reversal: staged by its force
        stage = damper_stages(force_all, summary["friction_force_n"])
    elif model != "line":
        stage[record.displacement >= head.upper_edge] = STAGE_COMPRESSION
        stage[record.displacement <= head.lower_edge] = STAGE_TENSION
    return Identification(
        source=where,
        frequency_hz=frequency,
        cycles_total=total,
        cycles=cycles,
        summary=summary,
        spread=spread,
        control=record.control,
        restoring_force=force_all,
        stage=stage,
        stderr=stderr,
        flags=flags,
        warnings=tuple(warnings),
        joint_id=record.joint_id,
        loop=(x, r),
    )


def _rate_note(record: Record, frequency: float) -> str:
    """The sampling rate and the samples a period, in words (for a flag's reason)."""
    return (
        f"{record.sampling_rate:g} Hz sampling is {record.sampling_rate / frequency:.2f} "
        f"samples a period"
    )


def _record_acceleration(record: Record, frequency: float) -> FloatArray:
    """The record's acceleration for the figures only: measured, or the second difference of
    the displacement smoothed over a fortieth of a period (a moving average)."""
    if record.acceleration is not None or record.control == "displacement":
        return (
            record.acceleration if record.acceleration is not None else np.zeros_like(record.time)
        )
    window = max(1, int(record.sampling_rate / frequency / 40))
    kernel = np.ones(window) / window
    smooth = np.convolve(record.displacement, kernel, mode="same")
    step = 1.0 / record.sampling_rate
    out: FloatArray = np.gradient(np.gradient(smooth, step), step)
    return out


def _flags(
    model: str,
    summary: dict[str, float],
    stderr: dict[str, float],
    residual: Reading,
    mass_missing: bool,
    mass: float,
) -> dict[str, tuple[str, str]]:
    """A flag and its reason for each quantity (see the module's docstring)."""
    flags = {q: ("ok", "") for q in QUANTITIES}
    fitted = [q for q in QUANTITIES if q not in PER_CYCLE]
    if model != "line":
        c, se = summary["clearance_m"], stderr["clearance_m"]
        if not (c - 2.0 * se > 0.0):
            flags["clearance_m"] = (
                "rejected",
                f"clearance {c * 1e3:.3g} ± {se * 1e3:.2g} mm: its interval spans zero",
            )
    for q in CREDIBLE:
        value, se = summary[q], stderr[q]
        if flags[q][0] == "ok" and value and abs(se / value) > RELATIVE_ERROR:
            flags[q] = (
                "doubtful",
                f"{q} has a standard error of {abs(se / value):.0%} of its value",
            )
    if math.isfinite(residual.ratio) and residual.ratio > RESIDUAL_FACTOR:
        reason = (
            f"fit residual {residual.residual:.3g} N is {residual.ratio:.1f} times the noise "
            f"floor {residual.floor:.3g} N of the cycle average (its force, displacement and "
            "velocity-sign noise)"
        )
        if residual.note:
            reason += f" ({residual.note})"
        for q in fitted:  # beside any other doubt: a model that misses the loop says why
            _doubt(flags, q, reason)
    if residual.unsure > UNSURE_SHARE:
        reason = (
            f"the velocity's sign is flipped by its noise with a chance above "
            f"{UNSURE_SIGN:.0%} on {residual.unsure:.0%} of the samples: the friction term, "
            "and the fit residual's floor, rest on noise"
        )
        for q in fitted:
            _doubt(flags, q, reason)
    if mass_missing:
        reason = f"force control without a mass: m = {mass:.4g} kg estimated from the record"
        for q in fitted:  # the issue's own rule: shown beside any other doubt
            _doubt(flags, q, reason)
    return flags


def _doubt(flags: dict[str, tuple[str, str]], quantity: str, reason: str) -> None:
    """Flag ``quantity`` doubtful for ``reason``; a doubt already there keeps its reason and
    gets this one beside it (every doubt is shown); a rejection stays as it is."""
    flag, was = flags[quantity]
    if flag == "ok":
        flags[quantity] = ("doubtful", reason)
    elif flag == "doubtful":
        flags[quantity] = ("doubtful", f"{was}; {reason}")


def flag_outliers(results: list[Identification]) -> list[Identification]:
    """Flag, per device (joint_id), a clearance more than twice the median of the others'.

    Needs at least three tests of the device; the others are the tests of the same
    ``joint_id`` in the same call.
    """
    out = list(results)
    groups: dict[str, list[int]] = {}
    for i, ident in enumerate(results):
        if ident.joint_id and ident.model != "line":
            groups.setdefault(ident.joint_id, []).append(i)
    for device, members in groups.items():
        if len(members) < 3:
            continue
        for i in members:
            others = [results[j].summary["clearance_m"] for j in members if j != i]
            middle = median(others)
            c = results[i].summary["clearance_m"]
            if middle > 0 and c > 2.0 * middle and results[i].flags["clearance_m"][0] == "ok":
                flags = dict(results[i].flags)
                flags["clearance_m"] = (
                    "doubtful",
                    f"clearance {c * 1e3:.3g} mm is more than twice the median "
                    f"{middle * 1e3:.3g} mm of the other {len(others)} tests of {device}",
                )
                out[i] = replace(results[i], flags=flags)
    return out


def _identify_path(args: tuple[str, bool, float]) -> tuple[Record, Identification] | str:
    """Read and identify one file; its result, or the line that says why it was not used."""
    from clearjoint.records import read_record

    path, resample, tolerance = args
    try:
        record = read_record(path, resample=resample)
        return record, identify(record, tolerance=tolerance)
    except ClearjointError as exc:
        text = str(exc)
        return text if text.startswith(str(path)) else f"{path}: {text}"


Outcome = tuple[Record, Identification] | str


def _size(path: str) -> int:
    try:
        return Path(path).stat().st_size
    except OSError:  # missing: refused by its reader, with its reason
        return 0


def identify_files(
    paths: list[str],
    *,
    resample: bool = False,
    tolerance: float = 0.03,
    jobs: int = 1,
    progress: Callable[[int, int], Any] | None = None,
) -> tuple[list[tuple[Record, Identification]], list[str]]:
    """Identify every file; return the results and one line for each file not used.

    Parameters
    ----------
    paths : list of str
        Record files (any format of :mod:`clearjoint.records`).
    resample, tolerance
        As for :func:`~clearjoint.records.read_record` and :func:`identify`.
    jobs : int
        Processes over the files: this one and ``jobs - 1`` workers forked after the
        readers are imported (``clearjoint.identify._pool.run_forked``); each takes
        the largest file not yet taken whenever it is free. The results are those of one
        process, in file order.
    progress : callable, optional
        ``progress(done, total)``, called after each file (a worker's files when that
        worker is done).

    Returns
    -------
    results : list of (Record, Identification)
    failures : list of str

    Clearances more than twice the median of the other tests of the same device are
    flagged (:func:`flag_outliers`).
    """
    tasks = [(str(path), resample, tolerance) for path in paths]
    outcomes: list[Outcome | None] = [None] * len(tasks)
    done = 0

    def finished(i: int, value: Outcome) -> None:
        nonlocal done
        outcomes[i] = value
        done += 1
        if progress:
            progress(done, len(tasks))

    if jobs > 1 and len(tasks) > 1 and hasattr(os, "fork"):
        from clearjoint.identify._pool import run_forked

        import_readers([path for path, _, _ in tasks])  # before the workers fork
        sizes = [_size(path) for path, _, _ in tasks]
        order = sorted(range(len(tasks)), key=lambda i: (-sizes[i], i))
        run_forked(_identify_path, tasks, order, jobs, finished)
    for i, task in enumerate(tasks):  # one process; or a file whose worker died
        if outcomes[i] is None:
            finished(i, _identify_path(task))
    results = [o for o in outcomes if o is not None and not isinstance(o, str)]
    failures = [o for o in outcomes if isinstance(o, str)]
    flagged = flag_outliers([ident for _, ident in results])
    return [(rec, ident) for (rec, _), ident in zip(results, flagged, strict=True)], failures
