"""Identify a joint from a test record: clearance, contact stiffness, friction, energy per cycle.

MODEL.md section 3. From a :class:`~clearjoint.records.Record` alone (this module
never sees the rig or the simulator):

1. the excitation frequency, from the displacement's spectrum (Hann window,
   parabolic interpolation of the peak);
2. the cycles, cut at the minima of the fundamental, and the steady ones kept by
   an amplitude criterion (amplitude and mean position within ``tolerance`` of the
   plateau's), which drops ramps, start-up transients and ringing;
3. the restoring force: force - m x'' for a force-controlled test (x'' from the
   acceleration channel, or by differentiating the displacement), the measured
   force for a displacement-controlled one;
4. for each cycle and each branch (rising, falling), a segmented least-squares fit
   of force against displacement (dynamic programming over binned data, the
   segment count fixed, segments told apart as steep or flat by two-means on the
   log of their slopes, not by a threshold), then least squares on the raw samples
   of each stage, F = a + k x + c x' (so viscous drag and the impacts' velocity
   jumps do not bend the lines); the gap edges are where the free-play line meets
   each contact line;
5. from them the stages (tension / free-play / compression; the paper's DE, AB/CD,
   BC), the clearance, A_c and A_t, the compression and tension stiffness, the
   friction force, the secant and the period-based dynamic stiffness, and the energy
   per cycle, the loop area of F dx (the inertia term cancels over a closed cycle).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.signal import savgol_filter

from clearjoint import stiffness
from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.joint import Joint
from clearjoint.records import Record

FloatArray = NDArray[np.float64]

#: Quantities measured per cycle and summarised per test (mean and spread).
QUANTITIES = (
    "amplitude_m",
    "clearance_m",
    "compression_stiffness_n_per_m",
    "tension_stiffness_n_per_m",
    "friction_force_n",
    "energy_per_cycle_j",
    "compression_penetration_m",
    "tension_penetration_m",
    "gap_stiffness_n_per_m",
    "secant_stiffness_n_per_m",
    "dynamic_stiffness_n_per_m",
)

STAGE_FREE, STAGE_COMPRESSION, STAGE_TENSION = 0, 1, -1
BINS = 48


class IdentificationError(ClearjointError, ValueError):
    """A record could not be identified; the message says why in one line."""


@dataclass(frozen=True)
class CycleResult:
    """What one kept cycle gives: each of ``QUANTITIES`` (SI), its sample span, its gap edges,
    the model that fitted it ("joint", "damper" or "line") and, for a joint, the elastic
    lines (intercept, slope) of its tension, free-play and compression stages."""

    start: int
    stop: int
    values: dict[str, float]
    upper_edge: float
    lower_edge: float
    model: str
    lines: tuple[tuple[float, float], ...] = ()


@dataclass(frozen=True)
class Identification:
    """The identification of one record: per-cycle values and their summary.

    ``summary[q]`` and ``spread[q]`` are the mean and the standard deviation over
    the kept cycles of each quantity in ``QUANTITIES``.
    """

    source: str
    frequency_hz: float
    cycles_total: int
    cycles: tuple[CycleResult, ...]
    summary: dict[str, float]
    spread: dict[str, float]
    control: str
    restoring_force: FloatArray = field(repr=False)
    stage: NDArray[np.int8] = field(repr=False)

    @property
    def cycles_used(self) -> int:
        return len(self.cycles)

    def row(self) -> dict[str, Any]:
        """One row for results.csv: the summary with a ``_std`` column beside each."""
        out: dict[str, Any] = {
            "file": self.source,
            "frequency_hz": self.frequency_hz,
        }
        for key in QUANTITIES:
            out[key] = self.summary[key]
            out[f"{key}_std"] = self.spread[key]
        out["cycles_used"] = self.cycles_used
        out["cycles_total"] = self.cycles_total
        out["control"] = self.control
        out["model"] = self.model
        return out

    @property
    def model(self) -> str:
        """The loop's model: "joint" (free play between two contacts), "damper" or "line"."""
        return self.cycles[0].model

    def stage_runs(self, time: FloatArray) -> list[tuple[str, float, float]]:
        """The stages as (name, start, end) runs over the record's time, for figures."""
        names = {
            STAGE_FREE: "free-play",
            STAGE_COMPRESSION: "compression",
            STAGE_TENSION: "tension",
        }
        change = np.nonzero(np.diff(self.stage))[0] + 1
        bounds = np.concatenate(([0], change, [self.stage.size]))
        return [
            (names[int(self.stage[a])], float(time[a]), float(time[min(b, time.size - 1)]))
            for a, b in itertools.pairwise(bounds)
        ]


