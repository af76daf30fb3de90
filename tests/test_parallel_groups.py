"""Short tasks grouped into fewer Dask tasks (issue 27): each keeps its own outcome."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from clearjoint.errors import ParameterError
from clearjoint.parallel import MAX_GROUP, TASKS_PER_THREAD, auto_group, dask_client, run_batches
from clearjoint.store import StoreError
from clearjoint.sweep import SERIAL, Sweep, run_sweep

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _square_but_seven(x: int) -> int:
    if x == 7:
        raise ArithmeticError("no convergence at 7")
    return x * x


def test_auto_group_keeps_every_thread_in_tasks_and_caps_their_size() -> None:
    assert (TASKS_PER_THREAD, MAX_GROUP) == (4, 64)  # the documented rule
    assert auto_group(2000, 2) == 64  # 2000 // 8 = 250, capped
    assert auto_group(10_000, 200) == 12  # 10000 // 800
    assert auto_group(20, 2) == 2  # 20 chunks of 0.5 s on 2 workers: 10 Dask tasks
    assert auto_group(7, 2) == 1  # fewer tasks than 4 a thread: never grouped
    assert auto_group(5, 0) == 1


@pytest.mark.parametrize("group", [1, 3, 5, None])
def test_grouped_tasks_give_each_argument_its_own_outcome_once(group: int | None) -> None:
    arguments = list(range(17))  # 17 = 3 x 5 + 2: the last group is short
    with dask_client(workers=2, processes=False) as client:
        outcomes = [
            o
            for batch in run_batches(_square_but_seven, arguments, client, group=group)
            for o in batch
        ]
    assert sorted(o.index for o in outcomes) == arguments
    by_index = {o.index: o for o in outcomes}
    assert isinstance(by_index[7].error, ArithmeticError)  # fails alone, not its group
    assert {i: o.result for i, o in by_index.items() if i != 7} == {
        i: i * i for i in arguments if i != 7
    }
    with pytest.raises(ParameterError, match="group must be >= 1"):
        next(run_batches(_square_but_seven, arguments, client, group=0))


def test_a_sweep_of_one_point_chunks_on_dask_equals_the_serial_run(tmp_path: Path) -> None:
    """Grouped on Dask, stored by the writer thread: the Dataset and the store as serial."""
    sweep = Sweep.from_toml(EXAMPLES / "tolerance.toml")
    sweep = replace(sweep, samples=40, chunk_size=1)  # 80 chunks: grouped 10 a Dask task
    assert auto_group(80, 2) == 10
    serial = run_sweep(sweep, client=SERIAL)
    with dask_client(workers=2, processes=False) as client:
        on_dask = run_sweep(sweep, client=client, out=tmp_path / "r.zarr")
    xr.testing.assert_identical(on_dask.drop_attrs(deep=False), serial.drop_attrs(deep=False))
    with xr.open_zarr(tmp_path / "r.zarr") as plain:
        xr.testing.assert_identical(plain.load(), on_dask)


def test_a_write_that_fails_in_the_writer_thread_is_raised_by_the_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import clearjoint.store

    sweep = replace(Sweep.from_toml(EXAMPLES / "tolerance.toml"), samples=10, chunk_size=1)

    def full_disk(self: object, chunks: object) -> None:
        raise StoreError("disk full (as a write would say it)")

    monkeypatch.setattr(clearjoint.store.ResultStore, "write_many", full_disk)
    with (
        dask_client(workers=1, processes=False) as client,
        pytest.raises(StoreError, match="disk full"),
    ):
        run_sweep(sweep, client=client, out=tmp_path / "r.zarr")
    assert np.isnan(xr.open_zarr(tmp_path / "r.zarr")["natural_frequency_hz"]).all()
