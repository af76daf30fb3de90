"""Tests of a sweep store's integrity: damage as a cluster's file system makes it (issue 27).

Each damage is done to a copy of a finished store, by hand on its files (never through
the code under test); the reference is the undamaged run. A plain open must refuse the
damaged store naming the chunk; ``--resume`` must give back a Dataset identical to the
undamaged one, saying in one line how many points it recomputes.
"""

from __future__ import annotations

import json
import shutil
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from distributed import LocalCluster

import clearjoint.store
from clearjoint.cli import main
from clearjoint.parallel import StoreError
from clearjoint.store import StoreWarning
from clearjoint.sweep import SERIAL, Sweep, open_sweep, run_sweep

STUDY = """
[joint]
mass = "2kg"
clearance = "0.1mm"
compression_stiffness = "8e7N/m"
[excitation]
force_amplitude = "500N"
frequency = "400Hz"
[losses]
damping_ratio = 0.02
restitution = 0.8
"""

# 5 points in chunks of 2: chunks 0 (points 0-1), 1 (points 2-3), 2 (point 4)
SWEEP = """
base = "study.toml"
chunk_size = 2
[task]
name = "steady_state"
outputs = ["amplitude_m", "energy_input_j"]
samples_per_period = 16
[axes.excitation]
force_amplitude = ["200N", "400N", "600N", "800N", "1kN"]
"""


@pytest.fixture(scope="module")
def finished(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, xr.Dataset]:
    """The sweep file, a finished store of it, and its results (the undamaged reference)."""
    folder = tmp_path_factory.mktemp("store")
    (folder / "study.toml").write_text(STUDY, encoding="utf-8")
    path = folder / "sweep.toml"
    path.write_text(SWEEP, encoding="utf-8")
    out = folder / "whole.zarr"
    with pytest.MonkeyPatch.context() as patch:  # a file per task chunk: a neighbour to copy
        patch.setattr(clearjoint.store, "POINTS_PER_FILE", 1)
        results = run_sweep(Sweep.from_toml(path), client=SERIAL, out=out)
    return path, out, results


def _chunk_file(store: Path, name: str, chunk: int) -> Path:
    """The file of one chunk of a 1-D array, read from the array's own zarr.json."""
    meta = json.loads((store / name / "zarr.json").read_text(encoding="utf-8"))
    encoding = meta["chunk_key_encoding"]
    assert encoding["name"] == "default"
    separator = encoding.get("configuration", {}).get("separator", "/")
    return store / name / f"c{separator}{chunk}"


def _delete(store: Path) -> None:
    _chunk_file(store, "amplitude_m", 1).unlink()