# ---- frequency and cycles -----------------------------------------------------------------


def excitation_frequency(record: Record) -> float:
    """Return the excitation frequency in Hz: the displacement spectrum's peak, interpolated."""
    x = record.displacement - record.displacement.mean()
    n = x.size
    spectrum = np.abs(np.fft.rfft(x * np.hanning(n), n=4 * n))
    spectrum[0] = 0.0
    k = int(np.argmax(spectrum))
    if 0 < k < spectrum.size - 1:
        a, b, c = np.log(spectrum[k - 1 : k + 2] + 1e-300)
        k = k + 0.5 * (a - c) / (a - 2 * b + c) if (a - 2 * b + c) != 0 else k
    return float(k * record.sampling_rate / (4 * n))


def _cycle_bounds(record: Record, frequency: float) -> list[tuple[int, int]]:
    """Cycles from one minimum of the fundamental to the next, as sample index ranges."""
    t = record.time - record.time[0]
    w = 2.0 * math.pi * frequency
    basis = np.column_stack((np.cos(w * t), np.sin(w * t), np.ones_like(t)))
    (a, b, _), *_ = np.linalg.lstsq(basis, record.displacement, rcond=None)
    # a cos + b sin = R cos(w t - phi): minimum where w t - phi = pi
    phi = math.atan2(b, a)
    period = 1.0 / frequency
    first = ((phi + math.pi) / w) % period
    starts = np.arange(first, t[-1], period)
    index = np.searchsorted(t, starts)
    return [(int(i), int(j)) for i, j in itertools.pairwise(index) if j - i >= 16]


def _steady(
    record: Record, bounds: list[tuple[int, int]], tolerance: float
) -> list[tuple[int, int]]:
    """The cycles whose amplitude and mean position sit on the plateau (ramps dropped)."""
    x = record.displacement
    amp = np.array([0.5 * np.ptp(x[i:j]) for i, j in bounds])
    mid = np.array([0.5 * (x[i:j].max() + x[i:j].min()) for i, j in bounds])
    if amp.size == 0:
        return []
    top = amp >= 0.9 * amp.max()
    reference = float(np.median(amp[top]))
    centre = float(np.median(mid[top]))
    keep = (np.abs(amp - reference) <= tolerance * reference) & (
        np.abs(mid - centre) <= tolerance * reference
    )
    return [b for b, k in zip(bounds, keep, strict=True) if k]


# ---- derivatives and the restoring force --------------------------------------------------


