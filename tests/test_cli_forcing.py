"""One meaning per option name (issue 28, Build 6): ``--force`` overwrites, so frf's
continuation parameter ``--parameter force`` is now ``--parameter forcing``; the old
spelling keeps working with one deprecation line on stderr."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from clearjoint import cli, cli_parser

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "frf.toml"
# a short force curve inside the gap at 300 Hz, where the orbit is linear
CURVE = ["--from", "10N", "--to", "20N", "--frequency", "300Hz", "--json", "--quiet"]


def test_forcing_follows_the_force_amplitude(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["frf", str(EXAMPLE), "--parameter", "forcing", *CURVE, "--out", str(tmp_path / "f.nc")]
    assert cli.main(args) == 0
    out, err = capsys.readouterr()
    assert err == ""
    data = json.loads(out)
    assert data["force_n"][0] == pytest.approx(10.0)
    assert data["force_n"][-1] == pytest.approx(20.0)
    # inside the gap: X = F0 / |k0 - m w^2 + i c w| (examples/frf.toml: m = 1 kg)
    w = 2 * math.pi * 300.0
    k0, c = 1.5791e6, 2 * 0.014434 * math.sqrt(4.7374e6)
    assert data["amplitude_m"][0] == pytest.approx(10.0 / math.hypot(k0 - w * w, c * w), 1e-9)


def test_the_old_spelling_runs_the_same_curve_with_one_deprecation_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(cli_parser, "DEPRECATION_LINES_IN_PROCESS", True)  # as the command says it
    runs = {}
    for value in ("forcing", "force"):
        out = tmp_path / f"{value}.nc"
        assert cli.main(["frf", str(EXAMPLE), "--parameter", value, *CURVE, "--out", str(out)]) == 0
        text, err = capsys.readouterr()
        runs[value] = (json.loads(text), err)
    assert runs["force"][0] == runs["forcing"][0]
    assert runs["forcing"][1] == ""
    assert runs["force"][1] == (
        "clearjoint frf: warning: --parameter force is now --parameter forcing "
        "(--force means overwrite); write --parameter forcing\n"
    )


def test_the_command_says_the_old_spelling_is_old(tmp_path: Path) -> None:
    """Run as the command (not main() from Python): the line is on by default."""
    args = [sys.executable, "-m", "clearjoint", "frf", str(EXAMPLE), "--parameter", "force"]
    args += [*CURVE, "--out", str(tmp_path / "f.nc")]
    result = subprocess.run(args, capture_output=True, text=True, check=False, cwd=ROOT)
    assert result.returncode == 0, result.stderr
    assert result.stderr.splitlines() == [
        "clearjoint frf: warning: --parameter force is now --parameter forcing "
        "(--force means overwrite); write --parameter forcing"
    ]


def test_help_and_errors_name_forcing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        cli.main(["frf", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--parameter {frequency,forcing}" in text
    assert "With --parameter forcing, --from and --to are forces" in text
    args = ["frf", str(EXAMPLE), "--from", "20Hz", "--to", "90Hz", "--frequency", "5Hz"]
    assert cli.main([*args, "--out", str(tmp_path / "x.nc")]) == 2
    assert capsys.readouterr().err == (
        "clearjoint frf: error: --frequency goes with --parameter forcing (formerly "
        "--parameter force); drop it or add that\n"
    )
