"""A friction damper with backlash (the BRFD device): backlash, contact slopes, friction.

MODEL.md section 3 applied to a displacement-controlled friction damper. Along the travel
s from each reversal the force goes from the previous slip level L_prev to the next one
L_new: elastic unloading (slope k), the backlash b (no contact: the force stays at the
backlash level, which need not be zero), elastic loading (slope k), then slip at L_new.
The two levels need not be opposite (an offset mean, asymmetric friction): both are
reported, and the friction force is half their difference.

The estimator reads level crossings, not segments, so that ringing after each contact and
an offset mean do not bend it: for fractions alpha in [0.1, 0.9], s(alpha) is the travel
where the force first reaches L_prev + alpha (L_new - L_prev). On the elastic pieces s grows
as alpha (L_new - L_prev) / k; across the backlash it jumps by b. So k is the slope of the
median step (the jump spans one or two of the sixteen), and b is what the steps longer than
two elastic steps hold beyond one elastic step each.

One gap is crossed both ways, so both branches must show the same backlash: the reading
of each branch is kept (``_Fit.backlash_branches``), and a loop whose two readings differ
by more than :data:`BRANCH_RATIO` is flagged (:mod:`clearjoint.identify.core`): its
backlash is not one gap's (ringing read as gap, or a loop that does not come back to a
backlash level on one branch).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from clearjoint.identify.segments import _Fit

FloatArray = NDArray[np.float64]

#: The fractions of the level change whose first crossings are read.
ALPHAS = np.linspace(0.1, 0.9, 17)
#: The part of each branch's travel (its end) over which the slip level is the median force.
PLATEAU = 0.4
#: A step longer than (1 + JUMP) elastic steps is part of the backlash.
JUMP = 1.0
#: A plateau may change by at most this fraction of the level change over its travel.
FLATNESS = 0.35
#: The two branches' backlash readings may differ by at most this factor (else: doubtful).
BRANCH_RATIO = 2.0


def _crossings(travel: FloatArray, f: FloatArray, start: float, stop: float) -> FloatArray | None:
    """Travel where f first reaches start + alpha (stop - start), for each alpha in ALPHAS."""
    delta = stop - start
    sign = 1.0 if delta > 0 else -1.0
    progress = sign * (f - start) / abs(delta)  # 0 at the previous level, 1 at the new one
    reached = np.maximum.accumulate(progress)
    out = np.empty(ALPHAS.size)
    for i, alpha in enumerate(ALPHAS):
        j = int(np.searchsorted(reached, alpha))
        if j >= reached.size:
            return None
        if j == 0:  # already there at the reversal (ringing, or a level not yet reached)
            out[i] = 0.0
            continue
        # linear interpolation between samples j-1 and j (of the running maximum)
        p0, p1 = reached[j - 1], reached[j]
        w = (alpha - p0) / (p1 - p0) if p1 != p0 else 1.0
        out[i] = travel[j - 1] + min(max(w, 0.0), 1.0) * (travel[j] - travel[j - 1])
    return out


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
        levels.append(float(np.median(fb[late])))
        # a slip plateau is flat: its straight-line change over its travel is small
        slope = np.polyfit(travel[late], fb[late], 1)[0]
        levels_change = abs(slope) * PLATEAU * total
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
        steps = np.diff(s)
        jump = int(np.argmax(steps))
        typical = float(np.median(steps))  # most steps are elastic: the jump is one or two
        if typical <= 0.0:
            return None
        k = float(np.diff(ALPHAS)[0] * abs(stop - start) / typical)
        # the backlash: what the steps hold beyond the elastic step (the jump, one or two)
        excess = steps - typical
        backlash = float(np.sum(excess[excess > JUMP * typical]))
        gap_start = float(s[jump])
        gap_end = float(s[jump + 1])
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
