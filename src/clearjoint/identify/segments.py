"""Piecewise-straight fits of force against displacement: stages and model choice.

MODEL.md section 3, "the stages": a segmented least-squares fit (dynamic programming
over binned data) splits a branch of the loop into straight pieces, told apart as
steep (contact) or flat (free play) by two-means on the log of their slopes, not by a
threshold. A clearance joint's branch reads steep, flat, steep. The per-sample fits
here (robust least squares of F = a_s + k_s x + c x' + F_f sgn x') decide between the
clearance joint and a straight line by BIC; the joint's parameters themselves come
from the weak form (:mod:`clearjoint.identify.weak`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

STAGE_FREE, STAGE_COMPRESSION, STAGE_TENSION = 0, 1, -1
BINS = 48


def _segments(x: FloatArray, y: FloatArray, n_segments: int, bins: int) -> list[tuple[int, int]]:
    """Best split of (x, y), sorted by x, into straight pieces, by dynamic programming.

    The data are averaged into ``bins`` bins of equal count; the cost of a piece is
    the weighted residual of a straight line through its bins. Returns the sample
    index range of every piece.
    """
    n = x.size
    edges = np.linspace(0, n, min(bins, n) + 1).astype(int)
    w = np.diff(edges).astype(float)
    sx = np.add.reduceat(x, edges[:-1])
    sy = np.add.reduceat(y, edges[:-1])
    sxx = np.add.reduceat(x * x, edges[:-1])
    sxy = np.add.reduceat(x * y, edges[:-1])
    syy = np.add.reduceat(y * y, edges[:-1])
    cum = [np.concatenate(([0.0], np.cumsum(s))) for s in (w, sx, sy, sxx, sxy, syy)]
    m = w.size
    i, j = np.triu_indices(m + 1, k=2)  # pieces of at least two bins: [i, j)
    cw, cx, cy, cxx, cxy, cyy = (c[j] - c[i] for c in cum)
    vxx = cxx - cx * cx / cw
    vxy = cxy - cx * cy / cw
    vyy = cyy - cy * cy / cw
    cost = np.full((m + 1, m + 1), np.inf)
    cost[i, j] = np.maximum(vyy - np.where(vxx > 0, vxy * vxy / np.where(vxx > 0, vxx, 1), 0), 0)
    best = np.full((n_segments + 1, m + 1), np.inf)
    back = np.zeros((n_segments + 1, m + 1), dtype=int)
    best[0, 0] = 0.0
    for k in range(1, n_segments + 1):
        total = best[k - 1][:, None] + cost
        back[k] = np.argmin(total, axis=0)
        best[k] = total[back[k], np.arange(m + 1)]
    cuts = [m]
    for k in range(n_segments, 0, -1):
        cuts.append(back[k, cuts[-1]])
    cuts = cuts[::-1]
    return [(int(edges[a]), int(edges[b])) for a, b in itertools.pairwise(cuts)]


def _two_means(values: FloatArray) -> NDArray[np.bool_]:
    """Split values in two groups by one-dimensional two-means; True for the high group."""
    order = np.sort(values)
    best, cut = np.inf, order[0]
    for k in range(1, order.size):
        low, high = order[:k], order[k:]
        spread = float(np.sum((low - low.mean()) ** 2) + np.sum((high - high.mean()) ** 2))
        if spread < best:
            best, cut = spread, 0.5 * (order[k - 1] + order[k])
    high_group: NDArray[np.bool_] = values > cut
    return high_group


#: Fraction of each stage's samples left out at both ends of it before fitting its line:
#: the samples at a contact's edges carry the impact's ringing and the filters' smearing.
TRIM = 0.15


Window = tuple[bool, float, float]


def _windows(x: FloatArray, y: FloatArray, n_segments: int) -> list[Window]:
    """Stages of a branch as (steep?, x_low, x_high), from a segmented fit in n pieces.

    Neighbouring pieces of the same kind are merged; each stage is trimmed by
    ``TRIM`` of its samples at both ends.
    """
    order = np.argsort(x, kind="stable")
    xs, ys = x[order], y[order]
    pieces = _segments(xs, ys, n_segments, BINS)
    slopes = []
    for a, b in pieces:
        dx = xs[a:b] - xs[a:b].mean()
        slopes.append(abs(float(np.dot(dx, ys[a:b]) / max(np.dot(dx, dx), 1e-300))))
    slope_arr = np.array(slopes)
    steep = _two_means(np.log(slope_arr + 1e-12 * max(slope_arr.max(), 1e-300)))
    runs: list[tuple[bool, int, int]] = []
    for kind, (a, b) in zip(steep, pieces, strict=True):
        if runs and runs[-1][0] == kind:
            runs[-1] = (bool(kind), runs[-1][1], b)
        else:
            runs.append((bool(kind), a, b))
    out = []
    for kind, a, b in runs:
        cut = int(TRIM * (b - a))
        out.append((kind, float(xs[a + cut]), float(xs[max(b - 1 - cut, a + cut)])))
    return out


def _is_joint(windows: list[Window]) -> bool:
    """Steep, flat, steep: a free-play stroke between two contacts."""
    return [kind for kind, _, _ in windows] == [True, False, True]


def _weighted_lstsq(design: FloatArray, y: FloatArray, weight: FloatArray | None) -> FloatArray:
    """Least squares by the normal equations (a few columns, many rows: fast and ample)."""
    wd = design if weight is None else design * weight[:, None]
    gram = wd.T @ design
    rhs = wd.T @ y
    try:
        solved = np.linalg.solve(gram, rhs)
    except np.linalg.LinAlgError:
        solved = np.linalg.lstsq(design, y, rcond=None)[0]
    return np.asarray(solved, dtype=np.float64)


def _solve(design: FloatArray, y: FloatArray, iterations: int = 2) -> tuple[FloatArray, float]:
    """Robust least squares (Tukey's biweight, by reweighting); the coefficients and the SSE.

    The samples next to an impact carry the ringing and a velocity the derivative
    filter smears; the biweight gives them no weight once they stand out.
    """
    coef = _weighted_lstsq(design, y, None)
    for _ in range(iterations):
        residual = y - design @ coef
        scale = 1.2533 * float(np.mean(np.abs(residual - residual.mean()))) + 1e-300
        u = residual / (4.685 * scale)
        weight = np.where(np.abs(u) < 1.0, (1.0 - u * u) ** 2, 0.0)
        coef = _weighted_lstsq(design, y, weight)
    residual = y - design @ coef
    return coef, float(np.dot(residual, residual))


def _bic(sse: float, n: int, p: int) -> float:
    return n * math.log(max(sse, 1e-300) / n) + p * math.log(n)


@dataclass(frozen=True)
class _Fit:
    upper_edge: float
    lower_edge: float
    k_compression: float
    k_tension: float
    k_gap: float
    friction: float
    lines: tuple[tuple[float, float], ...] = ()
    level_positive: float = math.nan
    level_negative: float = math.nan
    #: the damper's backlash read on the rising and on the falling branch
    backlash_branches: tuple[float, float] = (math.nan, math.nan)


def _joint_fit(
    x: FloatArray,
    f: FloatArray,
    v: FloatArray,
    parts: tuple[slice, slice],
    windows: tuple[list[Window], list[Window]],
    compete: bool = True,
) -> _Fit | None:
    """The clearance-joint model on both branches of a cycle at once.

    F = a_s + k_s x + c x' + F_f sgn(x') with s the stage (tension, free-play,
    compression: the ``windows`` of each branch, from the segmented fit of all
    steady cycles) and c, F_f shared: the free-play line alone cannot tell drag
    from offset (x' hardly changes there). With ``compete``, a straight-line model
    (no clearance) competes by BIC and wins if it explains the cycle as well.
    """
    rows: list[FloatArray] = []
    stage_of: list[FloatArray] = []
    for part, branch in zip(parts, windows, strict=True):
        if not _is_joint(branch):
            return None
        xb = x[part]
        for label, (_, low, high) in zip(
            (STAGE_TENSION, STAGE_FREE, STAGE_COMPRESSION), branch, strict=True
        ):
            idx = np.nonzero((xb >= low) & (xb <= high))[0] + (part.start or 0)
            rows.append(idx)
            stage_of.append(np.full(idx.size, label))
    index = np.concatenate(rows)
    stage = np.concatenate(stage_of)
    xs, fs, vs = x[index], f[index], v[index]
    columns = []
    for label in (STAGE_TENSION, STAGE_FREE, STAGE_COMPRESSION):
        mask = (stage == label).astype(float)
        columns += [mask, mask * xs]
    design = np.column_stack((*columns, vs, np.sign(vs)))
    if index.size <= design.shape[1] + 2:
        return None
    coef, sse = _solve(design, fs)
    if compete:
        line = np.column_stack((np.ones_like(xs), xs * (xs > 0), xs * (xs <= 0), vs, np.sign(vs)))
        _, sse_line = _solve(line, fs, iterations=0)
        if _bic(sse, index.size, design.shape[1]) >= _bic(sse_line, index.size, line.shape[1]):
            return None
    a_t, k_t, a_f, k_f, a_c, k_c, _, friction = (float(c) for c in coef)
    if not (k_c > k_f and k_t > k_f):
        return None
    upper = (a_f - a_c) / (k_c - k_f)
    lower = (a_f - a_t) / (k_t - k_f)
    lines = ((a_t, k_t), (a_f, k_f), (a_c, k_c))
    return _Fit(upper, lower, k_c, k_t, max(k_f, 0.0), abs(friction), lines)


def _line_fit(x: FloatArray, f: FloatArray, v: FloatArray) -> _Fit:
    """No clearance: F = a + k_c x (x > 0) + k_t x (x <= 0) + c x' + F_f sgn(x')."""
    design = np.column_stack((np.ones_like(x), x * (x > 0), x * (x <= 0), v, np.sign(v)))
    coef, _ = _solve(design, f)
    return _Fit(0.0, 0.0, float(coef[1]), float(coef[2]), 0.0, abs(float(coef[4])))
