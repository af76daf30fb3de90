"""A sweep store is the labelled grid that plain ``xarray.open_zarr`` reads (issue 27).

The references are built without the store: the sweep run in memory (no ``out``), the
task called by hand at single points, and numpy arrays filled here point by point.
"""

from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import clearjoint.store
from clearjoint.parallel import point_seed
from clearjoint.store import Grid, ResultStore, StoreError, Variable
from clearjoint.sweep import SERIAL, Sweep, open_sweep, run_sweep

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

# 7 samples x 2 amplitudes = 14 points in chunks of 3: chunks straddle the rows of
# `sample` (2 points a row) and, with 4 points a file, the zarr files too
SWEEP = """
base = "{study}"
seed = 11
samples = 7
chunk_size = 3
[task]
name = "free_cycle"
outputs = ["natural_frequency_hz", "equivalent_damping_ratio"]
[axes.task]
amplitude = ["10um", "40um"]
[draws.joint.clearance]
distribution = "normal"
mean = "0.1mm"
std = "0.02mm"
lower = "0mm"
"""


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("layout") / "tolerance.toml"
    path.write_text(SWEEP.format(study=EXAMPLES / "study.toml"), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def stored(sweep_file: Path) -> tuple[Path, xr.Dataset, xr.Dataset]:
    """A finished store (4 points a zarr file), what run_sweep returned, the in-memory run."""
    out = sweep_file.parent / "grid.zarr"
    sweep = Sweep.from_toml(sweep_file)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(clearjoint.store, "POINTS_PER_FILE", 1)
        returned = run_sweep(sweep, client=SERIAL, out=out)
    return out, returned, run_sweep(sweep, client=SERIAL)


def _plain_open(path: Path) -> xr.Dataset:
    """``xr.open_zarr(path)`` with every warning an error (a store must open cleanly)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with xr.open_zarr(path) as data:
            return data.load()


def test_plain_open_zarr_gives_the_labelled_grid_the_api_returns(
    sweep_file: Path, stored: tuple[Path, xr.Dataset, xr.Dataset]
) -> None:
    out, returned, in_memory = stored
    plain = _plain_open(out)
    assert plain["natural_frequency_hz"].dims == ("sample", "task.amplitude")
    assert plain["status"].dims == ("sample", "task.amplitude")
    np.testing.assert_allclose(plain["task.amplitude"], [10e-6, 40e-6], rtol=1e-12)  # in SI
    assert plain["task.amplitude"].attrs["units"] == "m"
    np.testing.assert_array_equal(plain["sample"], np.arange(7))
    assert plain["joint.clearance"].dims == ("sample",)  # a coordinate, not a variable
    assert "joint.clearance" in plain.coords
    assert not [name for name in plain.data_vars if "chunk" in name]  # no bookkeeping shown
    assert plain.attrs["points_missing"] == 0
    # identical to what the API returned (status: fixed-width strings there, numpy's
    # StringDType here; identical compares values, not the string dtype)
    xr.testing.assert_identical(plain, returned)
    # and to the run without a store, but for the store's own format mark
    xr.testing.assert_identical(plain.drop_attrs(deep=False), in_memory.drop_attrs(deep=False))
    extra = set(plain.attrs) - set(in_memory.attrs)
    assert extra == {"clearjoint_store_format"}
    assert {k: plain.attrs[k] for k in in_memory.attrs} == in_memory.attrs


def test_each_grid_cell_holds_its_own_point(
    sweep_file: Path, stored: tuple[Path, xr.Dataset, xr.Dataset]
) -> None:
    """Cells checked against the task called by hand at that point's values and seed."""
    out, _, _ = stored
    plain = _plain_open(out)
    sweep = Sweep.from_toml(sweep_file)
    clearance = sweep.drawn()["joint.clearance"]
    np.testing.assert_array_equal(plain["task.amplitude"], sweep.axes[0].values)
    np.testing.assert_array_equal(plain["joint.clearance"], clearance)
    for sample, k in [(0, 0), (3, 1), (6, 0), (6, 1)]:
        values = {
            **dict(sweep.fixed),
            "joint.clearance": float(clearance[sample]),
            "task.amplitude": sweep.axes[0].values[k],
        }
        with warnings.catch_warnings():  # a Hertz validity note: in status, "ok; ..."
            warnings.simplefilter("ignore")
            seed = point_seed(sweep.seed, 2 * sample + k)
            by_hand = sweep.task.evaluate(sweep.base, values, seed)
        for name in sweep.outputs:
            assert plain[name].values[sample, k] == by_hand[name]
        assert str(plain["status"].values[sample, k]).startswith("ok")


def test_a_deleted_file_straddled_by_two_chunks_is_recomputed(
    sweep_file: Path, stored: tuple[Path, xr.Dataset, xr.Dataset], tmp_path: Path
) -> None:
    out, returned, _ = stored
    copy = tmp_path / "copy.zarr"
    shutil.copytree(out, copy)
    # file 1 of a (sample, amplitude) array: samples 2-3, points 4-7 (chunks 1 and 2)
    (copy / "natural_frequency_hz" / "c" / "1" / "0").unlink()
    with pytest.raises(StoreError, match=r"chunk 1 \(points 3-5\) is damaged.*1 other chunks"):
        open_sweep(copy)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        resumed = run_sweep(Sweep.from_toml(sweep_file), client=SERIAL, out=copy, resume=True)
    said = [str(w.message) for w in caught if issubclass(w.category, clearjoint.store.StoreWarning)]
    assert len(said) == 1
    assert "recomputing 6 points of 2 damaged chunks" in said[0]
    xr.testing.assert_identical(resumed, returned)
    xr.testing.assert_identical(_plain_open(copy), returned)


def test_a_rewritten_coordinate_is_refused_and_written_again_on_resume(
    sweep_file: Path, stored: tuple[Path, xr.Dataset, xr.Dataset], tmp_path: Path
) -> None:
    import zarr

    out, returned, _ = stored
    copy = tmp_path / "copy.zarr"
    shutil.copytree(out, copy)
    zarr.open_array(str(copy / "task.amplitude"), mode="r+")[1] = 50e-6  # through zarr: crc ok
    with pytest.raises(StoreError, match=r"coordinate task.amplitude is damaged") as info:
        open_sweep(copy)
    assert "\n" not in str(info.value)
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        resumed = run_sweep(Sweep.from_toml(sweep_file), client=SERIAL, out=copy, resume=True)
    xr.testing.assert_identical(resumed, returned)


def test_a_flat_store_of_format_2_is_one_clear_line(
    stored: tuple[Path, xr.Dataset, xr.Dataset], tmp_path: Path
) -> None:
    out, _, _ = stored
    old = tmp_path / "old.zarr"
    shutil.copytree(out, old)
    meta = json.loads((old / "zarr.json").read_text(encoding="utf-8"))
    meta["attributes"]["clearjoint_store_format"] = 2
    (old / "zarr.json").write_text(json.dumps(meta), encoding="utf-8")
    with pytest.raises(StoreError, match=r"format 2: flat along point.*--force") as info:
        open_sweep(old)
    assert "\n" not in str(info.value)


def test_chunks_written_out_of_order_land_in_their_cells(tmp_path: Path) -> None:
    """A 3 x 4 grid, a per-point pair (dimension ``joint``), chunks of 5 points over rows."""
    grid = Grid(
        ("a", "b"),
        (3, 4),
        {"a": (("a",), np.array([1.0, 2.0, 3.0]), {}), "b": (("b",), np.arange(4), {})},
    )
    store = ResultStore.create(
        tmp_path / "g.zarr",
        fingerprint="f",
        n_points=12,
        chunk_size=5,
        variables=[Variable("x", "f8", {}, shape=(2,)), Variable("status", "str", {})],
        attrs={},
        grid=grid,
    )
    expected_x = np.full((3, 4, 2), np.nan)
    expected_status = np.full((3, 4), "", dtype=object)
    for chunk in (2, 0):  # points 10-11, then 0-4; chunk 1 (points 5-9) never
        a, b = chunk * 5, min(chunk * 5 + 5, 12)
        x = np.stack([np.arange(a, b) + 0.5, -np.arange(a, b) - 0.25], axis=1)
        status = np.array([f"ok {i}" for i in range(a, b)])
        store.write(chunk, {"x": x, "status": status})
        for i in range(a, b):
            expected_x[i // 4, i % 4] = x[i - a]
            expected_status[i // 4, i % 4] = status[i - a]
    store.write_counts()
    plain = _plain_open(tmp_path / "g.zarr")
    assert plain["x"].dims == ("a", "b", "joint")
    np.testing.assert_array_equal(plain["x"].values, expected_x)
    assert plain["status"].values.tolist() == expected_status.tolist()
    assert plain.attrs["points_missing"] == 5
    flat = ResultStore.open(tmp_path / "g.zarr").read()
    np.testing.assert_array_equal(flat["x"][0], expected_x.reshape(12, 2))
