"""benchmarks/bench_scale.py's table (--json) and the growth plot drawn from it (issue 25).

The table shipped in examples/ is the one the gallery script draws: it must hold what the
script reads, say how it was made, and its recorded fit must be the fit of its own rows.
"""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

ROOT = Path(__file__).parents[1]


def _bench() -> Any:
    path = ROOT / "benchmarks" / "bench_scale.py"
    spec = importlib.util.spec_from_file_location("bench_scale_table", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_the_shipped_table_is_a_benchmark_run_and_its_fit_is_its_own() -> None:
    table = json.loads((ROOT / "examples" / "bench_scale.json").read_text())
    assert table["command"].startswith("python benchmarks/bench_scale.py")
    assert "--json examples/bench_scale.json" in table["command"]
    sizes = table["sizes"]
    assert len(sizes) >= 3
    for row in sizes:
        assert row["unknowns"] == (2 * table["harmonics"] + 1) * 4 * row["bays"]
        assert 0.0 < row["verdict_per_point"] * row["points"] == pytest.approx(row["verdict"])
        assert row["per_point"] > 0.0
    fitted = [r for r in sizes if r["bays"] in table["fit"]["bays"]]
    slope = np.polyfit(
        np.log([r["unknowns"] for r in fitted]), np.log([r["per_point"] for r in fitted]), 1
    )[0]
    assert table["fit"]["exponent"] == pytest.approx(slope, rel=1e-12)


def test_write_json_round_trips_a_row(tmp_path: Path) -> None:
    """A row as run_size makes it (numpy scalars and arrays included) comes back as plain
    numbers, with the verdict's time per point and share derived from it."""
    bench = _bench()
    row = {
        "bays": 10,
        "unknowns": 600,
        "points": np.int64(4),
        "total": np.float64(3.0),
        "start": 1.0,
        "per_point": 0.5,
        "verdict": 0.8,
        "splu": 0.1,
        "splu_calls": 7,
        "rss_mib": 100.0,
        "load": 1.5,
        "reason": "max_points",
        "stable": np.array([True, False, False, True]),
        "omega": np.ones(4),
    }
    path = tmp_path / "t.json"
    bench.write_json(str(path), [row], [{"bays": 80, "error": "no start"}], [row], 1.25, "now")
    table = json.loads(path.read_text())
    (got,) = table["sizes"]
    assert got["points"] == 4
    assert got["verdict_per_point"] == pytest.approx(0.2)
    assert got["verdict_share"] == pytest.approx(0.4)  # of the 2 s after the start
    assert got["unstable"] == 2
    assert "omega" not in got
    assert table["no_curve"] == [{"bays": 80, "error": "no start"}]
    assert table["fit"]["exponent"] == 1.25
    assert table["fit"]["bays"] == [10]
    bench.write_json(str(path), [row], [], [row], math.nan, "now")
    assert json.loads(path.read_text())["fit"]["exponent"] is None


def test_on_old_curve_tells_the_same_orbits_from_moved_ones() -> None:
    """bench_scale.on_old_curve: a curve against itself has every point on it (distance 0,
    each its own nearest); against orbits moved by 1e-3 of the largest coefficient, none
    solves HB to the curve's tolerance at the new points' frequencies."""
    bench = _bench()
    row = bench.run_size(2, 5, False)
    coef = np.asarray(row["coefficients"])
    points = np.arange(coef.shape[0])
    on, gaps, nearest = bench.on_old_curve(2, coef, row, points)
    assert on == points.size
    assert np.all(gaps == 0.0)
    assert np.array_equal(nearest, points)
    moved = coef + 1e-3 * float(np.max(np.abs(coef)))
    on, gaps, _ = bench.on_old_curve(2, moved, row, points)
    assert on == 0
    assert np.all(gaps > 0.0)


def test_on_old_curve_holds_a_point_to_the_curves_own_scale() -> None:
    """bench_scale.on_old_curve calls an old orbit "on the curve" when it solves HB as the
    new curve's points must: max abs(R) / k_ref <= TOLERANCE times the continuation's
    u_scale, max(scale_length / 2, max abs of the curve's start), fixed along the curve
    (frequency_response). An orbit near the peak, moved so its residual lies between that
    and TOLERANCE times its own size (a looser scale), is not on the curve."""
    from clearjoint.harmonic import aft, response, solve

    bench = _bench()
    row = bench.run_size(2, 60, False)
    coef = np.asarray(row["coefficients"])
    sizes = np.max(np.abs(coef.reshape(coef.shape[0], -1)), axis=1)
    i = int(np.argmax(sizes))
    structure = bench.model(2)
    system = bench._system(structure)
    basis = aft.Basis.make(*aft.check_harmonics(bench.H, None))
    force = bench.tip_force(structure, 2, 0.1)
    floor = 0.5 * response.scale_length(system)
    curve = solve.TOLERANCE * max(floor, float(sizes[0]))
    own = solve.TOLERANCE * max(floor, float(sizes[i]))
    assert own > 1.5 * curve  # the peak's orbit is larger than the start's scale

    def size(q: np.ndarray) -> float:
        ev = aft.evaluate(system, basis, q, float(row["omega"][i]), force, jacobian=False)
        return float(np.max(np.abs(ev.residual))) / system.reference_stiffness

    direction = np.full(coef[i].shape, 1e-12 * float(sizes[i]))
    t = np.sqrt(curve * own) / size(coef[i] + direction)  # about linear: R(q) is ~0
    moved = coef.copy()
    moved[i] = coef[i] + t * direction
    assert curve < size(moved[i]) < own  # between the two scales
    on, _, nearest = bench.on_old_curve(2, moved, row, np.array([i]))
    assert nearest[0] == i
    assert on == 0
