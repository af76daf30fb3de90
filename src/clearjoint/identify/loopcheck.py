"""How well the fitted model describes the measured loop: its residual.

The per-sample fits of a clearance joint and of a line (MODEL.md section 3, "the stages";
:mod:`clearjoint.identify.segments`) are read against the cycle average by
:func:`sample_fit_residual`; the damper's below.

MODEL.md section 3 (the friction damper with backlash, elastic-plastic with a gap).
Along the travel s from a branch's reversal the model force is

    F(s) = L_prev + sgn (k min(s, s_b) + k max(s - s_b - b, 0)),  until it reaches L_new,

then L_new (slip): elastic unloading, the gap b crossed at the force it had reached
(s_b, the travel where the gap starts), elastic loading, slip. The levels L_prev and
L_new, the slope k and the backlash b of each branch are the identified ones
(:func:`clearjoint.identify.damper._damper_fit`); s_b, which the fit does not keep, is
placed where the branch's residual is least. The residual is the rms over both branches
of the cycle average's force minus the model's: a loop the model does not describe (a
smooth hysteresis with no gap at all, a loop read from the wrong reversal) leaves a
residual far above the noise floor of the cycle average, which
:mod:`clearjoint.identify.core` flags.

The noise floor (:func:`reading`, one function for every path: damper, a joint's or a
line's sample fit, the weak form) is errors-in-variables, per sample (or per weak-form
equation): a restoring-force model F(x) fitted to a measured x carries the displacement's
noise times the model's local slope as well as the force's own noise,

    sigma_i^2 = sigma_F^2 + (k_i sigma_x)^2,

k_i = dF/dx of the fitted model at sample i (0 in the gap and on a slip plateau; the
stage's slope k_s of MODEL.md section 3 on a contact or elastic line), sigma_F and sigma_x
the rms noise of the cycle average's restoring force and displacement (the scatter over
the cycles / sqrt(n), :func:`channel_noise`; the force's at least 0.1 % of its standard
deviation, ``clearjoint.identify.core.RESOLUTION``). A weak-form equation (a weighted
integral over a stage, :mod:`clearjoint.identify.weak`) carries sigma_e^2 = sigma_F^2 sum(w_F^2) +
sigma_x^2 sum(w_x^2), its weights on the force and on the displacement (phi; k_s phi -
c phi' + m phi'' when the inertia is read from the displacement). Residual and floor are
compared in one norm: each error over its own sigma, z_i = e_i / sigma_i, and the
residual's ratio to its floor is the rms of z (the sqrt of chi^2 per sample, 1 for a model
that leaves only noise), or on the sample fits, which read their residual robustly,
1.4826 times the median absolute deviation of z. The drag's and the sign term's share of
the velocity noise is not counted (a sign that follows the noise near a reversal touches
a few samples, which the robust reading ignores), nor, on a sample fit, the noise of an
inertia m x'' taken from the displacement's spectral derivative (the rig's records and
the weak form have no such term).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from clearjoint.errors import ParameterError
from clearjoint.identify._stats import median
from clearjoint.identify.segments import STAGE_COMPRESSION, STAGE_TENSION, _Fit

if TYPE_CHECKING:
    from clearjoint.identify.weak import WeakFit, WeakSystem

FloatArray = NDArray[np.float64]

#: Gap starts tried per branch (evenly over the travel that reaches the new level).
PLACES = 64
#: Samples of a branch the residual is read on at most (every k-th: an rms needs no more,
#: and the BRFD's 2048-sample branches would otherwise cost half the identification).
BRANCH_SAMPLES = 128
#: A sample in no stage window (a joint's stage codes are -1, 0, 1).
NO_STAGE = 2
#: The median absolute deviation times this is the rms of Gaussian residuals.
MAD_TO_RMS = 1.4826
#: A velocity sign the noise flips with a chance above this is unsure.
UNSURE_SIGN = 0.1


@dataclass(frozen=True)
class Noise:
    """The rms noise per sample of a cycle average's two channels.

    ``force`` (N) is the restoring force's (the measured force, minus m x'' with a measured
    acceleration under force control); ``displacement`` (m) is NaN when it could not be
    estimated, and ``note`` then says why (the floor counts the force alone); ``velocity``
    (m/s) is the noise of the velocity whose sign the friction term takes.
    """

    force: float
    displacement: float
    note: str = ""
    #: The velocity's (m/s) whose sign the friction term takes; NaN: its sign is not counted.
    velocity: float = math.nan

    def __post_init__(self) -> None:
        if not self.force >= 0.0:
            raise ParameterError(f"force noise {self.force!r} N: give a finite value >= 0")
        if self.displacement < 0.0:
            raise ParameterError(f"displacement noise {self.displacement!r} m: give a value >= 0")


@dataclass(frozen=True)
class Reading:
    """A fit residual against its noise floor.

    ``residual`` (N): the errors' rms (robust on a sample fit); ``ratio``: the rms (robust)
    of each error over its own sigma; ``floor`` (N) = residual / ratio, the floor those
    errors were held to; ``note``: why the displacement's noise is not counted, or "";
    ``unsure``: the share of the samples whose friction sign is a toss-up.
    """

    residual: float
    floor: float
    ratio: float
    note: str = ""
    #: The share of the samples whose velocity sign the noise flips with a chance above
    #: ``UNSURE_SIGN`` (there the friction term, and the floor, rest on noise).
    unsure: float = 0.0


def scatter(stacked: FloatArray) -> float:
    """Return the rms noise of one channel's cycle average.

    Parameters
    ----------
    stacked : (n, M) ndarray
        The channel's n cycles on one phase grid.

    Returns
    -------
    float
        The scatter over the cycles (rms over the phase of the per-sample standard
        deviation) / sqrt(n); NaN with fewer than two cycles.
    """
    n = stacked.shape[0]
    if n < 2:
        return math.nan
    return float(np.sqrt(np.mean(np.var(stacked, axis=0, ddof=1)))) / math.sqrt(n)


def jackknife_noise(replicates: FloatArray) -> float:
    """Return the rms noise of an average from its jackknife replicates.

    Parameters
    ----------
    replicates : (G + 1, M) ndarray
        Row 0 the average of all cycles, then the averages without each of G groups.

    Returns
    -------
    float
        sqrt(mean over samples of (G - 1)/G sum (theta_g - mean theta)^2); NaN with fewer
        than two groups.
    """
    rows = replicates[1:]
    g = rows.shape[0]
    if g < 2:
        return math.nan
    spread = (g - 1) / g * np.sum((rows - rows.mean(axis=0)) ** 2, axis=0)
    return float(np.sqrt(np.mean(spread)))


def sign_noise(velocity: FloatArray, noise: float) -> FloatArray:
    """Return the standard deviation of sgn(v + e), e Gaussian with the rms ``noise``.

    Parameters
    ----------
    velocity : (M,) ndarray
        The velocity whose sign is taken, m/s (it stands for the true one).
    noise : float
        The rms noise of that velocity, m/s.

    Returns
    -------
    (M,) ndarray
        2 sqrt(p (1 - p)), p = Phi(-abs(v) / noise) the chance that the noise flips the
        sign; zeros when ``noise`` is NaN or zero.
    """
    out: FloatArray = np.zeros_like(velocity)
    if not noise > 0.0:
        return out
    u = np.abs(velocity) / (noise * math.sqrt(2.0))
    near = np.flatnonzero(u < 6.0)  # beyond, a flip's chance is below 1e-17
    p = 0.5 * np.array([math.erfc(value) for value in u[near]])
    out[near] = 2.0 * np.sqrt(p * (1.0 - p))
    return out


def unsure_share(spread: FloatArray) -> float:
    """Return the share of samples whose velocity sign is a toss-up.

    Parameters
    ----------
    spread : (M,) ndarray
        The sign's standard deviation per sample (:func:`sign_noise`).

    Returns
    -------
    float
        The share whose flip has a chance above ``UNSURE_SIGN`` (0 when empty).
    """
    if spread.size == 0:
        return 0.0
    return float(np.mean(spread > 2.0 * math.sqrt(UNSURE_SIGN * (1.0 - UNSURE_SIGN))))


def channel_noise(
    force: FloatArray,
    displacement: float,
    resolution: float,
    velocity: float = math.nan,
) -> Noise:
    """Return the noise of the cycle average of the stacked ``force`` and ``displacement``.

    Parameters
    ----------
    force : (n, M) ndarray
        The restoring force (N) of the n steady cycles, stacked on one phase grid.
    displacement : float
        The displacement's :func:`scatter` on the same stack (m; NaN with one cycle).
    velocity : float
        The noise of the velocity whose sign the friction term takes, m/s
        (:func:`scatter` of a measured one, :func:`jackknife_noise` of a derived one).
    resolution : float
        The force's noise is at least this part of its cycle average's standard deviation
        (the digits and the ADC: a noise-free record is not held to zero; as before the
        floor counted the displacement, whose own resolution is not added).

    Returns
    -------
    Noise
        Each channel's scatter over the cycles / sqrt(n). With fewer than two cycles no
        scatter exists: the force's is its resolution alone and the displacement's is NaN,
        with a note (the floor then counts the force channel only).
    """
    f_res = resolution * float(np.std(force.mean(axis=0)))
    sf, sx = scatter(force), displacement
    if math.isnan(sx):
        note = (
            f"{force.shape[0]} cycle: no scatter over cycles to estimate the displacement's "
            "noise, so the floor counts the force channel alone (give more cycles)"
        )
        return Noise(f_res if math.isnan(sf) else max(sf, f_res), math.nan, note, velocity)
    return Noise(max(sf, f_res), sx, "", velocity)


def _robust_rms(values: FloatArray) -> float:
    """1.4826 times the median absolute deviation: the rms of Gaussian values."""
    # _stats.median: numpy.median's double without importing numpy.ma (about 10 ms a process)
    return float(MAD_TO_RMS * median(np.abs(values - median(values))))


def reading(
    error: FloatArray,
    noise: Noise,
    force_gain: FloatArray | float,
    displacement_gain: FloatArray | float,
    sign: FloatArray | float = 0.0,
    *,
    robust: bool = False,
    unsure: float = 0.0,
) -> Reading:
    """Return the residual ``error`` against its errors-in-variables noise floor.

    Each error's sigma is sqrt((g_F sigma_F)^2 + (g_x sigma_x)^2 + s^2): on a sample g_F = 1
    and g_x = abs(k_i), the model's local slope dF/dx, and s = abs(F_f) times the standard
    deviation of the velocity's sign there (:func:`sign_noise`); on a weak-form equation
    the rms-summed weights of the equation on the force's, the displacement's and the
    sign's samples. The ratio is the rms of error / sigma (``robust``: 1.4826 times its
    median absolute deviation).

    Parameters
    ----------
    error : (E,) ndarray
        The fit's errors, N (per sample or per equation).
    noise : Noise
        The cycle average's noise per channel (:func:`channel_noise`).
    force_gain, displacement_gain : (E,) ndarray or float
        Each error's gain on the force's noise (1 per sample) and on the displacement's
        (N/m: the slope).
    sign : (E,) ndarray or float
        Each error's noise from the friction term's velocity sign, N (0: none).
    robust : bool
        Read the residual and the ratio robustly (the sample fits' reading).
    unsure : float
        The share of unsure velocity signs (:func:`unsure_share`), passed on.

    Returns
    -------
    Reading
        NaN throughout when there is no error to read.
    """
    e = np.asarray(error, dtype=np.float64)
    if e.size == 0 or not np.all(np.isfinite(e)):
        return Reading(math.nan, math.nan, math.nan, noise.note)
    sx = 0.0 if math.isnan(noise.displacement) else noise.displacement
    gf = np.broadcast_to(np.asarray(force_gain, dtype=np.float64), e.shape)
    gx = np.broadcast_to(np.asarray(displacement_gain, dtype=np.float64), e.shape)
    gs = np.broadcast_to(np.asarray(sign, dtype=np.float64), e.shape)
    sigma = np.sqrt((gf * noise.force) ** 2 + (gx * sx) ** 2 + gs**2)
    if not np.all(sigma > 0.0):
        return Reading(math.nan, math.nan, math.nan, noise.note)
    z = e / sigma
    if robust:
        residual, ratio = _robust_rms(e), _robust_rms(z)
    else:
        residual, ratio = float(np.sqrt(np.mean(e**2))), float(np.sqrt(np.mean(z**2)))
    floor = residual / ratio if ratio > 0.0 else float(np.sqrt(np.mean(sigma**2)))
    return Reading(residual, floor, ratio, noise.note, unsure)


def _branch_residuals(
    travel: FloatArray, force: FloatArray, start: float, stop: float, k: float, b: float
) -> tuple[FloatArray, FloatArray]:
    """Residuals of the best-placed model branch and its slope |dF/dx| per sample, (n,)."""
    change = stop - start
    sign = 1.0 if change > 0 else -1.0
    elastic = abs(change) / k  # the elastic travel from one level to the other
    s = travel[None, :]

    def trial(places: FloatArray) -> tuple[float, FloatArray, FloatArray]:
        """The best of the gap starts ``places``, its residuals and its slopes."""
        column = places[:, None]
        strain = np.minimum(s, column) + np.maximum(s - column - b, 0.0)
        model = start + sign * np.minimum(k * strain, abs(change))
        errors = force[None, :] - model
        best = int(np.argmin((errors**2).sum(axis=1)))
        place = places[best]
        # elastic (slope k) before the gap and after it, until the new level is reached
        in_gap = (travel > place) & (travel < place + b)
        slipping = k * strain[best] >= abs(change)
        slope = np.where(in_gap | slipping, 0.0, k)
        return float(place), errors[best], slope

    # the gap's start s_b: a coarse grid over the elastic travel, then a fine one around
    # its best (a misplaced start leaves up to k times the grid step)
    step = elastic / (PLACES - 1)
    coarse, _, _ = trial(np.linspace(0.0, elastic, PLACES))
    _, out, slope = trial(np.linspace(max(coarse - step, 0.0), min(coarse + step, elastic), PLACES))
    return out, slope


def damper_residual(
    x: FloatArray, f: FloatArray, parts: tuple[slice, slice], fit: _Fit, noise: Noise
) -> Reading:
    """Return the damper model ``fit``'s residual on the cycle average against its floor.

    Parameters
    ----------
    x, f : (M,) ndarray
        The cycle average's displacement (m) and force (N), starting at the minimum of x.
    parts : tuple of slice
        The rising and the falling branch of ``x``.
    fit : _Fit
        The damper's fit on that average (levels, slopes, each branch's backlash).
    noise : Noise
        The average's noise per channel (:func:`channel_noise`).

    Returns
    -------
    Reading
        The rms over both branches (N) and its ratio to the floor (slope k on the elastic
        lines, 0 in the gap and on the slip plateaus); NaN when the fit lacks a level,
        slope or backlash.
    """
    high, low = fit.level_positive, fit.level_negative
    b_rise, b_fall = fit.backlash_branches
    numbers = (high, low, b_rise, b_fall, fit.k_compression, fit.k_tension)
    if not all(math.isfinite(v) for v in numbers) or min(fit.k_compression, fit.k_tension) <= 0:
        return Reading(math.nan, math.nan, math.nan, noise.note)
    # the rising branch slips at the level its end force is nearer to
    rise_end = median(f[parts[0]][-4:])
    rise_level, fall_level = (
        (high, low) if abs(rise_end - high) <= abs(rise_end - low) else (low, high)
    )
    errors, slopes = [], []
    for part, start, stop, b in (
        (parts[0], fall_level, rise_level, b_rise),
        (parts[1], rise_level, fall_level, b_fall),
    ):
        every = max(1, -(-(part.stop - (part.start or 0)) // BRANCH_SAMPLES))
        xb, fb = x[part][::every], f[part][::every]
        # the branch loading toward the higher level has the "compression" slope
        k = fit.k_compression if stop > start else fit.k_tension
        error, slope = _branch_residuals(np.abs(xb - xb[0]), fb, start, stop, k, max(b, 0.0))
        errors.append(error)
        slopes.append(slope)
    return reading(np.concatenate(errors), noise, 1.0, np.concatenate(slopes))


def sample_fit_residual(
    x: FloatArray,
    r: FloatArray,
    v: FloatArray,
    fit: _Fit,
    noise: Noise,
    stage: NDArray[np.int8] | None = None,
) -> Reading:
    """Return a per-sample fit's (a joint's or a line's) residual on the average, read
    against its floor.

    The model is the fit's own, its coefficients as fitted (the drag and the signed
    friction with them): a joint's F = a_s + k_s x + c x' + F_f sgn x' on the samples in
    a stage window, s that window's stage (the rows the fit was made on); a line's
    F = a + k_c x (x > 0) + k_t x (x <= 0) + c x' + F_f sgn x' on every sample. The
    residual is read as the fit reads it, robustly: 1.4826 times the median absolute
    deviation (the rms of Gaussian residuals), so the few samples the biweight fit gives
    no weight (the ringing right after an impact) do not count, while a model that
    misses the loop's shape (a smooth hysteresis read as straight pieces) leaves it large.
    The floor's slope at a sample is the fitted k_s (a joint) or k_c, k_t (a line).

    Parameters
    ----------
    x, r, v : (M,) ndarray
        The cycle average's displacement (m), restoring force (N) and velocity (m/s), as
        the fit had them.
    fit : _Fit
        The joint's or the line's fit on that average.
    noise : Noise
        The average's noise per channel (:func:`channel_noise`).
    stage : (M,) ndarray of int8, optional
        A joint's stage per sample (``STAGE_TENSION``, ``STAGE_FREE``,
        ``STAGE_COMPRESSION``; ``NO_STAGE`` outside every window); needed for a joint.

    Returns
    -------
    Reading
        NaN throughout when the fit kept no coefficients (or a joint has no stages).
    """
    c = fit.coefficients
    if len(c) == 8 and stage is not None:  # a joint: tension, free play, compression
        rows = stage != NO_STAGE
        s, xs, vs = stage[rows], x[rows], v[rows]
        tension, compression = s == STAGE_TENSION, s == STAGE_COMPRESSION
        intercept = np.where(compression, c[4], np.where(tension, c[0], c[2]))
        slope = np.where(compression, c[5], np.where(tension, c[1], c[3]))
        error = r[rows] - (intercept + slope * xs + c[6] * vs + c[7] * np.sign(vs))
        spread = sign_noise(vs, noise.velocity)
        friction = abs(c[7]) * spread
    elif len(c) == 5:  # a line
        slope = np.where(x > 0, c[1], c[2])
        error = r - (c[0] + slope * x + c[3] * v + c[4] * np.sign(v))
        spread = sign_noise(v, noise.velocity)
        friction = abs(c[4]) * spread
    else:
        return Reading(math.nan, math.nan, math.nan, noise.note)
    return reading(
        error, noise, 1.0, np.abs(slope), friction, robust=True, unsure=unsure_share(spread)
    )


def weak_residual(
    system: WeakSystem, fit: WeakFit, velocity: FloatArray, noise: Noise, *, inertia_from_x: bool
) -> Reading:
    """Return the weak form's equation residual (replicate 0) against its floor.

    Equation e, divided by its scale sum(abs(phi)) as the fit divides it, weighs the force
    samples by phi and the displacement samples by k_s phi - c phi' (+ m phi'' when the
    inertia is read from the displacement, no acceleration channel): its sigma is
    sqrt(sigma_F^2 sum(phi^2) + sigma_x^2 sum((k_s phi - c phi' + m phi'')^2)) / scale
    (white noise on the cycle average's samples), and the friction column int(phi sgn x')
    adds abs(F_f) sqrt(sum(phi^2 s^2)) / scale, s the sign's standard deviation per sample
    (:func:`sign_noise`).

    Parameters
    ----------
    system : WeakSystem
        The test functions' weights, E equations.
    fit : WeakFit
        Its solution; row 0 (the average of all cycles) is read.
    velocity : (M,) ndarray
        The velocity whose sign built the friction column (m/s).
    noise : Noise
        The average's noise per channel (:func:`channel_noise`).
    inertia_from_x : bool
        The inertia integral is m int(phi'' x) (no acceleration channel, under force
        control): the displacement's noise then also enters through m phi''.

    Returns
    -------
    Reading
        The rms equation residual (N) and its ratio to the floor.
    """
    scale = np.abs(system.phi).sum(axis=1)
    slope = fit.lines[0, system.stage, 1]  # (E,) k_s of each equation's stage
    weights = slope[:, None] * system.phi - fit.drag[0] * system.dphi
    if inertia_from_x:
        weights = weights + fit.mass[0] * system.ddphi
    force_gain = np.sqrt((system.phi**2).sum(axis=1)) / scale
    displacement_gain = np.sqrt((weights**2).sum(axis=1)) / scale
    spread = sign_noise(velocity, noise.velocity)
    flips = spread[system.columns] * system.phi
    sign = abs(float(fit.friction[0])) * np.sqrt((flips**2).sum(axis=1)) / scale
    used = np.unique(system.columns[system.phi != 0.0])
    return reading(
        fit.equations,
        noise,
        force_gain,
        displacement_gain,
        sign,
        unsure=unsure_share(spread[used]),
    )
