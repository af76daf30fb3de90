"""``--plot FILE.png`` on ``clearjoint stiffness``, ``simulate`` and ``dissipation``."""

from __future__ import annotations

from pathlib import Path

import pytest

from clearjoint.cli import main

ROOT = Path(__file__).resolve().parents[1]
STUDY = str(ROOT / "examples" / "study.toml")
JOINT = ["--mass", "2kg", "--stiffness", "8e7N/m", "--clearance", "0.106mm"]
COMMANDS = {
    "stiffness": ["stiffness", *JOINT, "--amplitude", "1um,5um,20um"],
    "dissipation": ["dissipation", *JOINT, "--amplitude", "1um,5um,20um", "--restitution", "0.8"],
    "simulate": ["simulate", STUDY],
}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    try:
        code = main(args)
    except SystemExit as exc:
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("command", list(COMMANDS))
def test_plot_writes_a_png_and_refuses_to_overwrite_it(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "figure.png"
    code, out, _ = run([*COMMANDS[command], "--plot", str(target)], capsys)
    assert code == 0
    assert target.read_bytes()[:8] == PNG_MAGIC
    assert f"wrote {target}" in out
    before = target.stat().st_mtime_ns
    code, out, err = run([*COMMANDS[command], "--plot", str(target)], capsys)
    assert code == 2
    assert out == ""
    assert len(err.strip().splitlines()) == 1
    assert "--force" in err
    assert str(target) in err
    assert target.stat().st_mtime_ns == before
    code, _, _ = run([*COMMANDS[command], "--plot", str(target), "--force"], capsys)
    assert code == 0


@pytest.mark.parametrize("command", list(COMMANDS))
def test_plot_refuses_a_suffix_that_is_not_a_figure(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "figure.csv"
    code, _out, err = run([*COMMANDS[command], "--plot", str(target)], capsys)
    assert code == 2
    assert "--plot must end in .png" in err
    assert "'figure.csv'" in err
    assert len(err.strip().splitlines()) == 1
    assert not target.exists()


def test_plot_keeps_json_output_clean(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import json

    target = tmp_path / "curve.svg"
    code, out, _ = run([*COMMANDS["stiffness"], "--json", "--plot", str(target)], capsys)
    assert code == 0
    assert json.loads(out)["stiffness_coefficient"][0] > 0.0
    assert target.read_text(encoding="utf-8").lstrip().startswith("<?xml")


MAST = str(ROOT / "examples" / "mast.toml")
NEWER = {
    "frf": ["frf", STUDY, "--from", "300Hz", "--to", "310Hz"],
    "modes": ["modes", STUDY, "--amplitude", "0.3mm..3mm", "--points", "3"],
    "structure": ["structure", MAST, "modes"],
}


@pytest.mark.parametrize("command", list(NEWER))
@pytest.mark.parametrize(
    ("out", "plot", "message"),
    [
        ("r.nc", "figure.csv", "--plot must end in .png, .pdf, .svg, got 'figure.csv'"),
        ("r.csv", "figure.png", "writes netCDF; name the file .nc"),
        ("r.nc", "exists.png", "will not overwrite"),
    ],
)
def test_newer_commands_check_out_and_plot_before_the_work(
    command: str,
    out: str,
    plot: str,
    message: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """frf, modes and structure: --out and --plot refused in one line, and nothing written."""
    (tmp_path / "exists.png").write_bytes(b"mine")
    args = [*NEWER[command], "--out", str(tmp_path / out), "--plot", str(tmp_path / plot)]
    code, stdout, err = run(args, capsys)
    assert code == 2
    assert stdout == ""
    assert message in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / out).exists()
    assert (tmp_path / "exists.png").read_bytes() == b"mine"
