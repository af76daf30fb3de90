"""PeriodicOrbit's tables and plot, checked against its own arrays."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

from clearjoint import Losses

matplotlib.use("Agg")

import matplotlib.pyplot as plt

from clearjoint.periodic import periodic_orbit
from clearjoint.results import PeriodicOrbit
from helpers import joint


@pytest.fixture(scope="module")
def orbit() -> PeriodicOrbit:
    return periodic_orbit(joint(), 20000.0, 2 * math.pi * 100.0, losses=Losses(damping_ratio=0.01))


def test_orbit_to_xarray_carries_the_cycle_multipliers_and_monodromy(orbit: PeriodicOrbit) -> None:
    data = orbit.to_xarray()
    np.testing.assert_array_equal(data["displacement"].values, orbit.cycle.displacement)
    np.testing.assert_array_equal(data["multiplier_real"].values, orbit.multipliers.real)
    np.testing.assert_array_equal(data["multiplier_imag"].values, orbit.multipliers.imag)
    np.testing.assert_array_equal(data["monodromy"].values, orbit.monodromy)
    assert float(data["omega"]) == orbit.omega
    assert float(data["frequency"]) == pytest.approx(orbit.omega / (2 * math.pi), rel=1e-15)
    assert float(data["initial_displacement"]) == orbit.initial_state[0]
    assert int(data["stable"]) == int(orbit.stable)
    units = {
        "omega": "rad/s",
        "frequency": "Hz",
        "force_amplitude": "N",
        "initial_velocity": "m/s",
        "displacement": "m",
    }
    for name, unit in units.items():
        assert data[name].attrs["units"] == unit


def test_orbit_to_pandas_is_its_cycle_table(orbit: PeriodicOrbit) -> None:
    table = orbit.to_pandas()
    np.testing.assert_array_equal(table.index.to_numpy(), orbit.cycle.time)
    np.testing.assert_array_equal(table["displacement_m"].to_numpy(), orbit.cycle.displacement)


def test_orbit_plot_draws_onto_the_given_axes(orbit: PeriodicOrbit) -> None:
    _, ax = plt.subplots()
    assert orbit.plot(ax) is ax
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), orbit.cycle.displacement * 1e6)
    assert "stable" in ax.get_title()
    plt.close("all")
