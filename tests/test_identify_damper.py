"""The damper estimator's helpers against numpy's own routines (independent of the fit)."""

from __future__ import annotations

import numpy as np

from clearjoint.identify.damper import _slope


def test_plateau_slope_is_numpys_least_squares_line() -> None:
    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(4, 400))
        t = np.sort(rng.uniform(0.0, rng.uniform(1e-4, 1e-1), n))
        y = rng.normal(size=n) * rng.uniform(1.0, 1e4) + rng.normal() * 1e5 * t
        scale = np.std(y) / np.std(t)  # the slope's natural size
        assert abs(_slope(t, y) - np.polyfit(t, y, 1)[0]) <= 1e-12 * scale
    assert _slope(np.full(5, 0.3), np.arange(5.0)) == 0.0  # no travel: no change
    assert _slope(np.arange(6.0), 2.5 * np.arange(6.0) - 1.0) == 2.5
