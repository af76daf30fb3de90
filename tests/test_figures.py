"""figures.py: each figure function returns a Figure with the data it was given."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

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


def test_stage_figure_shades_each_stage_once_in_the_legend() -> None:
    from clearjoint.figures import displacement_stages_figure

    t = np.linspace(0.0, 1e-2, 50)
    stages = [
        ("free-play", 0.0, 2e-3),
        ("compression", 2e-3, 4e-3),
        ("free-play", 4e-3, 6e-3),
        ("tension", 6e-3, 1e-2),
    ]
    fig = displacement_stages_figure(t, 1e-5 * np.sin(600 * t), stages)
    (ax,) = fig.axes
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == ["free-play", "compression", "tension", "displacement"]
    assert len(ax.patches) == 4


def test_loop_figure_closes_the_loop() -> None:
    from clearjoint.figures import force_displacement_figure

    x = np.sin(np.linspace(0, 2 * np.pi, 20, endpoint=False))
    fig = force_displacement_figure(1e-5 * x, 100 * x)
    line = fig.axes[0].get_lines()[0]
    assert line.get_xdata()[0] == line.get_xdata()[-1]


def test_fig13_names_its_reference_and_puts_the_one_to_one_line_in_the_legend() -> None:
    from clearjoint.figures import law_versus_measured_figure

    measured = np.geomspace(0.05, 0.4, 12)
    fig = law_versus_measured_figure(measured, measured * 1.1, reference="virtual rig")
    (ax,) = fig.axes
    assert ax.get_xlabel().startswith("virtual rig")
    assert "1:1" in [t.get_text() for t in ax.get_legend().get_texts()]
    fig.canvas.draw()  # labels exist only once drawn
    assert all(not t.get_text() for t in ax.xaxis.get_minorticklabels())
    shown = [t.get_text() for t in ax.xaxis.get_majorticklabels() if t.get_text()]
    assert 2 <= len(shown) <= 6  # 1, 2, 5 per decade over less than a decade
    assert (
        law_versus_measured_figure(measured, measured).axes[0].get_xlabel().startswith("measured")
    )


def test_structure_modes_draws_closed_and_open_side_by_side() -> None:
    from clearjoint.figures import structure_modes
    from clearjoint.joint import ClearanceJoint
    from clearjoint.structure import chain

    s = chain([2.0, 1.5], [1e7, 6e7], [ClearanceJoint(1e-4, 8e7, gap_stiffness=1e6), None])
    fig = structure_modes(s.modes("closed"), s.modes("open"))
    assert [ax.get_title() for ax in fig.axes] == ["closed pattern", "open pattern"]


def test_identified_loop_figure_of_a_damper_in_mm_with_its_own_stages_and_the_reason() -> None:
    from clearjoint.figures import NOTE_CHARACTERS, identified_loop_figure

    t = np.linspace(0.0, 1.0, 400, endpoint=False)
    x = 12e-3 * np.sin(2 * np.pi * t)  # a damper's 12 mm stroke
    force = 3000.0 * np.sign(np.cos(2 * np.pi * t))
    stage = np.sign(force).astype(np.int8)
    stage[::10] = 0
    reason = "backlash 4.68 mm on the rising branch and 1.4 mm on the falling one " * 3
    fig = identified_loop_figure(
        x, force, stage, (2.8e-3, -0.2e-3), (), model="damper",
        slip_levels=(3000.0, -2500.0), note=reason,
    )  # fmt: skip
    (ax,) = fig.axes
    assert ax.get_xlabel() == "displacement x (mm)"
    marks = [line for line in ax.get_lines() if line.get_linestyle() == "None"]
    np.testing.assert_allclose(np.sort(np.concatenate([m.get_xdata() for m in marks])),
                               np.sort(x * 1e3))  # fmt: skip
    labels = {text.get_text() for text in ax.get_legend().get_texts()}
    assert {"positive force", "backlash (after a reversal)", "negative force"} <= labels
    assert not labels & {"tension", "free-play", "compression"}
    # no gap lines at fixed x (a damper's backlash follows each reversal), its slip levels
    vertical = [line for line in ax.get_lines() if np.ptp(line.get_xdata()) == 0]
    assert not vertical
    levels = sorted(line.get_ydata()[0] for line in ax.get_lines() if "slip" in line.get_label())
    assert levels == [-2500.0, 3000.0]
    (note,) = fig.texts
    assert note.get_text().startswith("backlash 4.68 mm on the rising branch")
    assert note.get_text().endswith("…")
    assert len(note.get_text()) <= NOTE_CHARACTERS + 2
    # a joint's loop of 0.2 mm stays in µm with its gap edges and stage names
    fig = identified_loop_figure(x / 60, force, stage, (0.05e-3, -0.05e-3))
    (ax,) = fig.axes
    assert ax.get_xlabel() == "displacement x (µm)"
    assert {"tension", "free-play", "compression"} <= {
        t.get_text() for t in ax.get_legend().get_texts()
    }
    assert len([line for line in ax.get_lines() if np.ptp(line.get_xdata()) == 0]) == 2
    assert not fig.texts


def test_save_figure_writes_a_drawn_figure_or_draws_a_result_first(tmp_path: Path) -> None:
    """clearjoint.plotting.save_figure: the --plot file of every command."""
    from matplotlib.figure import Figure

    from clearjoint.plotting import save_figure

    class Result:
        def plot(self, ax: Any) -> Any:
            ax.plot([0.0, 1.0], [1.0, 0.0], label="drawn")
            return ax

    fig = Figure()
    fig.add_subplot().plot([0.0, 1.0])
    drawn = save_figure(fig, tmp_path / "made" / "fig.png")  # the folder is made
    assert drawn == tmp_path / "made" / "fig.png"
    assert drawn.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    result = save_figure(Result(), str(tmp_path / "result.svg"))
    assert "<svg" in result.read_text(encoding="utf-8")


# ---- issue 28: the report's figures read at a glance --------------------------------------


def _labelled_ticks(axis: Any) -> list[tuple[float, str]]:
    """The major ticks inside the axis' view with their labels (the figure drawn first)."""
    low, high = sorted(axis.get_view_interval())
    labels = [text.get_text() for text in axis.get_majorticklabels()]
    return [
        (loc, label)
        for loc, label in zip(axis.get_majorticklocs(), labels, strict=True)
        if label and low <= loc <= high
    ]


