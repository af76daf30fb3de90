"""reproduction.py: the control run is the same campaign without the installation sensitivity."""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest


def test_the_control_campaign_differs_only_in_the_installation_sensitivity() -> None:
    import dataclasses

    from clearjoint.reproduction import without_installation_sensitivity
    from clearjoint.rig import load_campaign

    campaign = load_campaign()
    control = without_installation_sensitivity(campaign)
    assert campaign.rig.frequency_sensitivity > 0
    assert campaign.rig.amplitude_sensitivity > 0
    assert control.rig.frequency_sensitivity == 0.0
    assert control.rig.amplitude_sensitivity == 0.0
    changed = {
        f.name
        for f in dataclasses.fields(campaign.rig)
        if getattr(campaign.rig, f.name) != getattr(control.rig, f.name)
    }
    assert changed == {"frequency_sensitivity", "amplitude_sensitivity"}
    assert control.tests == campaign.tests
    assert control.seed == campaign.seed


def _fake_reproduce(seen: dict[str, object]) -> Callable[..., list[Path]]:
    """Stands in for reproduce(): keeps what it was given and writes an empty findings table."""

    def fake(out_dir: Path, **options: object) -> list[Path]:
        seen.update(options)
        scheduler = getattr(options["executor"], "scheduler", None)  # a live Client's, now
        seen["address"] = getattr(scheduler, "address", None)
        Path(out_dir).mkdir(parents=True, exist_ok=True)
        (Path(out_dir) / "results.json").write_text(json.dumps({"findings": []}))
        return []

    return fake


def test_reproduce_runs_on_a_scheduler_or_a_local_cluster_as_sweep_does(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import socket

    from distributed import LocalCluster

    from clearjoint import parallel, reproduction
    from clearjoint.cli import main

    seen: dict[str, object] = {}
    monkeypatch.setattr(reproduction, "reproduce", _fake_reproduce(seen))
    out = str(tmp_path / "out")
    with LocalCluster(n_workers=1, processes=False, protocol="tcp", dashboard_address=":0") as c:
        assert main(["reproduce", "--out", out, "--scheduler", c.scheduler_address]) == 0
        client = seen["executor"]
        assert type(client).__name__ == "Client"
        assert seen["address"] == c.scheduler_address
        assert seen["jobs"] is None

    asked: list[dict[str, object]] = []

    @contextlib.contextmanager
    def fake_client(address: object = None, **options: object) -> Iterator[str]:
        asked.append({"address": address, **options})
        yield "a client"

    monkeypatch.setattr(parallel, "dask_client", fake_client)
    assert main(["reproduce", "--out", out, "--workers", "3", "--force"]) == 0
    assert asked == [{"address": None, "workers": 3}]
    assert seen["executor"] == "a client"
    assert main(["reproduce", "--out", out, "--jobs", "2", "--force"]) == 0
    assert seen["executor"] is None  # the process pool of --jobs, as before
    assert seen["jobs"] == 2
    capsys.readouterr()

    monkeypatch.undo()  # the real reproduce and dask_client: bad input is one line, no work
    for command, message in [
        (["--scheduler", "tcp://h:1", "--workers", "2"], "leave it out with --scheduler"),
        (["--workers", "2", "--jobs", "2"], "--jobs sizes a process pool"),
    ]:
        assert main(["reproduce", "--out", str(tmp_path / "bad"), *command]) == 2
        assert message in capsys.readouterr().err
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    assert (
        main(
            ["reproduce", "--out", str(tmp_path / "bad"), "--scheduler", f"tcp://127.0.0.1:{port}"]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"cannot reach the Dask scheduler at 'tcp://127.0.0.1:{port}'" in err
    assert not (tmp_path / "bad").exists()
