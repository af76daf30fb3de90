"""FrequencyResponse and ResponseEvent: tables, plot and the DOF names a curve carries."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt

from clearjoint.results import FrequencyResponse, ResponseEvent
from clearjoint.structure import Structure

EVENT = ResponseEvent("fold", 2 * math.pi * 12.0, 1.5, 2e-4, note="a fold")


def _curve(dofs: int | None, names: tuple[str, ...] | None = None) -> FrequencyResponse:
    """A hand-made curve of 4 points: one DOF (a Joint's) or ``dofs`` (a Structure's)."""
    n = 4
    omega = np.linspace(10.0, 20.0, n)
    amp = (
        np.linspace(1e-4, 4e-4, n)
        if dofs is None
        else np.outer(np.linspace(1, 4, n), 1e-4 * np.arange(1, dofs + 1))
    )
    width = 1 if dofs is None else dofs
    return FrequencyResponse(
        omega=omega,
        force_amplitude=np.full(n, 1.5),
        x_max=amp,
        x_min=-amp,
        amplitude=amp,
        stable=np.array([True, False, False, True]),
        multipliers=np.zeros((n, 2 * width), dtype=np.complex128),
        initial_state=np.zeros((n, 2 * width)),
        events=[EVENT],
        parameter="omega",
        stop_reason="reached",
        method="harmonic" if dofs is not None else "shooting",
        dof_names=names,
    )


def test_joint_curve_to_pandas_is_one_row_per_point() -> None:
    curve = _curve(None)
    table = curve.to_pandas()
    assert table.index.name == "point"
    assert len(table) == 4
    np.testing.assert_array_equal(table["amplitude_m"].to_numpy(), curve.amplitude)
    np.testing.assert_array_equal(table["omega_rad_per_s"].to_numpy(), curve.omega)
    np.testing.assert_allclose(table["frequency_hz"].to_numpy(), curve.omega / (2 * math.pi))
    np.testing.assert_array_equal(table["stable"].to_numpy(), curve.stable)
    assert curve.dof_names is None


def test_structure_curve_names_its_dofs_in_tables_and_plot() -> None:
    names = ("n1x", "n2x", "n3x")
    curve = _curve(3, names)
    data = curve.to_xarray()
    assert list(data["dof"].values) == list(names)
    np.testing.assert_array_equal(data["amplitude"].sel(dof="n2x").values, curve.amplitude[:, 1])
    assert data["amplitude"].attrs["units"] == "m"
    table = curve.to_pandas()
    np.testing.assert_array_equal(table["amplitude_m[n3x]"].to_numpy(), curve.amplitude[:, 2])
    np.testing.assert_array_equal(table["x_min_m[n1x]"].to_numpy(), curve.x_min[:, 0])
    _, ax = plt.subplots()
    assert curve.plot(ax) is ax
    labels = ax.get_legend_handles_labels()[1]
    assert set(names) <= set(labels)
    plt.close("all")


def test_a_curve_without_names_falls_back_to_dof_numbers() -> None:
    curve = _curve(2)
    assert "dof" not in curve.to_xarray().coords
    assert "amplitude_m[DOF 1]" in curve.to_pandas().columns


def test_a_harmonic_structure_curve_carries_the_structures_dof_names(
    three_links: Structure,
) -> None:
    from clearjoint.harmonic import frequency_response

    force = np.array([0.0, 0.0, 40.0])  # N on the last mass, as tests/test_harmonic_structure
    fr = frequency_response(three_links, force, 400.0, 410.0, max_points=3, check_points=0)
    assert fr.dof_names == tuple(three_links.dof_names)
    assert fr.settings["dof_names"] == list(three_links.dof_names)  # the older place
    assert list(fr.to_xarray()["dof"].values) == list(three_links.dof_names)


def test_event_tables_and_plot() -> None:
    data = EVENT.to_xarray()
    assert str(data["kind"].values) == "fold"
    assert float(data["frequency"]) == pytest.approx(12.0, rel=1e-15)
    assert data["frequency"].attrs["units"] == "Hz"
    assert data["amplitude"].attrs["units"] == "m"
    assert data.attrs["note"] == "a fold"
    row = EVENT.to_pandas()
    assert row.loc[0, "amplitude_m"] == EVENT.amplitude
    assert row.loc[0, "kind"] == "fold"
    _, ax = plt.subplots()
    assert EVENT.plot(ax) is ax
    line = ax.get_lines()[-1]
    assert line.get_xdata()[0] == pytest.approx(12.0)
    assert line.get_ydata()[0] == pytest.approx(0.2)
    plt.close("all")
