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

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

STAGE_FREE, STAGE_COMPRESSION, STAGE_TENSION = 0, 1, -1
BINS = 48


@functools.lru_cache(maxsize=4)
def _pieces(m: int) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Every piece of at least two of ``m`` bins, [i, j): ``numpy.triu_indices(m + 1, k=2)``,
    made once per bin count (read-only)."""
    i, j = np.triu_indices(m + 1, k=2)
    i.flags.writeable = False
    j.flags.writeable = False
    return i, j


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
    i, j = _pieces(m)
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
    #: the per-sample fit's coefficients as fitted (the drag and the signed friction with
    #: them), kept for its residual (:mod:`clearjoint.identify.loopcheck`): a joint's
    #: (a_t, k_t, a_f, k_f, a_c, k_c, c, F_f), a line's (a, k_c, k_t, c, F_f)
    coefficients: tuple[float, ...] = ()


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
    kept = tuple(float(c) for c in coef)
    return _Fit(upper, lower, k_c, k_t, max(k_f, 0.0), abs(friction), lines, coefficients=kept)


def _solve_batch(
    design: FloatArray, y: FloatArray, mask: FloatArray, iterations: int = 2
) -> FloatArray | None:
    """:func:`_solve` for R problems at once: design (R, N, P), y (R, N), mask (R, N) of 0/1
    (the rows each problem has); the coefficients (R, P), or None when a system is singular.

    The same robust least squares (Tukey's biweight, the same scale and iterations) as
    :func:`_solve` on each problem's own rows; rows outside a problem's mask weigh nothing.
    """
    count = mask.sum(axis=1)

    def weighted(weight: FloatArray) -> FloatArray:
        wd = design * weight[:, :, None]
        gram = wd.transpose(0, 2, 1) @ design
        rhs = (wd.transpose(0, 2, 1) @ y[:, :, None])[:, :, 0]
        solved = np.linalg.solve(gram, rhs[:, :, None])[:, :, 0]
        return np.asarray(solved, dtype=np.float64)

    try:
        coef = weighted(mask)
        for _ in range(iterations):
            residual = y - (design @ coef[:, :, None])[:, :, 0]
            centre = (residual * mask).sum(axis=1) / count
            spread = (np.abs(residual - centre[:, None]) * mask).sum(axis=1) / count
            scale = 1.2533 * spread + 1e-300
            u = residual / (4.685 * scale[:, None])
            weight: FloatArray = np.where(np.abs(u) < 1.0, (1.0 - u * u) ** 2, 0.0) * mask
            coef = weighted(weight)
    except np.linalg.LinAlgError:
        return None
    return coef


def _joint_fits(
    x: FloatArray,
    f: FloatArray,
    v: FloatArray,
    parts: tuple[slice, slice],
    windows: tuple[list[Window], list[Window]],
) -> list[_Fit | None] | None:
    """:func:`_joint_fit` (``compete=False``) on every row of x, f, v (R, M) in one batched
    solve: each row's own samples in each stage window, as there. None when the batch
    cannot be solved at once (a singular system: then fit the rows one by one)."""
    if not (_is_joint(windows[0]) and _is_joint(windows[1])):
        return [None] * x.shape[0]
    if any(w[0][2] >= w[1][1] or w[1][2] >= w[2][1] for w in windows):
        return None  # overlapping windows: a sample in two stages, as the row-by-row fit has
    blocks_x, blocks_v, blocks_f, labels = [], [], [], []
    for part, branch in zip(parts, windows, strict=True):
        xb = x[:, part]
        label = np.zeros(xb.shape, dtype=np.int64)  # 0: in no stage's window
        for code, (_, low, high) in enumerate(branch, start=1):  # tension, free, compression
            label[(xb >= low) & (xb <= high)] = code
        blocks_x.append(xb)
        blocks_f.append(f[:, part])
        blocks_v.append(v[:, part])
        labels.append(label)
    xs, fs, vs = np.hstack(blocks_x), np.hstack(blocks_f), np.hstack(blocks_v)
    stage = np.hstack(labels)
    mask = (stage > 0).astype(float)
    columns = []
    for code in (1, 2, 3):
        in_stage = (stage == code).astype(float)
        columns += [in_stage, in_stage * xs]
    design = np.stack((*columns, vs * mask, np.sign(vs) * mask), axis=2)
    coef = _solve_batch(design, fs * mask, mask)
    if coef is None:
        return None
    out: list[_Fit | None] = []
    for row, n_rows in zip(coef, mask.sum(axis=1), strict=True):
        a_t, k_t, a_f, k_f, a_c, k_c, _, friction = (float(c) for c in row)
        if n_rows <= design.shape[2] + 2 or not (k_c > k_f and k_t > k_f):
            out.append(None)
            continue
        lines = ((a_t, k_t), (a_f, k_f), (a_c, k_c))
        out.append(
            _Fit(
                (a_f - a_c) / (k_c - k_f),
                (a_f - a_t) / (k_t - k_f),
                k_c,
                k_t,
                max(k_f, 0.0),
                abs(friction),
                lines,
                coefficients=tuple(float(c) for c in row),
            )
        )
    return out


def _line_fits(x: FloatArray, f: FloatArray, v: FloatArray) -> list[_Fit] | None:
    """:func:`_line_fit` on every row of x, f, v (R, M) in one batched solve (None: singular)."""
    design = np.stack((np.ones_like(x), x * (x > 0), x * (x <= 0), v, np.sign(v)), axis=2)
    coef = _solve_batch(design, f, np.ones_like(x))
    if coef is None:
        return None
    return [
        _Fit(
            0.0,
            0.0,
            float(c[1]),
            float(c[2]),
            0.0,
            abs(float(c[4])),
            coefficients=tuple(float(v) for v in c),
        )
        for c in coef
    ]


def _line_fit(x: FloatArray, f: FloatArray, v: FloatArray) -> _Fit:
    """No clearance: F = a + k_c x (x > 0) + k_t x (x <= 0) + c x' + F_f sgn(x')."""
    design = np.column_stack((np.ones_like(x), x * (x > 0), x * (x <= 0), v, np.sign(v)))
    coef, _ = _solve(design, f)
    kept = tuple(float(c) for c in coef)
    return _Fit(0.0, 0.0, kept[1], kept[2], 0.0, abs(kept[4]), coefficients=kept)
