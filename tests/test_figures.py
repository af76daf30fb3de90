"""figures.py: each figure function returns a Figure with the data it was given."""

from __future__ import annotations

import numpy as np

from clearjoint.figures import Curve, stiffness_coefficient_figure


def test_stiffness_coefficient_figure_plots_every_curve_in_micrometres() -> None:
    a = np.linspace(0.0, 1e-4, 5)
    fig = stiffness_coefficient_figure([Curve(a, a * 1e4, "one"), Curve(a, a * 5e3, "two")])
    (ax,) = fig.axes
    lines = [line for line in ax.get_lines() if line.get_label() in ("one", "two")]
    assert len(lines) == 2
    np.testing.assert_allclose(lines[0].get_xdata(), a * 1e6)
    assert "µm" in ax.get_xlabel()
    assert lines[0].get_linestyle() != lines[1].get_linestyle()  # apart in grey print
