"""verification.py: the identification against the rig's truth, by hand."""

from __future__ import annotations

import math

import pytest

from clearjoint.analysis import Analysis
from clearjoint.verification import identification_accuracy


def test_relative_errors_compare_slopes_with_k0_plus_k_s() -> None:
    rows = [
        {
            "file": "/somewhere/records/joint-1_20Hz_800N.nc",
            "jointed": True,
            "clearance_m": 0.107e-3,
            "compression_stiffness_n_per_m": 51.2e6,
            "tension_stiffness_n_per_m": 40.0e6,
            "energy_per_cycle_j": 0.099,
        },
        {
            "file": "/somewhere/records/beam_20Hz_800N.nc",
            "jointed": False,
            "clearance_m": 0.0,
            "compression_stiffness_n_per_m": 70e6,
            "tension_stiffness_n_per_m": 70e6,
            "energy_per_cycle_j": 0.0104,
        },
    ]
    truth = {
        "joint-1_20Hz_800N.nc": {
            "gap_stiffness_n_per_m": "2e5",
            "energy_per_cycle_j": "0.1",
            "clearance_m": "0.106e-3",
            "compression_stiffness_n_per_m": "51e6",
            "tension_stiffness_n_per_m": "40.2e6",
        },
        "beam_20Hz_800N.nc": {"gap_stiffness_n_per_m": "2e5", "energy_per_cycle_j": "0.01"},
    }
    accuracy, worst = identification_accuracy(Analysis(rows, [], []), truth)
    joint, beam = accuracy
    assert joint["file"] == "joint-1_20Hz_800N.nc"
    assert joint["clearance_error"] == pytest.approx(0.107 / 0.106 - 1)
    assert joint["compression_stiffness_error"] == pytest.approx(51.2 / 51.2 - 1, abs=1e-12)
    assert joint["tension_stiffness_error"] == pytest.approx(40.0 / 40.4 - 1)
    assert "clearance_error" not in beam  # no clearance to compare
    assert worst["energy_error"] == pytest.approx(0.04)
    assert worst["clearance_error"] == pytest.approx(abs(0.107 / 0.106 - 1))
    empty, worst_empty = identification_accuracy(Analysis([], [], []), {})
    assert empty == []
    assert math.isnan(worst_empty["clearance_error"])
