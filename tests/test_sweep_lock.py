"""Tests of one writer per sweep store (issue 27): two clients, a killed one, a create race.

The holder of a lock is another process where it matters (its PID must be named, and
SIGKILL must leave its lock behind with no heartbeat), started here with only
clearjoint.lock imported; the reference results are a run without any store.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from clearjoint.cli import main
from clearjoint.errors import OutputExistsError
from clearjoint.parallel import StoreError
from clearjoint.store import StoreWarning
from clearjoint.sweep import SERIAL, Sweep, open_sweep, run_sweep
from test_sweep_store import STUDY, SWEEP


@pytest.fixture
def sweep_file(tmp_path: Path) -> Path:
    (tmp_path / "study.toml").write_text(STUDY, encoding="utf-8")
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP, encoding="utf-8")
    return path


def test_a_second_client_is_refused_naming_the_first_and_force_cannot_delete_under_it(
    sweep_file: Path, tmp_path: Path
) -> None:
    sweep = Sweep.from_toml(sweep_file)
    reference = run_sweep(sweep, client=SERIAL)
    out = tmp_path / "r.zarr"
    refusals: list[str] = []

    def second_client(done: int, total: int) -> None:
        if done == 0 or refusals:
            return
        for kwargs in ({"resume": True}, {"force": True}, {}):
            with pytest.raises(StoreError, match="is in use by") as info:
                run_sweep(sweep, client=SERIAL, out=out, **kwargs)
            refusals.append(str(info.value))
        assert out.exists()  # --force deleted nothing

    first = run_sweep(sweep, client=SERIAL, out=out, progress=second_client)
    assert len(refusals) == 3
    for text in refusals:
        assert "\n" not in text
        assert f"PID {os.getpid()}" in text
    for name in ("amplitude_m", "energy_input_j", "status"):
        np.testing.assert_array_equal(first[name].values, reference[name].values)
    assert not Path(f"{out}.lock").exists()  # released at the end
    again = run_sweep(sweep, client=SERIAL, out=out, resume=True)  # free again
    assert again.attrs["points_missing"] == 0


def _hold_the_lock(store: Path, timeout: float) -> subprocess.Popen[str]:
    code = (
        "import sys, time\n"
        "from clearjoint.lock import StoreLock\n"
        f"StoreLock({str(store)!r}, timeout={timeout!r}).acquire()\n"
        "print('held', flush=True)\n"
        "time.sleep(120)\n"
    )
    src = str(Path(__file__).resolve().parents[1] / "src")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}
    holder = subprocess.Popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, env=env
    )
    assert holder.stdout is not None
    assert holder.stdout.readline().strip() == "held"
    return holder


@pytest.mark.filterwarnings("default::clearjoint.store.StoreWarning")
def test_a_killed_clients_lock_is_taken_over_after_the_stated_time(
    sweep_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    timeout = 3.0
    out = tmp_path / "r.zarr"
    sweep = Sweep.from_toml(sweep_file)
    holder = _hold_the_lock(out, timeout)
    try:
        command = ["sweep", str(sweep_file), "--out", str(out), "--quiet", "--scheduler"]
        # the CLI's refusal: one line naming the holder's PID (run in this process, serially)
        with pytest.raises(StoreError, match=f"in use by .* PID {holder.pid} "):
            run_sweep(sweep, client=SERIAL, out=out, resume=True, lock_timeout=timeout)
        assert main([*command[:-1], "--force", "--lock-timeout", "3s"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        assert f"PID {holder.pid}" in err
        assert not out.exists()  # nothing was created or deleted under the holder
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
        assert holder.stdout is not None
        holder.stdout.close()
    killed = time.time()
    # right after the kill its last heartbeat is fresh: still refused
    with pytest.raises(StoreError, match="in use by"):
        run_sweep(sweep, client=SERIAL, out=out, resume=True, lock_timeout=timeout)
    assert time.time() - killed < timeout  # (so the refusal above was by the rule)
    time.sleep(timeout + 0.2)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        results = run_sweep(sweep, client=SERIAL, out=out, resume=True, lock_timeout=timeout)
    said = [str(w.message) for w in caught if issubclass(w.category, StoreWarning)]
    assert len(said) == 1
    assert f"took over the lock of {os.uname().nodename} PID {holder.pid}" in said[0]
    assert "more than 3 s" in said[0]
    assert results.attrs["points_missing"] == 0
    assert not Path(f"{out}.lock").exists()


def test_two_clients_starting_at_once_on_a_new_path_never_run_beside_each_other(
    sweep_file: Path, tmp_path: Path
) -> None:
    sweep = Sweep.from_toml(sweep_file)
    out = tmp_path / "new.zarr"
    start = threading.Barrier(2)
    outcomes: list[Any] = [None, None]

    def client(k: int) -> None:
        start.wait()
        try:
            outcomes[k] = run_sweep(sweep, client=SERIAL, out=out, resume=True)
        except Exception as exc:  # kept to be asserted on
            outcomes[k] = exc

    threads = [threading.Thread(target=client, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    errors = [o for o in outcomes if isinstance(o, BaseException)]
    assert len(errors) <= 1
    for error in errors:  # the loser is told who holds the store, never "pass resume=True"
        assert isinstance(error, StoreError)
        assert not isinstance(error, OutputExistsError)
        assert "is in use by" in str(error)
    assert open_sweep(out).attrs["points_missing"] == 0
