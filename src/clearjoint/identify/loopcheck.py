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
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from clearjoint.identify._stats import median
from clearjoint.identify.segments import STAGE_COMPRESSION, STAGE_TENSION, _Fit

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


def _branch_residuals(
    travel: FloatArray, force: FloatArray, start: float, stop: float, k: float, b: float
) -> FloatArray:
    """Squared residuals of the best-placed model branch, (n,)."""
    change = stop - start
    sign = 1.0 if change > 0 else -1.0
    elastic = abs(change) / k  # the elastic travel from one level to the other
    s = travel[None, :]

    def trial(places: FloatArray) -> tuple[float, FloatArray]:
        """The best of the gap starts ``places`` and its squared residuals."""
        column = places[:, None]
        strain = np.minimum(s, column) + np.maximum(s - column - b, 0.0)
        model = start + sign * np.minimum(k * strain, abs(change))
        squared = (force[None, :] - model) ** 2
        best = int(np.argmin(squared.sum(axis=1)))
        return float(places[best]), squared[best]

    # the gap's start s_b: a coarse grid over the elastic travel, then a fine one around
    # its best (a misplaced start leaves up to k times the grid step)
    step = elastic / (PLACES - 1)
    coarse, _ = trial(np.linspace(0.0, elastic, PLACES))
    _, out = trial(np.linspace(max(coarse - step, 0.0), min(coarse + step, elastic), PLACES))
    return out


def damper_residual(x: FloatArray, f: FloatArray, parts: tuple[slice, slice], fit: _Fit) -> float:
    """Return the rms residual (N) of the damper model ``fit`` on the cycle average.

    Parameters
    ----------
    x, f : (M,) ndarray
        The cycle average's displacement (m) and force (N), starting at the minimum of x.
    parts : tuple of slice
        The rising and the falling branch of ``x``.
    fit : _Fit
        The damper's fit on that average (levels, slopes, each branch's backlash).

    Returns
    -------
    float
        The rms over both branches, N; NaN when the fit lacks a level, slope or backlash.
    """
    high, low = fit.level_positive, fit.level_negative
    b_rise, b_fall = fit.backlash_branches
    numbers = (high, low, b_rise, b_fall, fit.k_compression, fit.k_tension)
    if not all(math.isfinite(v) for v in numbers) or min(fit.k_compression, fit.k_tension) <= 0:
        return math.nan
    # the rising branch slips at the level its end force is nearer to
    rise_end = median(f[parts[0]][-4:])
    rise_level, fall_level = (
        (high, low) if abs(rise_end - high) <= abs(rise_end - low) else (low, high)
    )
    squared = []
    for part, start, stop, b in (
        (parts[0], fall_level, rise_level, b_rise),
        (parts[1], rise_level, fall_level, b_fall),
    ):
        every = max(1, -(-(part.stop - (part.start or 0)) // BRANCH_SAMPLES))
        xb, fb = x[part][::every], f[part][::every]
        # the branch loading toward the higher level has the "compression" slope
        k = fit.k_compression if stop > start else fit.k_tension
        squared.append(_branch_residuals(np.abs(xb - xb[0]), fb, start, stop, k, max(b, 0.0)))
    return float(np.sqrt(np.mean(np.concatenate(squared))))


def sample_fit_residual(
    x: FloatArray,
    r: FloatArray,
    v: FloatArray,
    fit: _Fit,
    stage: NDArray[np.int8] | None = None,
) -> float:
    """Return the residual (N) of a per-sample fit (a joint's or a line's) on the average.

    The model is the fit's own, its coefficients as fitted (the drag and the signed
    friction with them): a joint's F = a_s + k_s x + c x' + F_f sgn x' on the samples in
    a stage window, s that window's stage (the rows the fit was made on); a line's
    F = a + k_c x (x > 0) + k_t x (x <= 0) + c x' + F_f sgn x' on every sample. The
    residual is read as the fit reads it, robustly: 1.4826 times the median absolute
    deviation (the rms of Gaussian residuals), so the few samples the biweight fit gives
    no weight (the ringing right after an impact) do not count, while a model that
    misses the loop's shape (a smooth hysteresis read as straight pieces) leaves it large.

    Parameters
    ----------
    x, r, v : (M,) ndarray
        The cycle average's displacement (m), restoring force (N) and velocity (m/s), as
        the fit had them.
    fit : _Fit
        The joint's or the line's fit on that average.
    stage : (M,) ndarray of int8, optional
        A joint's stage per sample (``STAGE_TENSION``, ``STAGE_FREE``,
        ``STAGE_COMPRESSION``; ``NO_STAGE`` outside every window); needed for a joint.

    Returns
    -------
    float
        The residual, N; NaN when the fit kept no coefficients (or a joint has no stages).
    """
    c = fit.coefficients
    if len(c) == 8 and stage is not None:  # a joint: tension, free play, compression
        rows = stage != NO_STAGE
        s, xs, vs = stage[rows], x[rows], v[rows]
        tension, compression = s == STAGE_TENSION, s == STAGE_COMPRESSION
        intercept = np.where(compression, c[4], np.where(tension, c[0], c[2]))
        slope = np.where(compression, c[5], np.where(tension, c[1], c[3]))
        error = r[rows] - (intercept + slope * xs + c[6] * vs + c[7] * np.sign(vs))
    elif len(c) == 5:  # a line
        error = r - (c[0] + np.where(x > 0, c[1], c[2]) * x + c[3] * v + c[4] * np.sign(v))
    else:
        return math.nan
    if error.size == 0:
        return math.nan
    return float(MAD_TO_RMS * np.median(np.abs(error - np.median(error))))
