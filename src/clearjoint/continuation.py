"""Pseudo-arclength continuation of the solutions of R(u, lambda) = 0 (MODEL.md sec. 5.1).

Generic over the residual: periodic orbits by shooting (``clearjoint.periodic``)
use it, and so can harmonic balance. A branch is followed in scaled coordinates
y = (u / u_scale, lambda / lambda_scale):

- tangent t: the null vector of [dR/du, dR/dlambda], oriented along the last one;
- predictor y + h t + (h^2 / 2) dt/ds, the curvature taken from the last step; after
  n = ``predictor_degree`` ordinary steps in a row with tangents that turn little (and
  before any kink), the polynomial of degree n through the last n + 1 points in chord
  length instead (error ~h^(n + 1), so most corrections converge in one iteration);
- corrector: Newton on R(y) = 0 together with the arclength condition
  t . (y - y_predicted) = 0, so that it passes folds where dR/du is singular;
- step control from the corrector's iteration count: grow after an easy
  correction, shrink after a hard one, halve and retry after a failure or a
  turn of the tangent sharper than ``max_turn`` (that is how the corrector is kept
  from jumping to another branch near a fold). At the smallest step a sharp turn
  is accepted: the branch has a kink there (grazing), which it must cross; with
  ``differs`` given it is recorded in ``Branch.kinks`` (so that it is reported whether
  Newton crosses it or fails on it and a parameter jump does).
- crossing a kink where no arclength step converges (a grazing with impacts, where the
  map has a square-root singularity and Newton fails on it): a natural-parameter step,
  lambda moved by a fixed increment (growing tenfold from ten times the smallest step
  to ``max_kink_jump``), Newton at that fixed lambda from the last point's unknowns
  (then from ``restart``'s guess, e.g. a short transient), accepted only when the
  unknowns moved less than the largest arclength step (else it is another branch); the
  point reached is recorded in ``Branch.kinks`` and the pseudo-arclength continuation
  resumes from it. A jump backwards in lambda (a fold at the kink) is taken only when
  ``differs`` says the point is on another piece of the branch than the last one, and
  not on a piece the branch left at an earlier kink.
- crossing a corner (the residual continuous, its Jacobian not: a sticking onset),
  where the other piece may turn back in lambda (a nonsmooth fold) and no parameter
  jump from the last point finds it: the residual is probed around the last point
  until a probe lands on another piece; that piece's own tangent predicts, the
  arclength corrector solves. If nothing converges the branch stops with the
  reason saying where; if a crossing sends it back along its own path, it stops
  too (``_BACK_POINTS`` points in a row), saying so.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.jit import njit  # numba.njit that survives a read-only install
from clearjoint.progress import report

__all__ = [
    "Branch",
    "ContinuationError",
    "ContinuationSettings",
    "Residual",
    "continue_branch",
    "extrapolate",
    "parameter_range",
    "tangent_solve",
]

FloatArray = NDArray[np.float64]

#: residual(u, lam) -> (R (d,), dR/du (d, d), dR/dlam (d,), data for the caller)
Residual = Callable[[FloatArray, float], tuple[FloatArray, FloatArray, FloatArray, Any]]
#: restart(u, lam) -> a fresh guess of the unknowns at lam (None: none), used at a kink
Restart = Callable[[FloatArray, float], FloatArray | None]
#: differs(data_last, data_new) -> True when the two points lie on different smooth pieces
Differs = Callable[[Any, Any], bool]
#: equivalents(u) -> other coordinates of the same solution (e.g. across a jump at the section)
Equivalents = Callable[[FloatArray], list[FloatArray]]


#: ... and while the last tangents turned by less than arccos of this between points.
_POLY_ALIGN = math.cos(0.1)

#: Scaled distance within which a branch has reached the ``join`` point of another.
_JOIN_DISTANCE = 1e-3

#: A step of at most this many smallest steps counts towards ``crawl_points``.
_CRAWL_STEPS = 100.0

#: Points in a row running back along the branch's own path after which it stops.
_BACK_POINTS = 5


class ContinuationError(ClearjointError, RuntimeError):
    """The continuation could not start or could not go on."""


@dataclass(frozen=True)
class ContinuationSettings:
    """Step control of the pseudo-arclength continuation (lengths in scaled coordinates).

    Attributes
    ----------
    step, min_step, max_step : float
        First, smallest and largest arclength step.
    max_points : int
        Points on the branch at most.
    tolerance : float
        Converged when every scaled residual component is below it.
    max_iterations : int
        Corrector iterations per attempt.
    easy, hard : int
        The step grows by ``growth`` after at most ``easy`` iterations and shrinks
        by ``1 / growth`` after at least ``hard``.
    growth : float
    max_turn : float
        Largest angle between successive tangents, rad, before the step is cut.
    max_kink_jump : float
        Largest natural-parameter step (scaled lambda) tried to cross a kink
        where the arclength step fell below ``min_step``; 0 turns that off.
    chord_parameter : bool
        Ask for dR/dlambda only at the first corrector iteration of each step and
        keep it (a chord in that one column): the residual is then called as
        ``residual(u, lam, False)`` after the first iteration and may return None
        for dR/dlambda. Worth it when that derivative costs a second evaluation.
    predictor_degree : int
        Degree of the polynomial predictor through the last points, used after as
        many ordinary steps in a row (3: a cubic through four points).
    crawl_points : int
        After this many points in a row reached by steps of at most 100 smallest
        steps (the branch crawls towards a singular point), the natural-parameter
        jump across a kink is tried at once; if it finds nothing the branch goes on
        crawling. 0 (the default) never tries it early.
    """

    step: float = 0.01
    min_step: float = 1e-6
    max_step: float = 0.05
    max_points: int = 2000
    tolerance: float = 1e-11
    max_iterations: int = 8
    easy: int = 2
    hard: int = 5
    growth: float = 1.5
    max_turn: float = 0.3
    max_kink_jump: float = 1e-4
    chord_parameter: bool = False
    predictor_degree: int = 3
    crawl_points: int = 0

    def __post_init__(self) -> None:
        if not 0.0 < self.min_step <= self.step <= self.max_step:
            raise ParameterError(
                "the steps must satisfy 0 < min_step <= step <= max_step, got "
                f"{self.min_step!r}, {self.step!r}, {self.max_step!r}"
            )
        if isinstance(self.predictor_degree, bool) or not (
            isinstance(self.predictor_degree, int) and self.predictor_degree >= 1
        ):
            raise ParameterError(
                f"predictor_degree must be an integer >= 1, got {self.predictor_degree!r}"
            )
        if self.max_points < 2:
            raise ParameterError(f"max_points must be >= 2, got {self.max_points!r}")


@dataclass(frozen=True)
class Branch:
    """A followed branch: unknowns, parameter, tangents and the residual's data per point.

    Attributes
    ----------
    u : (n, d) ndarray
        Unknowns at each point.
    lam : (n,) ndarray
        Continuation parameter at each point.
    tangent : (n, d + 1) ndarray
        Unit tangents in scaled coordinates (last component: the parameter's).
    iterations : (n,) ndarray of int
        Corrector iterations each point took.
    data : list
        What the residual returned as data at each converged point.
    reason : str
        Why it stopped: "reached" (the last point is ``lam_stop`` itself), "passed
        the end of the range ...: the branch ends at lambda = ..." (a step went
        past ``lam_stop`` but no point converged on it), "max_points", "left the
        range", "step too small at lambda = ...: ..." (no step converged, the kink
        jump included),
        or "ran back along its own path from lambda = ...: ..." (a kink crossing
        led back onto the branch already followed; those points are dropped),
        or "joined" (it reached the ``join`` point).
    kinks : (k,) ndarray of int
        Indices of the points reached by a natural-parameter jump across a kink,
        or (with ``differs`` given) by an arclength step at the smallest step that
        turned sharper than ``max_turn`` (the kink lies between point i - 1 and
        point i).
    """

    u: FloatArray
    lam: FloatArray
    tangent: FloatArray
    iterations: NDArray[np.int64]
    data: list[Any] = field(repr=False)
    reason: str
    kinks: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))


@njit(cache=True)
def _solve(a: FloatArray, b: FloatArray) -> FloatArray:
    """np.linalg.solve compiled: the systems are tiny and called thousands of times."""
    x: FloatArray = np.asarray(np.linalg.solve(a, b), dtype=np.float64)
    return x


@njit(cache=True)
def _gauss(m: FloatArray) -> bool:
    """Solve the square system held in ``m`` = [A | b] in place (partial pivoting).

    On success the last column holds x; False when a pivot is zero or not finite.
    """
    n = m.shape[0]
    for col in range(n):
        pivot = col
        for row in range(col + 1, n):
            if abs(m[row, col]) > abs(m[pivot, col]):
                pivot = row
        if m[pivot, col] == 0.0 or not np.isfinite(m[pivot, col]):
            return False
        if pivot != col:
            for j in range(n + 1):
                m[col, j], m[pivot, j] = m[pivot, j], m[col, j]
        for row in range(col + 1, n):
            f = m[row, col] / m[col, col]
            for j in range(col, n + 1):
                m[row, j] -= f * m[col, j]
    for i in range(n - 1, -1, -1):
        s = m[i, n]
        for j in range(i + 1, n):
            s -= m[i, j] * m[j, n]
        m[i, n] = s / m[i, i]
    return True


@njit(cache=True)
def tangent_solve(a: FloatArray, previous: FloatArray, t: FloatArray) -> bool:
    """Return whether the unit tangent t solving [a; previous] t = e_last was found (t filled).

    Shared by this module and the shooting solver's compiled arclength step
    (``clearjoint.simulate._shooting``); False when the system is singular.
    """
    d = a.shape[0]
    m = np.zeros((d + 1, d + 2))
    for i in range(d):  # loops, not slices: a slice assignment compiles numba's shape-error text
        for j in range(d + 1):
            m[i, j] = a[i, j]
    for j in range(d + 1):
        m[d, j] = previous[j]
    m[d, d + 1] = 1.0
    if not _gauss(m):
        return False
    norm = 0.0
    for i in range(d + 1):
        t[i] = m[i, d + 1]
        norm += t[i] * t[i]
    norm = math.sqrt(norm)
    if not (norm > 0.0 and math.isfinite(norm)):
        return False
    for i in range(d + 1):
        t[i] /= norm
    return True


def _tangent(a: Any, previous: FloatArray) -> FloatArray:
    """Unit null vector of the (d, d+1) matrix ``a``, oriented along ``previous``.

    ``a`` is dense, or a scipy sparse matrix when a residual's own corrector returns
    one (a structure's harmonic balance): then :func:`_sparse_tangent`.
    """
    if not isinstance(a, np.ndarray):
        return _sparse_tangent(a, previous)
    t = np.empty(a.shape[1])
    if not _compiled_tangent_solve(np.ascontiguousarray(a, dtype=np.float64), previous, t):
        _, _, vt = np.linalg.svd(a)
        t = vt[-1] / np.linalg.norm(vt[-1])
    unit: FloatArray = np.asarray(t, dtype=np.float64)
    return unit if float(unit @ previous) >= 0.0 else np.asarray(-unit, dtype=np.float64)


def _sparse_tangent(a: Any, previous: FloatArray) -> FloatArray:
    """:func:`_tangent` for a scipy sparse ``a``: [a; previous] t = e_last by a sparse LU.

    The same bordered system as the dense route, solved by block elimination on the
    sparse LU of dR/du alone, its column ordering reused along the branch
    (:func:`clearjoint.bordered.bordered_solve`); where that fails, a sparse LU of the
    whole bordered matrix, and a singular one falls back to the dense SVD, as there.
    """
    import scipy.sparse
    import scipy.sparse.linalg

    from clearjoint.bordered import bordered_solve

    d = a.shape[0]
    rhs = np.zeros(d + 1)
    rhs[d] = 1.0
    t: FloatArray | None = None
    columns = scipy.sparse.csc_matrix(a)
    try:
        solved = bordered_solve(
            columns[:, :d],
            columns[:, d].toarray().ravel(),
            previous[:d],
            float(previous[d]),
            rhs[:d],
            1.0,
        )
    except RuntimeError:  # dR/du singular: the whole bordered matrix instead
        try:
            matrix = scipy.sparse.vstack(
                (a, scipy.sparse.csr_matrix(previous[None, :])), format="csc"
            )
            solved = np.asarray(scipy.sparse.linalg.splu(matrix).solve(rhs), dtype=np.float64)
        except RuntimeError:  # "Factor is exactly singular"
            solved = np.zeros(0)
    norm = float(np.linalg.norm(solved))
    if solved.size and norm > 0.0 and math.isfinite(norm):
        t = solved / norm
    if t is None:
        _, _, vt = np.linalg.svd(a.toarray())
        t = vt[-1] / np.linalg.norm(vt[-1])
    unit: FloatArray = np.asarray(t, dtype=np.float64)
    return unit if float(unit @ previous) >= 0.0 else np.asarray(-unit, dtype=np.float64)


def _correct(
    residual: Residual,
    y0: FloatArray,
    tangent: FloatArray,
    scale: FloatArray,
    settings: ContinuationSettings,
    fixed_lambda: bool,
) -> tuple[FloatArray, FloatArray, Any, int] | None:
    """Newton on [R(y); t . (y - y0)] = 0 (or on R at fixed lambda); None if it fails.

    A residual that carries a ``corrector(y0, tangent, scale, settings, fixed_lambda)``
    method doing this same correction (compiled, say) is handed the work when
    ``settings.chord_parameter`` is set.
    """
    fast = getattr(residual, "corrector", None)
    if fast is not None and settings.chord_parameter:
        result: tuple[FloatArray, FloatArray, Any, int] | None = fast(
            y0, tangent, scale, settings, fixed_lambda
        )
        return result
    y = y0.copy()
    d = y.size - 1
    u_scale = scale[:d]
    system = np.empty((d + 1, d + 1))
    if fixed_lambda:
        system[d, :d] = 0.0
        system[d, d] = 1.0
    else:
        system[d] = tangent
    rhs = np.empty(d + 1)
    for iteration in range(settings.max_iterations + 1):
        try:
            if settings.chord_parameter and iteration > 0:
                r, jac_u, _, data = residual(  # type: ignore[call-arg]
                    y[:d] * u_scale, float(y[d] * scale[d]), False
                )
            else:
                r, jac_u, r_lam, data = residual(y[:d] * u_scale, float(y[d] * scale[d]))
                system[:d, d] = r_lam * (scale[d] / u_scale)
        except ClearjointError:
            return None
        # rows scaled by the unknowns' sizes, columns by the scaled unknowns
        system[:d, :d] = jac_u * (u_scale / u_scale[:, None])
        rs = r / u_scale
        size = float(np.max(np.abs(rs)))
        if not math.isfinite(size) or not math.isfinite(float(system.sum())):
            return None
        if size <= settings.tolerance:
            return y, system[:d].copy(), data, iteration
        if iteration == settings.max_iterations:
            return None
        rhs[:d] = -rs
        rhs[d] = 0.0 if fixed_lambda else -float(tangent @ (y - y0))
        try:
            dy = _solve(system, rhs)
        except np.linalg.LinAlgError:
            return None
        y = y + dy
    return None


def continue_branch(
    residual: Residual,
    u0: FloatArray,
    lam0: float,
    lam_stop: float,
    *,
    u_scale: FloatArray,
    lam_scale: float,
    settings: ContinuationSettings | None = None,
    restart: Restart | None = None,
    differs: Differs | None = None,
    equivalents: Equivalents | None = None,
    join: tuple[FloatArray, float, Any] | None = None,
) -> Branch:
    """Follow R(u, lambda) = 0 from (u0, lam0) until lambda reaches ``lam_stop``.

    Parameters
    ----------
    residual : callable
        residual(u, lam) -> (R (d,), dR/du (d, d), dR/dlam (d,), data). With
        ``settings.chord_parameter`` it may carry compiled versions of the work:
        ``corrector`` (see ``_correct``) and ``step(points (k, d + 1), h, t,
        curvature, scale, settings)``, the ordinary step (the predictor from the
        last k points, or from the last one with ``t`` and ``curvature`` when k = 1,
        the correction and the new unit tangent oriented along ``t``), returning
        ((y, a, data, iterations), tangent) or None, as the Python steps here do.
    u0 : (d,) ndarray
        A solution, or a guess close to one, at ``lam0`` (corrected there first).
    lam0, lam_stop : float
        Start and end of the parameter range.
    u_scale : (d,) ndarray
        Typical sizes of the unknowns (the residual is scaled by them too).
    lam_scale : float
        Typical size of a change of the parameter.
    settings : ContinuationSettings, optional
    restart : callable, optional
        restart(u, lam) -> a guess of the unknowns at ``lam`` (or None), tried at a
        kink when Newton from the last point's unknowns fails.
    differs : callable, optional
        differs(data_last, data_new) -> bool: the two points lie on different
        smooth pieces. Needed for a backward jump at a kink; without it only
        forward jumps are tried.
    equivalents : callable, optional
        equivalents(u) -> other unknowns that describe the same solution as ``u``
        (a state on a jump of the section: before and after an impact); at a
        kink Newton starts from them too, and a point near one of them counts as
        near the last point.
    join : (u (d,), lam, data), optional
        A point of another branch (where that one stopped): the continuation stops
        with reason "joined" on reaching it (within ``_JOIN_DISTANCE`` in scaled
        coordinates, on the same smooth piece by ``differs``).

    Returns
    -------
    Branch

    Raises
    ------
    ContinuationError
        No solution at ``lam0`` near ``u0``.
    """
    settings = settings or ContinuationSettings()
    u0 = np.asarray(u0, dtype=np.float64)
    d = u0.size
    scale = np.concatenate((np.asarray(u_scale, dtype=np.float64), [float(lam_scale)]))
    direction = 1.0 if lam_stop > lam0 else -1.0
    y = np.concatenate((u0, [lam0])) / scale
    target = None if join is None else np.concatenate((join[0], [join[1]])) / scale

    def joined(point: FloatArray, point_data: Any) -> bool:
        if target is None or join is None:
            return False
        same = differs is None or not differs(join[2], point_data)
        return same and float(np.linalg.norm(point - target)) <= _JOIN_DISTANCE

    t = np.zeros(d + 1)
    t[-1] = direction
    first = _correct(residual, y, t, scale, settings, fixed_lambda=True)
    if first is None:
        raise ContinuationError(
            f"no solution near the start at parameter {lam0!r}; give a better starting guess"
        )
    y, a, data, its = first
    t = _tangent(a, t)
    ys, ts, datas, iters = [y], [t], [data], [its]
    trail = np.empty((settings.max_points + 1, d + 1))  # ys as rows, for the predictor
    trail[0] = y
    h = settings.step
    stop = lam_stop / scale[-1]
    reason = "max_points"
    kinks: list[int] = []
    curvature = np.zeros_like(t)  # d(tangent)/ds from the last step: a second-order predictor
    back_steps = 0  # points in a row that run back along the branch's own path
    smooth = 0  # points in a row reached by an ordinary arclength step (no kink, no retry)
    aligned = 0  # ... of which the last ones whose tangent turned by less than _POLY_ALIGN
    retry = False  # the last attempt failed: predict from the tangent and curvature only
    # a residual may carry its ordinary step compiled: step(points, h, t, curvature, scale,
    # settings) -> ((y, a, data, its), tangent) or None, predicting as below from ``points``
    fast_step = getattr(residual, "step", None) if settings.chord_parameter else None
    crawl = 0  # points in a row reached by steps of at most _CRAWL_STEPS smallest steps
    while len(ys) < settings.max_points:
        poly = (
            smooth >= settings.predictor_degree
            and not retry
            and not kinks  # past a kink the pieces lie close: keep the cautious predictor
            and aligned
            >= settings.predictor_degree  # the last tangents turned little between points
        )
        fast_tangent: FloatArray | None = None
        if fast_step is not None:
            # predictor, corrector and tangent in one call (the same arithmetic compiled)
            points = (
                trail[len(ys) - settings.predictor_degree - 1 : len(ys)] if poly else y[None, :]
            )
            stepped = fast_step(points, h, t, curvature, scale, settings)
            attempt, fast_tangent = (None, None) if stepped is None else stepped
        else:
            if poly:
                predicted = _compiled_extrapolate(
                    trail[len(ys) - settings.predictor_degree - 1 : len(ys)], h
                )
            else:
                predicted = y + h * t + 0.5 * h * h * curvature
            attempt = _correct(residual, predicted, t, scale, settings, fixed_lambda=False)
        if poly and (attempt is None or (differs is not None and differs(datas[-1], attempt[2]))):
            # near a kink the polynomial may reach across it: the same step again, predicted
            # from the tangent and curvature (the ordinary way, with its step control)
            retry = True
            continue
        if attempt is not None:
            y_new, a_new, data_new, its = attempt
            if fast_tangent is not None and math.isfinite(float(fast_tangent[0])):
                t_new = fast_tangent
            else:
                t_new = _tangent(a_new, t)
            cos_turn = float(t_new @ t)
            turn = math.acos(min(1.0, max(-1.0, cos_turn)))
            sharp = turn > settings.max_turn
            if sharp and h > settings.min_step:
                attempt = None
        stuck = attempt is None and h <= settings.min_step
        # crawling: the last ``crawl_points`` steps all accepted at tiny steps (towards a
        # grazing whose square-root singularity no larger step passes): try the jump now
        crawling = not stuck and settings.crawl_points > 0 and crawl >= settings.crawl_points
        if stuck or crawling:
            crawl = 0
            # the way the branch was travelling (the tangent at a kink can point anywhere)
            travel = float(np.sign(y[-1] - ys[-2][-1])) if len(ys) > 1 else 0.0

            def back(found: FloatArray, found_data: Any) -> bool:
                return _retraces(found, found_data, ys, datas, kinks, differs)

            jump = _cross_kink(
                residual,
                y,
                travel or direction,
                datas[-1],
                scale,
                settings,
                stop,
                direction,
                restart,
                differs,
                equivalents,
                back,
            )

            if jump is None and not crawling:
                jump = _other_piece(residual, y, t, datas[-1], scale, settings, differs, back)
            if jump is None and crawling:
                stuck = False  # no jump: go on with the small step that converged
            elif jump is None:
                reason = (
                    f"step too small at lambda = {y[-1] * scale[-1]:.10g}: no arclength step "
                    "converged, nor a parameter jump of up to "
                    f"{settings.max_kink_jump * scale[-1]:.3g}"
                )
                break
        if stuck or (crawling and jump is not None):
            assert jump is not None
            (y_new, a_new, data_new, its), relabelled = jump
            t_new = _tangent(a_new, t)
            if differs is not None and (y_new[-1] - y[-1]) * (travel or direction) < 0.0:
                # a fold at the kink: both pieces may end there, so try which way leads away
                t_new = _away(residual, y, y_new, t_new, data_new, scale, settings, differs)
            elif relabelled:
                # the same orbit written across a jump of the section: keep the way lambda was
                # moving (the tangent at the jump itself can point anywhere)
                if t_new[-1] * (travel or direction) < 0.0:
                    t_new = -t_new
            elif float(t_new @ (y_new - y)) < 0.0:
                t_new = -t_new  # go on away from the kink (at a grazing fold: back in lambda)
            if direction * (y_new[-1] - stop) >= 0.0:
                if direction * (y_new[-1] - stop) == 0.0:
                    reason = "reached"
                    ys.append(y_new)
                    ts.append(t_new)
                    datas.append(data_new)
                    iters.append(its)
                else:
                    reason = _short_of_end(stop * scale[-1], y[-1] * scale[-1])
                break
            if not relabelled:
                kinks.append(len(ys))
            curvature = np.zeros_like(t)
            smooth, aligned, retry = 0, 0, False
            y, t = y_new, t_new
            ys.append(y)
            trail[len(ys) - 1] = y
            ts.append(t)
            datas.append(data_new)
            iters.append(its)
            h = settings.step
            if joined(y, data_new):
                reason = "joined"
                break
            continue
        if attempt is None:
            h = max(0.5 * h, settings.min_step)
            retry = True
            continue
        if direction * (y_new[-1] - stop) >= 0.0:
            # passed the end: land exactly on it, from the last point's side
            frac = (stop - y[-1]) / (y_new[-1] - y[-1])
            guess = y + frac * (y_new - y)
            guess[-1] = stop
            end = _correct(residual, guess, t, scale, settings, fixed_lambda=True)
            if end is not None:
                y_end, a_end, data_end, its_end = end
                ys.append(y_end)
                ts.append(_tangent(a_end, t_new))
                datas.append(data_end)
                iters.append(its_end)
                reason = "reached"
            else:
                reason = _short_of_end(stop * scale[-1], y[-1] * scale[-1])
            break
        if kinks and differs is not None:
            back_steps = (
                back_steps + 1 if _behind(y_new, t_new, data_new, ys, ts, datas, differs) else 0
            )
            if back_steps >= _BACK_POINTS:
                first_back = ys[-_BACK_POINTS + 1] if _BACK_POINTS > 1 else y_new
                reason = (
                    f"ran back along its own path from lambda = {first_back[-1] * scale[-1]:.10g}"
                    f" (after the kink at lambda = {ys[kinks[-1]][-1] * scale[-1]:.10g}): no "
                    "way on past the kinks was found"
                )
                del ys[len(ys) - _BACK_POINTS + 1 :], ts[len(ts) - _BACK_POINTS + 1 :]
                del datas[len(datas) - _BACK_POINTS + 1 :], iters[len(iters) - _BACK_POINTS + 1 :]
                break
        chord = y_new - y
        step_length = math.sqrt(float(chord @ chord))
        curvature = (t_new - t) / step_length if step_length > 0.0 else np.zeros_like(t)
        smooth = 0 if retry else smooth + 1
        aligned = aligned + 1 if cos_turn > _POLY_ALIGN else 0
        crawl = crawl + 1 if h <= _CRAWL_STEPS * settings.min_step else 0
        retry = False
        y, t = y_new, t_new
        if sharp and differs is not None:
            # the sharp turn accepted at the smallest step: a kink (a corner where a stage
            # appears or sticking begins), crossed by the arclength step itself
            kinks.append(len(ys))
        ys.append(y)
        trail[len(ys) - 1] = y
        ts.append(t)
        datas.append(data_new)
        iters.append(its)
        report(direction * (y[-1] * scale[-1] - lam0), abs(lam_stop - lam0))  # for a bar
        if joined(y, data_new):
            reason = "joined"
            break
        if direction * (y[-1] * scale[-1] - lam0) < -abs(lam_scale):
            reason = "left the range"
            break
        if its <= settings.easy:
            h = min(h * settings.growth, settings.max_step)
        elif its >= settings.hard:
            h = max(h / settings.growth, settings.min_step)
    points = np.array(ys) * scale
    return Branch(
        u=points[:, :d],
        lam=points[:, d],
        tangent=np.array(ts),
        iterations=np.array(iters, dtype=np.int64),
        data=datas,
        reason=reason,
        kinks=np.array(kinks, dtype=np.int64),
    )


def _short_of_end(stop: float, last: float) -> str:
    """The stop reason when a step passed ``stop`` but no point converged on it."""
    return (
        f"passed the end of the range (lambda = {stop:.10g}) but no point converged there; "
        f"the branch ends at lambda = {last:.10g}"
    )


@njit(cache=True)
def extrapolate(path: FloatArray, h: float) -> FloatArray:
    """Return the polynomial through the rows of ``path`` (in chord length) at ``h`` past the last.

    Lagrange interpolation in the cumulative chord length s (s = 0 at the last
    row), evaluated at s = h: through the last n points, a predictor whose error
    falls as h^n (h^4 for a cubic through four), against h^3 for the
    tangent-and-curvature one.
    """
    n, m = path.shape
    s = np.zeros(n)
    for i in range(n - 2, -1, -1):
        step = 0.0
        for j in range(m):
            step += (path[i + 1, j] - path[i, j]) ** 2
        s[i] = s[i + 1] - math.sqrt(step)
    out = np.zeros(m)
    for i in range(n):
        weight = 1.0
        for j in range(n):
            if j != i:
                weight *= (h - s[j]) / (s[i] - s[j])
        for k in range(m):
            out[k] += weight * path[i, k]
    return out


#: The old private name, kept for the tests that call it.
_extrapolate = extrapolate


def parameter_range(
    parameter: str,
    force_amplitude: float,
    omega_start: float,
    omega_stop: float | None,
    force_stop: float | None,
) -> tuple[float, float]:
    """Return the (start, stop) of the continuation parameter, checked: positive, nonzero width.

    Shared by shooting (``clearjoint.periodic``) and harmonic balance
    (``clearjoint.harmonic.response``): ``parameter`` "omega" runs omega_start to
    omega_stop (rad/s), "force" runs force_amplitude to force_stop (N).
    """
    if parameter == "omega":
        if omega_stop is None:
            raise ParameterError("omega_stop is required with parameter='omega' (rad/s)")
        w1 = _checks.positive("omega_stop", omega_stop, unit="rad/s")
        if w1 == omega_start:
            raise ParameterError(
                f"the omega range has zero width ({omega_start!r} to {w1!r} rad/s); give two values"
            )
        return omega_start, w1
    if force_stop is None:
        raise ParameterError(
            "force_stop is required with parameter='force': give the end of the force range (N)"
        )
    f1 = _checks.positive("force_stop", force_stop, unit="N")
    if f1 == force_amplitude:
        raise ParameterError(
            f"the force range has zero width ({force_amplitude!r} to {f1!r} N); give two values"
        )
    return force_amplitude, f1


def _behind(
    y_new: FloatArray,
    t_new: FloatArray,
    data_new: Any,
    ys: list[FloatArray],
    ts: list[FloatArray],
    datas: list[Any],
    differs: Differs,
) -> bool:
    """``y_new`` lies on the branch's earlier path, travelled the other way.

    On a chord between two earlier points (not among the last ten) to 1e-2 of
    its length, on the same smooth piece, with a tangent turned by more than 155
    degrees from theirs: the branch runs back along itself (a kink crossing went
    back onto a piece it had followed). Near a fold the two halves of a branch
    part quadratically, so a few points in a row tell the two apart.
    """
    if len(ys) < 12:
        return False
    path = np.array(ys[:-9])
    chords = np.diff(path, axis=0)  # chords[j] = y_j+1 - y_j, j < len(ys) - 10
    lengths = np.einsum("ij,ij->i", chords, chords)
    offsets = y_new - path[:-1]
    where = np.clip(np.einsum("ij,ij->i", offsets, chords) / np.maximum(lengths, 1e-300), 0, 1)
    miss = np.linalg.norm(offsets - where[:, None] * chords, axis=1)
    near = np.nonzero(miss <= 1e-2 * np.sqrt(lengths) + 1e-12)[0]
    return any(
        float(t_new @ ts[int(j)]) < -0.9 and not differs(datas[int(j)], data_new) for j in near
    )


def _away(
    residual: Residual,
    y: FloatArray,
    y_new: FloatArray,
    t_new: FloatArray,
    data_new: Any,
    scale: FloatArray,
    settings: ContinuationSettings,
    differs: Differs,
) -> FloatArray:
    """Orient the tangent at a point reached back in lambda across a kink: away from ``y``.

    A short trial step (100 smallest steps) each way along the new piece; of the
    ways that stay on that piece, the one whose point ends further from ``y`` wins
    (at a grazing fold both pieces end at the grazing, so the way towards ``y`` runs
    back into it). Without such a trial, the tangent points along ``y_new - y``.
    """
    best, far = None, -1.0
    for way in (1.0, -1.0):
        tangent = way * t_new
        trial = y_new + 100.0 * settings.min_step * tangent
        found = _correct(residual, trial, tangent, scale, settings, fixed_lambda=False)
        if found is None or differs(data_new, found[2]):
            continue
        distance = float(np.linalg.norm(found[0] - y))
        if distance > far:
            best, far = tangent, distance
    if best is None:
        best = t_new if float(t_new @ (y_new - y)) >= 0.0 else -t_new
    return np.asarray(best, dtype=np.float64)


def _retraces(
    y_new: FloatArray,
    data_new: Any,
    ys: list[FloatArray],
    datas: list[Any],
    kinks: list[int],
    differs: Differs | None,
) -> bool:
    """A kink crossing that lands back on a piece the branch left earlier.

    True when ``y_new`` lies on the same smooth piece (``differs`` False) as a
    point before the current piece, and nearer to it than that point's larger
    spacing to its neighbours: the branch would run back along itself. The
    current piece is the run of points since the last kink on the last point's
    piece (it may fold back close to itself); a piece left by a smooth change of
    the events (a grazing the arclength step passed) counts as left too.
    """
    if differs is None or len(ys) < 3:
        return False
    # the current piece: the points since the last kink that lie on the last point's piece
    start = len(ys) - 1
    while start > (kinks[-1] if kinks else 0) and not differs(datas[start - 1], datas[-1]):
        start -= 1
    if start < 2:
        return False
    before = np.array(ys[:start])
    gaps = np.linalg.norm(before - y_new, axis=1)
    spacing = np.linalg.norm(np.diff(before, axis=0), axis=1)
    reach = np.maximum(np.append(spacing, 0.0), np.insert(spacing, 0, 0.0))
    return any(not differs(datas[int(j)], data_new) for j in np.nonzero(gaps <= reach)[0])


def _scaled_jacobian(jac_u: FloatArray, r_lam: FloatArray, scale: FloatArray) -> FloatArray:
    """[dR/du, dR/dlam] (d, d + 1) in the scaled coordinates of ``_correct``."""
    d = scale.size - 1
    u_scale = scale[:d]
    a = np.empty((d, d + 1))
    a[:, :d] = jac_u * (u_scale / u_scale[:, None])
    a[:, d] = r_lam * (scale[d] / u_scale)
    return a


def _other_piece(
    residual: Residual,
    y: FloatArray,
    t: FloatArray,
    data: Any,
    scale: FloatArray,
    settings: ContinuationSettings,
    differs: Differs | None,
    back: Callable[[FloatArray, Any], bool],
) -> tuple[tuple[FloatArray, FloatArray, Any, int], bool] | None:
    """Step onto the other smooth piece at a kink where the residual is continuous (C0).

    At a sticking onset (a velocity zero that becomes tangent) the map stays
    continuous but its Jacobian jumps, so the branch has a corner: it goes on
    (persistence) or turns back in lambda (a nonsmooth fold), and neither the
    arclength step nor a natural-parameter jump from the last point finds the
    piece that turns back. Here the residual is probed around the last point
    ``y`` (scaled offsets 1e-6 to 1e-4 along each coordinate) until a probe lands
    on another piece (``differs``); that piece's own tangent, taken both ways,
    predicts the next point, which the arclength corrector then solves for. A
    point is accepted only when it lies on another piece than the last one and
    near its prediction, and not on the way back (``back``). Returns it (with
    False: it is a kink) or None.
    """
    if differs is None:
        return None
    d = y.size - 1
    tried: list[FloatArray] = []
    for size in (1e-6, 1e-5, 1e-4):
        for axis in range(d + 1):
            for sign in (1.0, -1.0):
                probe = y.copy()
                probe[axis] += sign * size
                try:
                    _, jac_u, r_lam, data_probe = residual(
                        probe[:d] * scale[:d], float(probe[d] * scale[d])
                    )
                except ClearjointError:
                    continue
                if not differs(data, data_probe):
                    continue
                a = _scaled_jacobian(jac_u, r_lam, scale)
                if not np.all(np.isfinite(a)):
                    continue
                other = np.linalg.svd(a)[2][-1]
                if any(abs(float(other @ seen)) > 1.0 - 1e-6 for seen in tried):
                    continue  # this piece's tangent was tried already
                tried.append(other)
                # away from the old piece first: the way the last tangent did not come from
                ways = sorted((1.0, -1.0), key=lambda w: float(w * other @ t))
                for way in ways:
                    tangent = way * other
                    h = 10.0 * settings.min_step
                    while h <= settings.max_step * (1.0 + 1e-12):
                        predicted = y + h * tangent
                        found = _correct(
                            residual, predicted, tangent, scale, settings, fixed_lambda=False
                        )
                        if (
                            found is not None
                            and differs(data, found[2])
                            and float(np.linalg.norm(found[0] - predicted)) <= h
                            and not back(found[0], found[2])
                        ):
                            return found, False
                        h *= 10.0
    return None


def _cross_kink(
    residual: Residual,
    y: FloatArray,
    forward: float,
    data: Any,
    scale: FloatArray,
    settings: ContinuationSettings,
    stop: float,
    direction: float,
    restart: Restart | None,
    differs: Differs | None,
    equivalents: Equivalents | None,
    back: Callable[[FloatArray, Any], bool] | None = None,
) -> tuple[tuple[FloatArray, FloatArray, Any, int], bool] | None:
    """A natural-parameter step across a kink: Newton at fixed lambda, smallest jump first.

    Forward (``forward``: +1 or -1, the way lambda was moving) from ten times
    ``min_step`` up to ``max_kink_jump``, tenfold each time, not past ``stop``; then
    backward when ``differs`` is given, accepting only a point on another smooth piece
    than the last one and not on the way back (``back``). Returns the point and
    whether it was reached through an equivalent of the last one (no kink).
    """
    if settings.max_kink_jump <= 0.0:
        return None
    d = y.size - 1
    t = np.zeros(d + 1)  # unused by Newton at fixed lambda
    sides = [forward] if differs is None else [forward, -forward]
    for side in sides:
        jump = 10.0 * settings.min_step
        while jump <= settings.max_kink_jump * (1.0 + 1e-12):
            lam = y[-1] + side * jump
            if side * direction > 0.0 and direction * (lam - stop) > 0.0:
                lam = stop
            last = y[:d] * scale[:d]
            anchors = [last] + (equivalents(last) if equivalents is not None else [])
            tried = 0
            while tried <= len(anchors):
                if tried < len(anchors):
                    u: FloatArray | None = anchors[tried]
                else:  # then from a fresh guess (a short transient, say)
                    u = restart(last, float(lam * scale[-1])) if restart is not None else None
                tried += 1
                if u is None:
                    continue
                start = np.concatenate((np.asarray(u, dtype=np.float64) / scale[:d], [lam]))
                found = _correct(residual, start, t, scale, settings, fixed_lambda=True)
                if found is None:
                    continue
                gaps = [float(np.linalg.norm(found[0][:d] - a / scale[:d])) for a in anchors]
                if min(gaps) > settings.max_step:
                    continue  # further than any arclength step: another branch, not this one
                if side != forward and (
                    not differs(data, found[2])  # type: ignore[misc]
                    or (back is not None and back(found[0], found[2]))
                ):
                    continue
                # near an equivalent of the last point, not the point itself: the same orbit
                # written across a jump of the section, no kink of the branch
                return found, int(np.argmin(gaps)) > 0 and gaps[0] > settings.max_step
            if lam == stop:
                break
            jump *= 10.0
    return None


# for Python callers: the kernel as compiled at install where that is usable
_compiled_tangent_solve = prefer(tangent_solve)
_compiled_extrapolate = prefer(extrapolate)
