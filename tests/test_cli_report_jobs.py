"""``clearjoint report`` on a folder of records: --jobs and progress (issue 28, Build 2 and 6).

The records are identified by --jobs processes, every core by default as in ``identify``,
``rig`` and ``reproduce``, with the same results as one process; without a terminal the
command says how far the identification is, as ``identify`` does.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from clearjoint import cli, cli_progress

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "tests" / "data" / "brfd"  # three BRFD records a clone ships


def _records(tmp_path: Path) -> Path:
    folder = tmp_path / "records"
    folder.mkdir()
    for path in sorted(SHIPPED.glob("*.json")):
        shutil.copy(path, folder / path.name)
    return folder


def test_report_with_two_jobs_writes_what_one_writes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = _records(tmp_path)
    assert len(list(folder.glob("*.json"))) == 3
    monkeypatch.setattr(cli_progress, "PROGRESS_EVERY_S", 0.0)
    monkeypatch.setattr(cli_progress, "PROGRESS_LINES_IN_PROCESS", True)  # as the command
    one, two = tmp_path / "one", tmp_path / "two"
    assert cli.main(["report", "--records", str(folder), "--out", str(one), "--jobs", "1"]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if "% done" in line]
    assert [line.split(": ")[1].split(" %")[0] for line in lines] == ["67", "100"]  # 2 of 3, 3
    assert all(line.startswith("clearjoint report: ") for line in lines)
    assert cli.main(["report", "--records", str(folder), "--out", str(two), "--jobs", "2"]) == 0
    for name in ("results.json", "results.csv", "fits.csv"):
        assert (one / name).read_bytes() == (two / name).read_bytes(), name
    assert json.loads((one / "results.json").read_text())["findings"]


def test_report_refuses_no_jobs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = _records(tmp_path)
    code = cli.main(
        ["report", "--records", str(folder), "--out", str(tmp_path / "r"), "--jobs", "0"]
    )
    assert code == 2
    assert capsys.readouterr().err == "clearjoint report: error: --jobs must be at least 1, got 0\n"
    assert not (tmp_path / "r").exists()


def test_report_jobs_defaults_to_every_core_as_identify() -> None:
    from clearjoint.cli_parser import build_parser

    parser = build_parser()
    (sub,) = (a for a in parser._actions if hasattr(a, "choices") and a.choices)
    for name in ("identify", "report"):
        (jobs,) = (a for a in sub.choices[name]._actions if "--jobs" in a.option_strings)
        assert jobs.default is None, name
        assert jobs.help == (
            "processes over the files (default: every core; the results do not depend on it)"
        ), name