def _flip_a_bit(store: Path) -> None:
    file = _chunk_file(store, "amplitude_m", 1)
    data = bytearray(file.read_bytes())
    data[len(data) // 2] ^= 0x04
    file.write_bytes(bytes(data))


def _neighbour(store: Path) -> None:
    shutil.copyfile(_chunk_file(store, "amplitude_m", 0), _chunk_file(store, "amplitude_m", 1))


def _truncate(store: Path) -> None:
    file = _chunk_file(store, "amplitude_m", 1)
    file.write_bytes(file.read_bytes()[:7])


def _empty(store: Path) -> None:
    _chunk_file(store, "amplitude_m", 1).write_bytes(b"")


def _status_deleted(store: Path) -> None:
    _chunk_file(store, "status", 1).unlink()


def _rewritten_consistently(store: Path) -> None:
    """A wrong value written through zarr itself: its crc32c is right, only the digest sees it."""
    import zarr

    array = zarr.open_array(str(store / "amplitude_m"), mode="r+")
    values = np.asarray(array[2:4])
    array[2:4] = values * (1 + 0.0037)


DAMAGE: dict[str, Callable[[Path], None]] = {
    "deleted": _delete,
    "flipped bit": _flip_a_bit,
    "neighbour chunk": _neighbour,
    "truncated": _truncate,
    "emptied": _empty,
    "status deleted": _status_deleted,
    "rewritten with a wrong value": _rewritten_consistently,
}


@pytest.mark.parametrize("damage", list(DAMAGE))
def test_damage_is_refused_on_open_and_recomputed_on_resume(
    finished: tuple[Path, Path, xr.Dataset], tmp_path: Path, damage: str
) -> None:
    sweep_file, whole, reference = finished
    copy = tmp_path / "copy.zarr"
    shutil.copytree(whole, copy)
    DAMAGE[damage](copy)
    with pytest.raises(StoreError, match=r"chunk 1 \(points 2-3\) is damaged") as info:
        open_sweep(copy)
    assert "\n" not in str(info.value)
    assert "--resume" in str(info.value)
    calls: list[tuple[int, int]] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        resumed = run_sweep(
            Sweep.from_toml(sweep_file),
            client=SERIAL,
            out=copy,
            resume=True,
            progress=lambda d, t: calls.append((d, t)),
        )
    said = [str(w.message) for w in caught if issubclass(w.category, StoreWarning)]
    assert len(said) == 1
    assert "recomputing 2 points of 1 damaged chunks" in said[0]
    assert calls[0] == (3, 5)  # the two undamaged chunks kept, only chunk 1 computed
    xr.testing.assert_identical(resumed, reference)
    xr.testing.assert_identical(open_sweep(copy), reference)


@pytest.mark.filterwarnings("default::clearjoint.store.StoreWarning")
def test_the_command_line_says_the_repair_in_one_line_and_a_damaged_open_in_one_line(
    finished: tuple[Path, Path, xr.Dataset], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    sweep_file, whole, reference = finished
    copy = tmp_path / "copy.zarr"
    shutil.copytree(whole, copy)
    _flip_a_bit(copy)
    assert main(["sweep", "--plot", str(copy), "amplitude_m"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "chunk 1 (points 2-3) is damaged: amplitude_m does not decode" in err
    # a "running cluster" in this process, reached by its address as --scheduler would
    with LocalCluster(n_workers=1, processes=False, protocol="tcp", dashboard_address=":0") as c:
        command = ["sweep", str(sweep_file), "--out", str(copy), "--resume", "--quiet"]
        assert main([*command, "--scheduler", c.scheduler_address]) == 0
    out, err = capsys.readouterr()
    assert err.count("\n") == 1
    assert "warning:" in err
    assert "recomputing 2 points of 1 damaged chunks" in err
    assert "3 of them kept from the store" in out
    xr.testing.assert_identical(open_sweep(copy), reference)


def test_a_damaged_done_flag_is_recomputed_and_never_read_as_done(
    finished: tuple[Path, Path, xr.Dataset], tmp_path: Path
) -> None:
    sweep_file, whole, reference = finished
    copy = tmp_path / "copy.zarr"
    shutil.copytree(whole, copy)
    _chunk_file(copy, "clearjoint/chunk_done", 2).write_bytes(b"\x00")  # in its subgroup
    with pytest.raises(StoreError, match=r"chunk 2 \(point 4\) is damaged: its done flag"):
        open_sweep(copy)
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        resumed = run_sweep(Sweep.from_toml(sweep_file), client=SERIAL, out=copy, resume=True)
    xr.testing.assert_identical(resumed, reference)


def test_a_store_of_the_older_format_is_one_clear_line(
    finished: tuple[Path, Path, xr.Dataset], tmp_path: Path
) -> None:
    sweep_file, whole, _ = finished
    old = tmp_path / "old.zarr"
    shutil.copytree(whole, old)
    meta_file = old / "zarr.json"
    meta = json.loads(meta_file.read_text(encoding="utf-8"))
    del meta["attributes"]["clearjoint_store_format"]  # as clearjoint wrote stores before
    meta_file.write_text(json.dumps(meta), encoding="utf-8")
    for attempt in (
        lambda: open_sweep(old),
        lambda: run_sweep(Sweep.from_toml(sweep_file), client=SERIAL, out=old, resume=True),
    ):
        with pytest.raises(StoreError, match=r"older clearjoint .*--force") as info:
            attempt()
        assert "\n" not in str(info.value)


def test_task_chunks_sharing_a_file_are_all_recomputed_when_it_is_damaged(
    finished: tuple[Path, Path, xr.Dataset], tmp_path: Path
) -> None:
    sweep_file, _, reference = finished
    out = tmp_path / "shared.zarr"
    run_sweep(Sweep.from_toml(sweep_file), client=SERIAL, out=out)  # every chunk in one file
    assert not _chunk_file(out, "amplitude_m", 1).exists()
    _chunk_file(out, "amplitude_m", 0).write_bytes(b"\x00" * 9)
    with pytest.raises(StoreError, match=r"chunk 0 \(points 0-1\) is damaged.*2 other chunks"):
        open_sweep(out)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        resumed = run_sweep(Sweep.from_toml(sweep_file), client=SERIAL, out=out, resume=True)
    said = [str(w.message) for w in caught if issubclass(w.category, StoreWarning)]
    assert "recomputing 5 points of 3 damaged chunks" in said[0]
    xr.testing.assert_identical(resumed, reference)
