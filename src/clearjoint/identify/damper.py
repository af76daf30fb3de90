"""A friction damper with backlash (the BRFD device): backlash, contact slopes, friction.

MODEL.md section 3 applied to a displacement-controlled friction damper. Along the travel
s from each reversal the force goes from the previous slip level L_prev to the next one
L_new: elastic unloading (slope k), the backlash b (no contact: the force stays at the
backlash level, which need not be zero), elastic loading (slope k), then slip at L_new.
The two levels need not be opposite (an offset mean, asymmetric friction): both are
reported, and the friction force is half their difference.

The estimator reads level crossings, not segments, so that ringing after each contact and
an offset mean do not bend it: for fractions alpha_i = (i + 1/2) / N of the level change
(i = 0 ... N - 1, the midpoints of N equal bands: a resolution, not a chosen range), s(alpha)
is the travel where the force first reaches L_prev + alpha (L_new - L_prev). The elastic-
plastic loop with a gap has exactly

    s(alpha) = alpha abs(L_new - L_prev) / k + b H(alpha - alpha_b),

with H the unit step at the backlash level alpha_b: two parallel lines in alpha (the elastic
unloading before the gap, the elastic loading after it), b apart. The slope is the median
step between successive crossings (most of them are elastic), so k is read as before; b is
the distance between the two lines, each placed by least absolute deviations (the median of
s - alpha abs(L_new - L_prev) / k before and after the step), at the step place alpha_b, between
two crossings (at least two on each side), whose total absolute deviation is least. No
threshold decides what is gap: a crossing delayed by ringing as slip starts (the force
reaching 85 % of the new level, ringing back and reaching 90 % millimetres later) is one
residual about the upper line, not travel of the gap, and a gap crossed over a spread of
levels is still the distance between the lines on either side of it.

One gap is crossed both ways, so both branches must show the same backlash: the reading
of each branch is kept (``_Fit.backlash_branches``), and a loop whose two readings differ
by more than :data:`BRANCH_RATIO` is flagged (:mod:`clearjoint.identify.core`): its
backlash is not one gap's (ringing read as gap, or a loop that does not come back to a
backlash level on one branch).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from clearjoint.identify._stats import median
from clearjoint.identify.segments import _Fit

FloatArray = NDArray[np.float64]

#: Crossings read per branch: alpha_i = (i + 1/2) / N, the midpoints of N equal bands.
N_CROSSINGS = 48
#: The fractions of the level change whose first crossings are read.
ALPHAS = (np.arange(N_CROSSINGS) + 0.5) / N_CROSSINGS
#: The part of each branch's travel (its end) over which the slip level is the median force.
PLATEAU = 0.4
#: A plateau may change by at most this fraction of the level change over its travel.
FLATNESS = 0.35
#: The two branches' backlash readings may differ by at most this factor (else: doubtful).
BRANCH_RATIO = 2.0

#: Step places tried: the step lies between crossings j - 1 and j, for j in _PLACES.
_PLACES = np.arange(2, N_CROSSINGS - 1)
#: Whether crossing i lies before the step at each place, shape (places, N).
_BEFORE = np.arange(N_CROSSINGS)[None, :] < _PLACES[:, None]


def _crossings(travel: FloatArray, f: FloatArray, start: float, stop: float) -> FloatArray | None:
    """Travel where f first reaches start + alpha (stop - start), for each alpha in ALPHAS.

    None when the force never reaches the last fraction on this branch.
    """
    delta = stop - start
    sign = 1.0 if delta > 0 else -1.0
    progress = sign * (f - start) / abs(delta)  # 0 at the previous level, 1 at the new one
    reached = np.maximum.accumulate(progress)
    j = np.searchsorted(reached, ALPHAS)
    if j[-1] >= reached.size:
        return None
    # linear interpolation between samples j-1 and j of the running maximum; a fraction
    # already reached at the reversal (ringing, or a level not yet left) reads travel 0
    jm = np.maximum(j - 1, 0)
    p0, p1 = reached[jm], reached[j]
    rise = p1 - p0
    w = np.clip((ALPHAS - p0) / np.where(rise != 0.0, rise, 1.0), 0.0, 1.0)
    out = travel[jm] + np.where(rise != 0.0, w, 1.0) * (travel[j] - travel[jm])
    out = np.where(j == 0, 0.0, out)
    return np.asarray(out, dtype=np.float64)


def _best_place(r: FloatArray) -> int:
    """The step place (index into :data:`_PLACES`) of least absolute deviation for r (N,),
    the crossings less the line's slope part: at each place the intercept and the step's
    top are the medians of r before and from it."""
    low = np.where(_BEFORE, r[None, :], np.inf)
    high = np.where(_BEFORE, -np.inf, r[None, :])
    low.sort(axis=1)
    high.sort(axis=1)
    rows = np.arange(_PLACES.size)
    n_low, n_high = _PLACES, N_CROSSINGS - _PLACES
    med_low = 0.5 * (low[rows, (n_low - 1) // 2] + low[rows, n_low // 2])
    med_high = 0.5 * (high[rows, n_low + (n_high - 1) // 2] + high[rows, n_low + n_high // 2])
    centre = np.where(_BEFORE, med_low[:, None], med_high[:, None])
    return int(np.argmin(np.abs(r[None, :] - centre).sum(axis=1)))


def _step_fit(s: FloatArray) -> tuple[float, float, float, int]:
    """The line-plus-step model fitted to crossings s (N,): two parallel elastic lines.

    Returns (intercept, slope in travel per unit alpha, step b, place j): the step lies
    between crossings j - 1 and j. The slope d is the median step's (most steps are
    elastic); with it fixed, the least-absolute-deviation fit of the intercept and of the
    step at a place is a pair of medians (of s - d alpha before and from the place), every
    place is tried at once and the one of least absolute deviation is kept.
    """
    d = median(np.diff(s)) * N_CROSSINGS
    if not d > 0.0:
        return 0.0, 0.0, 0.0, int(_PLACES[0])
    r = s - d * ALPHAS
    j = int(_PLACES[_best_place(r)])
    c, top = median(r[:j]), median(r[j:])
    return c, d, top - c, j


def _slope(t: FloatArray, y: FloatArray) -> float:
    """The least-squares straight line's slope through (t, y) (n,), in closed form.

    The centred normal equation, as ``numpy.polyfit(t, y, 1)[0]`` solves it by an SVD, to
    rounding; 0 when t does not vary.
    """
    tc = t - t.mean()
    spread = float(tc @ tc)
    return float(tc @ (y - y.mean())) / spread if spread > 0.0 else 0.0


def _damper_fit(x: FloatArray, f: FloatArray, parts: tuple[slice, slice]) -> _Fit | None:
    """The damper model on one cycle average: None if the loop has no slip plateaus.

    ``parts`` are the rising and the falling branch of ``x`` (M,), which starts at its
    minimum.
    """
    levels = []
    for part in parts:
        xb, fb = x[part], f[part]
        travel = np.abs(xb - xb[0])
        total = float(travel[-1])
        late = travel >= (1.0 - PLATEAU) * total
        if total <= 0.0 or late.sum() < 4:
            return None
        levels.append(median(fb[late]))
        # a slip plateau is flat: its straight-line change over its travel is small
        levels_change = abs(_slope(travel[late], fb[late])) * PLATEAU * total
        levels.append(levels_change)
    rise, rise_change, fall, fall_change = levels
    delta = rise - fall
    if delta == 0.0 or max(rise_change, fall_change) > FLATNESS * abs(delta):
        return None
    results = []
    for part, start, stop in ((parts[0], fall, rise), (parts[1], rise, fall)):
        xb, fb = x[part], f[part]
        travel = np.abs(xb - xb[0])
        s = _crossings(travel, fb, start, stop)
        if s is None:
            return None
        c, d, b, j = _step_fit(s)
        if d <= 0.0:
            return None
        k = float(abs(stop - start) / d)
        backlash = max(b, 0.0)
        alpha_b = 0.5 * (ALPHAS[j - 1] + ALPHAS[j])
        gap_start = max(c + d * alpha_b, 0.0)
        gap_end = gap_start + backlash
        direction = 1.0 if xb[-1] > xb[0] else -1.0
        results.append((k, backlash, xb[0] + direction * gap_start, xb[0] + direction * gap_end))
    (k_rise, b_rise, r0, r1), (k_fall, b_fall, f0, f1) = results
    upper = 0.5 * (max(r0, r1) + max(f0, f1))
    lower = 0.5 * (min(r0, r1) + min(f0, f1))
    backlash = 0.5 * (b_rise + b_fall)
    centre = 0.5 * (upper + lower)
    # the rising branch loads toward the higher level: its slope is the "compression" one
    k_c, k_t = (k_rise, k_fall) if rise > fall else (k_fall, k_rise)
    return _Fit(
        centre + 0.5 * backlash,
        centre - 0.5 * backlash,
        k_c,
        k_t,
        0.0,
        0.5 * abs(delta),
        level_positive=max(rise, fall),
        level_negative=min(rise, fall),
        backlash_branches=(b_rise, b_fall),
    )
