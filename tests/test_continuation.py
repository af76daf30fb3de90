"""continuation: pseudo-arclength through the two folds of an S-curve with known folds."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint.continuation import (
    ContinuationError,
    ContinuationSettings,
    continue_branch,
)
from clearjoint.errors import ClearjointError, ParameterError


def _s_curve(u: np.ndarray, lam: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """u^3 - u - lambda = 0: folds at u = +-1/sqrt(3), lambda = -+2/(3 sqrt(3))."""
    r = np.array([u[0] ** 3 - u[0] - lam])
    return r, np.array([[3 * u[0] ** 2 - 1.0]]), np.array([-1.0]), float(u[0])


def test_follows_an_s_curve_through_both_folds_without_jumping() -> None:
    branch = continue_branch(
        _s_curve,
        np.array([-1.5]),
        -1.875,
        1.875,
        u_scale=np.array([1.0]),
        lam_scale=1.0,
        settings=ContinuationSettings(step=0.01, max_step=0.05),
    )
    assert branch.reason == "reached"
    assert branch.lam[-1] == pytest.approx(1.875)
    u = branch.u[:, 0]
    # every point solves the equation, and u only grows: the middle branch is followed,
    # never skipped by a jump from one outer branch to the other
    assert np.max(np.abs(u**3 - u - branch.lam)) < 1e-10
    assert np.all(np.diff(u) > 0.0)
    assert np.max(np.diff(u)) < 0.1
    assert u[-1] == pytest.approx(1.5)
    # two folds, where the parameter component of the tangent changes sign
    t = branch.tangent[:, -1]
    folds = np.nonzero(np.sign(t[:-1]) != np.sign(t[1:]))[0]
    assert folds.size == 2
    fold_lam = sorted(float(branch.lam[i]) for i in folds)
    expected = 2.0 / (3.0 * math.sqrt(3.0))
    assert fold_lam[0] == pytest.approx(-expected, abs=5e-3)
    assert fold_lam[1] == pytest.approx(expected, abs=5e-3)


def test_no_solution_at_the_start_is_an_error() -> None:
    def nowhere(u: np.ndarray, lam: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, None]:
        return np.array([u[0] ** 2 + 1.0]), np.array([[2 * u[0]]]), np.array([0.0]), None

    with pytest.raises(ContinuationError, match="no solution near the start"):
        continue_branch(nowhere, np.array([0.3]), 0.0, 1.0, u_scale=np.ones(1), lam_scale=1.0)


def test_settings_are_validated() -> None:
    with pytest.raises(ParameterError, match="min_step <= step <= max_step"):
        ContinuationSettings(step=1.0, max_step=0.1)
    for bad in (0, 2.5, True):
        with pytest.raises(ParameterError, match="predictor_degree must be an integer >= 1"):
            ContinuationSettings(predictor_degree=bad)  # type: ignore[arg-type]


def _corner(u: np.ndarray, lam: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """|u| - lambda = 0: two pieces u = -lambda and u = +lambda meet in a corner at 0."""
    return (
        np.array([abs(u[0]) - lam]),
        np.array([[math.copysign(1.0, u[0])]]),
        np.array([-1.0]),
        u[0],
    )


def _sides(a: float, b: float) -> bool:
    return (a > 0.0) != (b > 0.0)


def test_turns_back_at_a_corner_onto_the_other_piece() -> None:
    # a nonsmooth fold: the residual is continuous, its Jacobian jumps at u = 0; the branch
    # coming down u = -lambda must go on up u = +lambda (no solution exists for lambda < 0)
    settings = ContinuationSettings(step=0.01, max_step=0.05, max_points=80)
    branch = continue_branch(
        _corner,
        np.array([-0.5]),
        0.5,
        -0.5,
        u_scale=np.ones(1),
        lam_scale=1.0,
        settings=settings,
        differs=_sides,
    )
    u, lam = branch.u[:, 0], branch.lam
    assert np.max(np.abs(np.abs(u) - lam)) < 1e-10
    assert branch.kinks.size == 1
    k = int(branch.kinks[0])
    assert np.all(u[:k] < 0.0)
    assert np.all(u[k:] > 0.0)
    assert lam[k - 1] < 1e-5  # it came down to the corner before turning
    assert np.all(np.diff(lam[:k]) < 0.0)
    assert np.all(np.diff(lam[k:]) > 0.0)
    assert lam[-1] > 0.4
    # the parameter-jump crossing alone cannot find the piece that turns back
    stuck = continue_branch(
        _corner,
        np.array([-0.5]),
        0.5,
        -0.5,
        u_scale=np.ones(1),
        lam_scale=1.0,
        settings=settings,
    )
    assert stuck.reason.startswith("step too small")
    assert np.all(stuck.u < 0.0)


def test_cubic_predictor_is_exact_on_a_line_and_fourth_order_on_a_circle() -> None:
    from clearjoint.continuation import _extrapolate

    # a line: chord length is arclength, so the cubic lands exactly h further on
    direction = np.array([0.6, -0.8, 0.0])
    steps = np.array([0.0, 0.013, 0.03, 0.041])  # uneven spacing, as step control gives
    line = np.array([1.0, 2.0, 3.0]) + steps[:, None] * direction
    expected = line[-1] + 0.02 * direction
    assert np.allclose(_extrapolate(line, 0.02), expected, rtol=0.0, atol=1e-13)

    # a circle of radius 1: the miss falls as h^4 when every spacing is halved
    def miss(h: float) -> float:
        angles = np.arange(-3, 2) * h  # four points up to angle 0, then the one to predict
        points = np.stack((np.cos(angles), np.sin(angles), np.zeros(5)), axis=1)
        # the next point is h (in angle) on: its chord from the last is 2 sin(h / 2)
        guess = _extrapolate(points[:4], 2.0 * math.sin(h / 2.0))
        return float(np.linalg.norm(guess - points[4]))

    ratio = miss(0.02) / miss(0.01)
    assert 12.0 < ratio < 20.0  # 2^4 = 16; a quadratic predictor would give 8


def test_a_step_past_the_end_with_no_point_there_is_not_called_reached() -> None:
    # u = lam, but the residual cannot be evaluated within 1e-9 of lam = 1 (as when the
    # exact map fails at the end of the range): a step passes the end, the correction on
    # the end itself fails, and the branch ends short of it
    def fails_at_end(u: np.ndarray, lam: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, None]:
        if abs(lam - 1.0) < 1e-9:
            raise ClearjointError(f"no evaluation at lambda = {lam!r}")
        return np.array([u[0] - lam]), np.array([[1.0]]), np.array([-1.0]), None

    branch = continue_branch(
        fails_at_end,
        np.array([0.0]),
        0.0,
        1.0,
        u_scale=np.ones(1),
        lam_scale=1.0,
        settings=ContinuationSettings(step=0.03, max_step=0.03),
    )
    assert 0.9 < branch.lam[-1] < 1.0
    assert branch.reason.startswith("passed the end of the range (lambda = 1)")
    assert f"ends at lambda = {branch.lam[-1]:.10g}" in branch.reason
    assert np.max(np.abs(branch.u[:, 0] - branch.lam)) < 1e-9


def test_sparse_tangent_is_the_dense_one() -> None:
    """A scipy sparse [dR/du, dR/dlam] (from a residual's own corrector) gets its null
    vector by a sparse LU: the same unit tangent, same orientation, as the dense solve;
    and the null vector it finds is one (a t = 0)."""
    import scipy.sparse

    from clearjoint import continuation as cont

    rng = np.random.default_rng(3)
    a = rng.normal(size=(40, 41)) * (rng.random((40, 41)) < 0.2)
    a[np.arange(40), np.arange(40)] += 5.0
    previous = rng.normal(size=41)
    dense = cont._tangent(a, previous)
    sparse = cont._tangent(scipy.sparse.csr_matrix(a), previous)
    np.testing.assert_allclose(sparse, dense, rtol=0.0, atol=1e-13)
    assert abs(float(np.linalg.norm(sparse)) - 1.0) < 1e-14
    assert float(sparse @ previous) > 0.0
    assert float(np.max(np.abs(a @ sparse))) < 1e-12
    flipped = cont._tangent(scipy.sparse.csr_matrix(a), -previous)
    np.testing.assert_allclose(flipped, -dense, rtol=0.0, atol=1e-13)