def test_fig13_log_axes_have_enough_labelled_ticks_as_plain_numbers() -> None:
    """The issue's report: energies over about a decade (0.04 to 0.6 J) got two labels."""
    from clearjoint.figures import law_versus_measured_figure

    measured = np.geomspace(0.04, 0.6, 40)
    fig = law_versus_measured_figure(measured, measured * 1.2, model=measured * 1.5)
    fig.canvas.draw()
    (ax,) = fig.axes
    for axis in (ax.xaxis, ax.yaxis):
        ticks = _labelled_ticks(axis)
        assert len(ticks) >= 4, ticks
        # a plain number, read back as the tick's own value (no 10^x mathtext)
        assert all(float(text) == pytest.approx(loc) for loc, text in ticks), ticks


def test_the_identification_error_legend_is_outside_the_points() -> None:
    """A point at +1.1 % (the issue's energy point) sat on the '±1 %' legend."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.transforms import Bbox

    from clearjoint.figures import identification_accuracy_figure

    rng = np.random.default_rng(3)
    accuracy = [
        {
            "clearance_error": 1e-4 * rng.standard_normal(),
            "compression_stiffness_error": 1e-3 * rng.standard_normal(),
            "tension_stiffness_error": 1e-3 * rng.standard_normal(),
            "energy_error": 0.011 if k == 0 else 0.005 * rng.standard_normal(),
        }
        for k in range(30)
    ]
    fig = identification_accuracy_figure(accuracy)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    (ax,) = fig.axes
    renderer = canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(renderer)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["±1 %"]
    # no marker of any point inside the legend's box
    for line in ax.get_lines():
        for x, y in ax.transData.transform(line.get_xydata()):
            assert not legend.contains(x, y), (x, y)
    assert not Bbox.intersection(legend, ax.get_window_extent(renderer))  # outside the axes


def test_fig8_frequencies_apart_and_coinciding_lines_said() -> None:
    """Five frequencies whose eq 19 lines lie within 0.1 % of each other: each its own
    colour and style, and a note says the lines coincide (the law barely depends on w)."""
    from clearjoint.figures import StiffnessPanel, stiffness_panels_figure

    freqs = np.repeat([20.0, 40.0, 60.0, 80.0, 100.0], 4)
    amp = np.tile(np.linspace(20e-6, 80e-6, 4), 5)
    k = 5e6 + 2.5e11 * amp + 100.0 * freqs  # 0.008 MN/m across 80 Hz, 15 MN/m across A
    grid = np.linspace(20e-6, 80e-6, 20)
    lines = {f: (grid, 5e6 + 2.5e11 * grid + 100.0 * f) for f in np.unique(freqs)}
    fig = stiffness_panels_figure(
        [StiffnessPanel("joint-1, compression", freqs, amp, k, lines)], ylabel="k (MN/m)"
    )
    ax = fig.axes[0]
    drawn = [line for line in ax.get_lines() if line.get_xdata().size == grid.size]
    assert len(drawn) == 5
    assert len({line.get_color() for line in drawn}) == 5
    points = [line for line in ax.get_lines() if line.get_xdata().size == 4]
    assert len({line.get_marker() for line in points}) == 5
    assert {line.get_color() for line in points} == {line.get_color() for line in drawn}
    notes = [t.get_text() for t in ax.texts]
    assert len(notes) == 1
    assert "5 frequencies' lines lie within 0.008 MN/m" in notes[0]
    # lines far apart (the beam's panels): no note
    apart = {f: (grid, law + 2e5 * f) for f, (grid, law) in lines.items()}
    fig = stiffness_panels_figure(
        [StiffnessPanel("beam, compression", freqs, amp, k + 2e5 * freqs, apart)],
        ylabel="k (MN/m)",
    )
    assert not fig.axes[0].texts
