"""Ctrl-C (issue 28): one line, exit 130, no traceback; what an interrupted run leaves.

Each command runs as a user runs it (``python -m clearjoint ...`` in its own process group)
and gets SIGINT on the whole group, as a terminal's Ctrl-C sends it to the command and its
worker processes alike, once its output shows it has started.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from conftest import SMALL_CAMPAIGN

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def _start(args: list[str], folder: Path) -> tuple[subprocess.Popen[bytes], Path]:
    """Start ``clearjoint ARGS`` in its own process group; return it and its stderr file."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    err = folder / "stderr.txt"
    with err.open("wb") as handle:
        proc = subprocess.Popen(
            [sys.executable, "-m", "clearjoint", *args],
            stdout=subprocess.DEVNULL,
            stderr=handle,
            env=env,
            cwd=folder,
            start_new_session=True,
        )
    return proc, err


def _interrupt_when(
    proc: subprocess.Popen[bytes], ready: Callable[[], bool], timeout: float = 180.0
) -> int:
    """Send SIGINT to the command's process group once ``ready()``; return its exit code."""
    end = time.monotonic() + timeout
    while not ready():
        assert proc.poll() is None, "the command ended before it could be interrupted"
        assert time.monotonic() < end, "the command did not start within the time allowed"
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGINT)
    return proc.wait(timeout=120)


def _said(err: Path, text: str) -> Callable[[], bool]:
    return lambda: text in err.read_text(errors="replace")


def _one_interrupt_line(err: Path, command: str) -> str:
    """The stderr of an interrupted command: no traceback, one line saying so (returned)."""
    text = err.read_text(errors="replace")
    assert "Traceback" not in text, text
    assert "Exception ignored" not in text, text
    lines = [line for line in text.splitlines() if "interrupted" in line]
    assert len(lines) == 1, text
    assert lines[0].startswith(f"clearjoint {command}: interrupted; "), text
    assert text.endswith(lines[0] + "\n"), text  # the last word, nothing after it
    return lines[0]


def test_an_interrupted_reproduce_resumes_where_it_stopped(
    reproduction: Path, tmp_path: Path
) -> None:
    """Ctrl-C while the rig runs: the finished records stay, and the same command run again
    completes the study with the same records as an uninterrupted run (the session's)."""
    (tmp_path / "campaign.toml").write_text(SMALL_CAMPAIGN)
    args = ["reproduce", "--out", "out", "--campaign", "campaign.toml", "--jobs", "2"]
    proc, err = _start(args, tmp_path)
    journal = tmp_path / "out" / "records" / "campaign-progress.jsonl"

    def two_tests_done() -> bool:  # the first line names the campaign, one line per test
        return journal.is_file() and journal.read_text().count("\n") >= 3

    assert _interrupt_when(proc, two_tests_done) == 130
    line = _one_interrupt_line(err, "reproduce")
    assert "run the same command again" in line
    records = tmp_path / "out" / "records"
    assert 2 <= len(list(records.glob("*.nc"))) < 27
    assert not (records / "manifest.csv").exists()
    assert not (tmp_path / "out" / "report.html").exists()
    finished = [
        json.loads(entry)["truth"]["file"] for entry in journal.read_text().splitlines()[1:]
    ]
    before = {name: (records / name).stat().st_mtime_ns for name in finished}

    proc, err = _start(args, tmp_path)
    assert proc.wait(timeout=600) == 0, err.read_text()
    assert (tmp_path / "out" / "report.html").is_file()
    assert not journal.exists()
    # the tests finished before the interruption were kept, not simulated again ...
    assert {name: (records / name).stat().st_mtime_ns for name in finished} == before
    # ... and the whole is what an uninterrupted run writes, bit for bit
    manifest = (records / "manifest.csv").read_bytes()
    assert manifest == (reproduction / "records" / "manifest.csv").read_bytes()
    for name in finished:
        assert (records / name).read_bytes() == (reproduction / "records" / name).read_bytes()


def test_an_interrupted_modes_run_writes_nothing(tmp_path: Path) -> None:
    args = ["modes", str(EXAMPLES / "mast.toml"), "--amplitude", "2mm..7mm"]
    proc, err = _start([*args, "--points", "30", "--out", "m.nc"], tmp_path)
    assert _interrupt_when(proc, _said(err, "clearjoint modes: mode 1 at 30 amplitudes")) == 130
    assert _one_interrupt_line(err, "modes").endswith("nothing written")
    assert not (tmp_path / "m.nc").exists()


def test_an_interrupted_frf_run_writes_nothing(tmp_path: Path) -> None:
    args = ["frf", str(EXAMPLES / "frf.toml"), "--from", "10Hz", "--to", "360Hz"]
    proc, err = _start([*args, "--out", "f.nc", "--plot", "f.png"], tmp_path)
    assert _interrupt_when(proc, _said(err, "clearjoint frf: following the curve")) == 130
    assert _one_interrupt_line(err, "frf").endswith("nothing written")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stderr.txt"]


def test_a_keyboard_interrupt_wrapped_by_compiled_code_is_still_an_interrupt(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C inside numba or scipy code reaches Python as a SystemError whose context is the
    KeyboardInterrupt (the 55-line chain of the issue): still one line and 130."""
    from clearjoint import cli, studies

    def wrapped(*_args: object, **_kwargs: object) -> None:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            # implicitly chained, as the C function's error is
            raise SystemError("<built-in function x> returned a result with an exception set")  # noqa: B904

    monkeypatch.setattr(studies, "nonlinear_modes_of", wrapped)
    out = tmp_path / "h.nc"
    args = ["modes", str(EXAMPLES / "frf.toml"), "--amplitude", "1um..1mm", "--out", str(out)]
    assert cli.main(args) == 130
    err = capsys.readouterr().err
    assert err.splitlines()[-1] == "clearjoint modes: interrupted; nothing written"

    def other(*_args: object, **_kwargs: object) -> None:
        raise SystemError("a real bug")  # not an interrupt: not hidden as one

    monkeypatch.setattr(studies, "nonlinear_modes_of", other)
    with pytest.raises(SystemError, match="a real bug"):
        cli.main(args)


def test_a_file_output_cut_short_is_removed(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C while --out is being written: the incomplete file is removed, and said so."""
    from clearjoint import cli, studies

    out = tmp_path / "f.nc"

    def half_written(*_args: object, **_kwargs: object) -> None:
        out.write_bytes(b"CDF\x01 half")
        raise KeyboardInterrupt

    monkeypatch.setattr(studies, "write_curve", half_written)
    monkeypatch.setattr(studies, "frequency_response_of", lambda *a, **k: None)
    args = ["frf", str(EXAMPLES / "frf.toml"), "--from", "10Hz", "--to", "20Hz", "--out", str(out)]
    assert cli.main([*args, "--quiet"]) == 130
    assert not out.exists()
    assert capsys.readouterr().err == (
        f"clearjoint frf: interrupted; removed the incomplete {out}\n"
    )
