"""The joint's motion results: EnergyLedger, Stage, FrequencySweep (Motion and SteadyState:
tests/test_simulate_results.py)."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt

from clearjoint.results import EnergyLedger, FrequencySweep, Stage

LEDGER = EnergyLedger(
    input=2e-3,
    viscous=1.2e-3,
    sliding_friction=0.5e-3,
    impact=0.3e-3,
    contact_friction=0.1e-3,
    mechanical_energy_change=0.0,
)


@pytest.fixture
def sweep() -> FrequencySweep:
    omega = 2 * math.pi * np.array([100.0, 200.0, 300.0])
    return FrequencySweep(
        omega=omega,
        amplitude_up=np.array([1e-5, 3e-5, np.nan]),
        amplitude_down=np.array([1.1e-5, 2.5e-5, 0.5e-5]),
        multiple_up=np.array([1, 2, 0], dtype=np.int64),
        multiple_down=np.array([1, 1, 1], dtype=np.int64),
    )


def test_ledger_tables_carry_every_entry_in_joules() -> None:
    data = LEDGER.to_xarray()
    for key, value in LEDGER.as_dict().items():
        assert float(data[key]) == value
        assert data[key].attrs["units"] == "J"
    assert float(data["balance_error"]) == LEDGER.balance_error
    table = LEDGER.to_pandas()
    assert table.loc["impact", "energy_j"] == LEDGER.impact
    assert table.loc["losses", "energy_j"] == LEDGER.losses
    text = repr(LEDGER)
    assert text.startswith("EnergyLedger(")
    assert "input 2 mJ" in text
    assert len(text) < 250


def test_ledger_plot_draws_onto_the_given_axes() -> None:
    _, ax = plt.subplots()
    assert LEDGER.plot(ax) is ax
    assert len(ax.patches) == 6  # input, three losses, contact friction, energy change
    plt.close("all")


def test_stage_tables_and_plot() -> None:
    stage = Stage("compression", 0.001, 0.0015)
    data = stage.to_xarray()
    assert str(data["name"].values) == "compression"
    assert float(data["start"]) == 0.001
    assert data["end"].attrs["units"] == "s"
    row = stage.to_pandas()
    assert row.loc[0, "end_s"] == 0.0015
    assert repr(stage) == "Stage(compression, 1-1.5 ms)"
    _, ax = plt.subplots()
    assert stage.plot(ax) is ax
    assert ax.patches[-1].get_label() == "compression"
    plt.close("all")


def test_sweep_tables_carry_the_arrays_with_units(sweep: FrequencySweep) -> None:
    data = sweep.to_xarray()
    np.testing.assert_array_equal(data["omega"].values, sweep.omega)
    np.testing.assert_array_equal(data["amplitude_up"].values, sweep.amplitude_up)
    np.testing.assert_array_equal(data["multiple_up"].values, sweep.multiple_up)
    assert data["amplitude_down"].attrs["units"] == "m"
    assert data["frequency"].attrs["units"] == "Hz"
    table = sweep.to_pandas()
    np.testing.assert_array_equal(table["amplitude_down"].to_numpy(), sweep.amplitude_down)
    np.testing.assert_allclose(table["frequency"].to_numpy(), [100.0, 200.0, 300.0])


def test_sweep_repr_is_a_short_summary(sweep: FrequencySweep) -> None:
    text = repr(sweep)
    assert text.startswith("FrequencySweep(3 frequencies, 100-300 Hz")
    assert "max X up 30 um" in text
    assert "1 orbits of more than one period" in text
    assert "array" not in text


def test_sweep_plot_draws_up_and_down_onto_the_given_axes(sweep: FrequencySweep) -> None:
    _, ax = plt.subplots()
    assert sweep.plot(ax) is ax
    up, down = ax.get_lines()
    np.testing.assert_allclose(up.get_ydata(), sweep.amplitude_up * 1e3)
    assert down.get_label() == "sweep down"
    plt.close("all")
