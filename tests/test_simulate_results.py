"""simulate.core's result objects: repr, to_xarray, to_pandas and plot of Motion and SteadyState."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from clearjoint import Friction, Joint, Losses
from clearjoint.exact.single import STAGE_NAMES, _stages
from clearjoint.results import Stage
from clearjoint.simulate import Motion, SteadyState, steady_state, time_response

JOINT = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, tension_stiffness=5e7)
LINEAR = Joint(mass=2.0, clearance=0.0, compression_stiffness=8e7)
TWO_PI = 2.0 * math.pi


@pytest.fixture(scope="module")
def cycle() -> SteadyState:
    return steady_state(
        JOINT, 1000.0, TWO_PI * 400.0,
        losses=Losses(damping_ratio=0.01, restitution=0.8, friction=Friction(0.2, 300.0)),
    )  # fmt: skip


@pytest.fixture(scope="module")
def transient() -> Motion:
    return time_response(JOINT, 500.0, TWO_PI * 300.0, 0.05, losses=Losses(damping_ratio=0.02))


def test_steady_state_repr_is_short_and_gives_the_textbook_amplitude() -> None:
    omega, zeta, f0 = TWO_PI * 300.0, 0.02, 500.0
    ss = steady_state(LINEAR, f0, omega, losses=Losses(damping_ratio=zeta), samples_per_period=4096)
    text = repr(ss)
    assert len(text) < 400
    assert "array" not in text
    c_v = 2 * zeta * math.sqrt(2.0 * 8e7)
    x_amp = f0 / math.hypot(8e7 - 2.0 * omega**2, c_v * omega)  # textbook, by hand
    assert f"X = {x_amp * 1e6:.4g} um" in text
    assert "period-1 orbit at 300 Hz" in text


def test_motion_repr_does_not_grow_with_the_samples(transient: Motion) -> None:
    assert transient.time.size > 3000
    assert len(repr(transient)) < 300
    assert repr(transient).startswith("Motion(")
    assert f"{transient.impact_times.size} impacts" in repr(transient)


def test_to_xarray_round_trips_the_arrays_with_units(cycle: SteadyState) -> None:
    data = cycle.to_xarray()
    pairs = {
        "displacement": (cycle.displacement, "m"),
        "velocity": (cycle.velocity, "m/s"),
        "acceleration": (cycle.acceleration, "m/s^2"),
        "excitation_force": (cycle.excitation, "N"),
        "restoring_force": (cycle.restoring_force, "N"),
        "impact_time": (cycle.impact_times, "s"),
        "impact_velocity": (cycle.impact_velocities, "m/s"),
    }
    for name, (values, unit) in pairs.items():
        np.testing.assert_array_equal(data[name].values, values)
        assert data[name].attrs["units"] == unit
    np.testing.assert_array_equal(data["time"].values, cycle.time)
    assert data["time"].attrs["units"] == "s"
    assert list(data["stage_name"].values) == [s.name for s in cycle.stages]
    assert float(data["energy_input"]) == cycle.energy.input
    assert data["energy_impact"].attrs["units"] == "J"
    assert int(data["period_multiple"]) == cycle.period_multiple
    assert float(data["compression_penetration"]) == cycle.compression_penetration


def test_to_xarray_writes_and_reads_back_as_netcdf(cycle: SteadyState, tmp_path: Path) -> None:
    import xarray as xr

    path = tmp_path / "cycle.nc"
    cycle.to_xarray().to_netcdf(path, engine="h5netcdf")
    with xr.open_dataset(path, engine="h5netcdf") as back:
        np.testing.assert_array_equal(back["displacement"].values, cycle.displacement)
        assert back["velocity"].attrs["units"] == "m/s"


def test_to_pandas_is_one_row_per_sample(transient: Motion) -> None:
    table = transient.to_pandas()
    assert table.shape == (transient.time.size, 5)
    np.testing.assert_array_equal(table.index.to_numpy(), transient.time)
    np.testing.assert_array_equal(table["displacement_m"].to_numpy(), transient.displacement)


def test_plot_draws_the_displacement_in_um_against_ms(cycle: SteadyState) -> None:
    ax = Figure().add_subplot()
    assert cycle.plot(ax) is ax
    line = ax.lines[0]
    np.testing.assert_allclose(line.get_xdata(), cycle.time * 1e3)
    np.testing.assert_allclose(line.get_ydata(), cycle.displacement * 1e6)
    # one shaded span per contact stage, at the stage's times
    contact = [s for s in cycle.stages if s.name != "free-play"]
    assert len(ax.patches) == len(contact)
    first = ax.patches[0].get_x()
    assert first == pytest.approx(contact[0].start * 1e3)


def test_plot_without_axes_makes_a_figure(transient: Motion) -> None:
    import matplotlib.pyplot as plt

    ax = transient.plot()
    try:
        np.testing.assert_allclose(ax.lines[0].get_ydata(), transient.displacement * 1e6)
    finally:
        plt.close(ax.figure)


def _stages_one_by_one(
    regions: np.ndarray, starts: np.ndarray, ends: np.ndarray
) -> tuple[Stage, ...]:
    """The rule written plainly, segment by segment: merge one region's run, skip empty ones."""
    stages: list[Stage] = []
    for region, start, end in zip(regions, starts, ends, strict=True):
        name = STAGE_NAMES[int(region)]
        if stages and stages[-1].name == name:
            stages[-1] = Stage(name, stages[-1].start, float(end))
        elif end > start or not stages:
            stages.append(Stage(name, float(start), float(end)))
    return tuple(stages)


def test_stages_merge_runs_and_skip_empty_segments_as_the_plain_rule_does() -> None:
    rng = np.random.default_rng(1)
    for _ in range(3000):
        n = int(rng.integers(1, 12))
        regions = rng.integers(-1, 2, n)
        lengths = rng.choice([0.0, 1.0, 2.5], n)  # empty segments: events at one instant
        starts = np.concatenate(([0.0], np.cumsum(lengths)[:-1])) + rng.choice([0.0, 1e-17], n)
        ends = starts + lengths + rng.choice([0.0, 1e-16], n)  # ends off by round-off
        expected = _stages_one_by_one(regions, starts, ends)
        assert _stages(regions.astype(np.int64), starts, ends) == expected