def _derivatives(record: Record, frequency: float) -> tuple[FloatArray, FloatArray]:
    """Velocity and acceleration: measured where the record has them, else Savitzky-Golay."""
    dt = 1.0 / record.sampling_rate
    window = max(5, int(record.sampling_rate / frequency / 40) | 1)
    window = min(window, (record.time.size // 2) * 2 - 1)
    velocity = record.velocity
    if velocity is None:
        velocity = savgol_filter(record.displacement, window, 3, deriv=1, delta=dt)
    acceleration = record.acceleration
    if acceleration is None:
        acceleration = savgol_filter(record.displacement, window, 3, deriv=2, delta=dt)
    return velocity, acceleration


def restoring_force(record: Record, acceleration: FloatArray) -> FloatArray:
    """Force minus m x'' (force control, MODEL.md sec. 3) or the measured force."""
    if record.control == "displacement" or not record.mass:
        return record.force
    return record.force - record.mass * acceleration


# ---- segmented least squares --------------------------------------------------------------


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


def _damper_fit(x: FloatArray, f: FloatArray, parts: tuple[slice, slice]) -> _Fit | None:
    """A friction damper with backlash (e.g. the BRFD): per branch, along the travel,
    elastic unloading, backlash (force near zero), elastic loading, slip plateau.

    The plateau's level is the median force over the second half of the travel (the
    friction force). Before the force first reaches it, a three-piece segmented fit
    finds the unloading, the backlash and the loading; the backlash's ends are where
    its line meets theirs, and the two elastic slopes are the contact stiffnesses.
    """
    uppers: list[float] = []
    lowers: list[float] = []
    k_pos: list[float] = []
    k_neg: list[float] = []
    levels: list[float] = []
    for part in parts:
        xb, fb = x[part], f[part]
        travel = np.abs(xb - xb[0])
        level = float(np.median(fb[travel >= 0.5 * travel[-1]]))
        reached = np.nonzero(np.sign(level) * (fb - level) >= 0.0)[0]
        if level == 0.0 or reached.size == 0 or reached[0] < 12:
            return None
        xa, fa = xb[: reached[0] + 1], fb[: reached[0] + 1]
        backlash = _backlash_pieces(xa, fa)
        if backlash is None:
            return None
        xs, pieces, lines = backlash
        (a1, k1), (a0, k0), (a2, k2) = lines
        e1, e2 = (a0 - a1) / (k1 - k0), (a0 - a2) / (k2 - k0)
        uppers.append(max(e1, e2))
        lowers.append(min(e1, e2))
        levels.append(abs(level))
        for intercept, k, (lo, hi) in ((a1, k1, pieces[0]), (a2, k2, pieces[2])):
            mean_force = intercept + k * float(np.mean(xs[lo:hi]))
            (k_pos if mean_force > 0 else k_neg).append(k)
    if not k_pos or not k_neg:
        return None
    return _Fit(
        float(np.mean(uppers)),
        float(np.mean(lowers)),
        float(np.mean(k_pos)),
        float(np.mean(k_neg)),
        0.0,
        float(np.mean(levels)),
    )


def _backlash_pieces(
    xa: FloatArray, fa: FloatArray
) -> tuple[FloatArray, list[tuple[int, int]], list[tuple[float, float]]] | None:
    """Unloading, backlash and loading from the start of a branch, by a segmented fit.

    Three pieces first; if the middle one is not the flattest (ringing at the plateau's
    start can bend the loading piece), four, keeping the three nearest the reversal.
    Returns (x sorted, the three pieces in x order, their (intercept, slope)).
    """
    order = np.argsort(xa, kind="stable")
    xs, fs = xa[order], fa[order]
    rising = bool(xa[-1] > xa[0])  # travel from the reversal goes up in x
    for n in (3, 4):
        pieces = _segments(xs, fs, n, BINS)
        pieces = pieces[:3] if rising else pieces[-3:]
        if any(b - a < 3 for a, b in pieces):
            continue
        lines = []
        for a, b in pieces:
            k, c = np.polyfit(xs[a:b], fs[a:b], 1)
            lines.append((float(c), float(k)))
        if min(abs(lines[0][1]), abs(lines[2][1])) > abs(lines[1][1]):
            return xs, pieces, lines
    return None


def _line_fit(x: FloatArray, f: FloatArray, v: FloatArray) -> _Fit:
    """No clearance: F = a + k_c x (x > 0) + k_t x (x <= 0) + c x' + F_f sgn(x')."""
    design = np.column_stack((np.ones_like(x), x * (x > 0), x * (x <= 0), v, np.sign(v)))
    coef, _ = _solve(design, f)
    return _Fit(0.0, 0.0, float(coef[1]), float(coef[2]), 0.0, abs(float(coef[4])))


# ---- one cycle, one record ----------------------------------------------------------------


def _branches(x: FloatArray) -> tuple[slice, slice] | None:
    """The rising and the falling branch of one cycle (it starts near a minimum)."""
    top = int(np.argmax(x))
    if top < 8 or x.size - top < 8:
        return None
    return slice(0, top + 1), slice(top, x.size)


def _cycle(
    record: Record,
    start: int,
    stop: int,
    force: FloatArray,
    velocity: FloatArray,
    windows: tuple[list[Window], list[Window]],
) -> CycleResult | None:
    x = record.displacement[start:stop]
    f = force[start:stop]
    v = velocity[start:stop]
    parts = _branches(x)
    if parts is None:
        return None
    # a clearance joint's branch has three stages, a friction damper's four; whether
    # the joint's stages beat a straight line was settled once, on the first cycle
    fit, kind = _joint_fit(x, f, v, parts, windows, compete=False), "joint"
    if fit is None:
        fit, kind = _damper_fit(x, f, parts), "damper"
    if fit is None:
        fit, kind = _line_fit(x, f, v), "line"
    x_max, x_min = float(x.max()), float(x.min())
    closed_x = np.append(x, x[0])
    closed_f = np.append(record.force[start:stop], record.force[start])
    energy = abs(float(np.trapezoid(closed_f, closed_x)))
    ends = [int(np.argmax(x)), int(np.argmin(x))]
    f_ends = [float(np.mean(f[max(i - 2, 0) : i + 3])) for i in ends]
    clearance = fit.upper_edge - fit.lower_edge
    a_c, a_t = x_max - fit.upper_edge, fit.lower_edge - x_min
    k0 = fit.k_gap
    dynamic = math.nan
    if record.mass and fit.k_compression > k0 and fit.k_tension > k0 and a_c > 0:
        try:
            joint = Joint(
                mass=record.mass,
                clearance=clearance,
                compression_stiffness=fit.k_compression - k0,
                tension_stiffness=fit.k_tension - k0,
                gap_stiffness=k0,
            )
            dynamic = float(stiffness.dynamic_stiffness(joint, a_c))
        except ParameterError:
            dynamic = math.nan
    values = {
        "amplitude_m": 0.5 * (x_max - x_min),
        "clearance_m": clearance,
        "compression_stiffness_n_per_m": fit.k_compression,
        "tension_stiffness_n_per_m": fit.k_tension,
        "friction_force_n": fit.friction,
        "energy_per_cycle_j": energy,
        "compression_penetration_m": a_c,
        "tension_penetration_m": a_t,
        "gap_stiffness_n_per_m": k0,
        "secant_stiffness_n_per_m": (f_ends[0] - f_ends[1]) / (x_max - x_min),
        "dynamic_stiffness_n_per_m": dynamic,
    }
    return CycleResult(start, stop, values, fit.upper_edge, fit.lower_edge, kind, fit.lines)


def _pooled_windows(
    x: FloatArray, force: FloatArray, cycles: list[tuple[int, int]]
) -> tuple[list[Window], list[Window]]:
    """The stages of the rising and of the falling branch, from all steady cycles together.

    The steady cycles repeat one loop, so one segmented fit of their pooled samples
    places the stages more surely than a fit per cycle; each cycle's own values then
    come from least squares on its own samples inside those stages.
    """
    pooled: list[tuple[list[FloatArray], list[FloatArray]]] = [([], []), ([], [])]
    for i, j in cycles:
        parts = _branches(x[i:j])
        if parts is None:
            continue
        for store, part in zip(pooled, parts, strict=True):
            store[0].append(x[i:j][part])
            store[1].append(force[i:j][part])
    if not pooled[0][0]:
        return [], []
    rising, falling = (_windows(np.concatenate(xs), np.concatenate(fs), 3) for xs, fs in pooled)
    return rising, falling


def _consistent(cycles: list[CycleResult]) -> list[CycleResult]:
    """The cycles fitted with the record's majority model, without outliers in clearance.

    A cycle whose segmented fit found other stages than most (ringing can hide a
    stage) or whose clearance is more than five scaled MADs from the median is a
    failed fit, not a measurement: it is dropped, and not counted as used.
    """
    if not cycles:
        return []
    models = [c.model for c in cycles]
    majority = max(set(models), key=models.count)
    same = [c for c in cycles if c.model == majority]
    gaps = np.array([c.values["clearance_m"] for c in same])
    centre = float(np.median(gaps))
    mad = 1.4826 * float(np.median(np.abs(gaps - centre)))
    if len(same) < 5 or mad == 0.0:
        return same  # too few cycles to call one an outlier
    return [c for c, g in zip(same, gaps, strict=True) if abs(g - centre) <= 5.0 * mad]


def identify(record: Record, *, tolerance: float = 0.03) -> Identification:
    """Return the identification of one record (see the module's docstring for the steps).

    Raises
    ------
    IdentificationError
        Fewer than three steady cycles, or no cycle shows a free-play stroke between
        two contacts; the message says which.
    """
    where = record.source or "record"
    frequency = excitation_frequency(record)
    if record.frequency_hz and abs(frequency / record.frequency_hz - 1.0) > 0.05:
        raise IdentificationError(
            f"{where}: the displacement's frequency is {frequency:.4g} Hz, not the nominal "
            f"{record.frequency_hz:g} Hz; check the record"
        )
    bounds = _cycle_bounds(record, frequency)
    steady = _steady(record, bounds, tolerance)
    if len(steady) < 3:
        raise IdentificationError(
            f"{where}: only {len(steady)} steady cycles of {len(bounds)} (amplitude within "
            f"{tolerance:.0%} of its plateau); a record needs at least 3"
        )
    velocity, acceleration = _derivatives(record, frequency)
    force = restoring_force(record, acceleration)
    windows = _pooled_windows(record.displacement, force, steady)
    first_x = record.displacement[steady[0][0] : steady[0][1]]
    first = _branches(first_x)
    if (
        first is not None
        and _joint_fit(
            first_x,
            force[steady[0][0] : steady[0][1]],
            velocity[steady[0][0] : steady[0][1]],
            first,
            windows,
        )
        is None
    ):
        windows = ([], [])  # no free play worth the name: not a clearance joint
    fitted = [c for c in (_cycle(record, i, j, force, velocity, windows) for i, j in steady) if c]
    cycles = _consistent(fitted)
    if len(cycles) < 2:
        raise IdentificationError(
            f"{where}: only {len(cycles)} of {len(steady)} steady cycles could be fitted "
            "consistently; the loop has no recognisable stages"
        )
    table = {key: np.array([c.values[key] for c in cycles]) for key in QUANTITIES}
    summary = {
        key: float(np.nanmean(val)) if np.any(np.isfinite(val)) else math.nan
        for key, val in table.items()
    }
    spread = {
        key: float(np.nanstd(val)) if np.sum(np.isfinite(val)) > 1 else math.nan
        for key, val in table.items()
    }
    stage = np.zeros(record.time.size, dtype=np.int8)
    upper = float(np.mean([c.upper_edge for c in cycles]))
    lower = float(np.mean([c.lower_edge for c in cycles]))
    stage[record.displacement >= upper] = STAGE_COMPRESSION
    stage[record.displacement <= lower] = STAGE_TENSION
    return Identification(
        source=where,
        frequency_hz=frequency,
        cycles_total=len(bounds),
        cycles=tuple(cycles),
        summary=summary,
        spread=spread,
        control=record.control,
        restoring_force=force,
        stage=stage,
    )


def identify_files(
    paths: list[str],
    *,
    resample: bool = False,
    tolerance: float = 0.03,
    progress: Any = None,
) -> tuple[list[tuple[Record, Identification]], list[str]]:
    """Identify every file; return the results and one line for each file not used.

    ``progress(done, total)`` is called after each file.
    """
    from clearjoint.records import read_record

    results: list[tuple[Record, Identification]] = []
    failures: list[str] = []
    for n, path in enumerate(paths, start=1):
        try:
            record = read_record(path, resample=resample)
            results.append((record, identify(record, tolerance=tolerance)))
        except ClearjointError as exc:
            text = str(exc)
            failures.append(text if text.startswith(str(path)) else f"{path}: {text}")
        if progress:
            progress(n, len(paths))
    return results, failures
