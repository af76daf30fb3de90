"""Runaway requests, unusual values and progress on the command line (issue 28).

A request estimated above an hour is refused before any work with its estimate and the
option that allows it; values legal but unusual for a pin joint get one warning line each;
long commands show progress, as lines every few seconds when stderr is no terminal.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import pytest

from clearjoint import cli, cli_progress, studies
from clearjoint.errors import ParameterError

ROOT = Path(__file__).resolve().parents[1]
FRF = str(ROOT / "examples" / "frf.toml")


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = cli.main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_a_hundred_million_mode_amplitudes_are_refused_up_front(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The issue's command: refused at once (no 800 MB of amplitudes made), exit 2, one line
    with the estimate: 1e8 points at 0.02 s each are 2e6 s, 23 days."""
    out = tmp_path / "h.nc"
    args = ["modes", FRF, "--amplitude", "1um..1mm", "--points", "100000000", "--out", str(out)]
    code, _, err = _run(args, capsys)
    assert code == 2
    assert err.count("\n") == 1
    assert err.startswith("clearjoint modes: error: --points 100000000: about 23 days")
    assert "above the limit of 60 min" in err
    assert "--allow-long" in err
    assert not out.exists()


def test_a_curve_of_a_hundred_million_points_at_most_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["frf", FRF, "--from", "10Hz", "--to", "360Hz", "--max-points", "100000000"]
    code, _, err = _run([*args, "--out", str(tmp_path / "f.nc")], capsys)
    assert code == 2
    assert err.count("\n") == 1
    # 1e8 points at 0.01 s each: 1e6 s, 11.6 days
    assert err.startswith("clearjoint frf: error: --max-points 100000000: about 12 days")
    assert "--allow-long" in err


def test_allow_long_runs_what_the_estimate_refuses(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """500,000 amplitudes (10,000 s estimated) are refused, and reach the solver with
    --allow-long (stood in for here: the run itself would take hours)."""

    def solver(_study: object, _mode: int, amplitudes: object, **_: object) -> None:
        raise ParameterError(f"reached the solver with {len(amplitudes)} amplitudes")  # type: ignore[arg-type]

    monkeypatch.setattr(studies, "nonlinear_modes_of", solver)
    args = ["modes", FRF, "--amplitude", "1um..1mm", "--points", "500000", "--quiet"]
    args += ["--out", str(tmp_path / "h.nc")]
    code, _, err = _run(args, capsys)
    assert code == 2
    assert "about 2.8 h" in err  # 500,000 x 0.02 s = 10,000 s
    code, _, err = _run([*args, "--allow-long"], capsys)
    assert code == 2
    assert err == "clearjoint modes: error: reached the solver with 500000 amplitudes\n"
    code, _, err = _run([*args[:5], "40", *args[6:]], capsys)  # the default count: no check
    assert "reached the solver with 40 amplitudes" in err


JOINT = ["--mass", "2kg", "--stiffness", "8e7N/m", "--amplitude", "5um"]


@pytest.mark.parametrize(
    ("options", "warning"),
    [
        (
            ["--clearance", "0.1m"],
            "clearjoint stiffness: warning: --clearance is 100 mm, unusual for a pin joint",
        ),
        (
            ["--clearance", "0.1mm", "--mass", "2t"],
            "clearjoint stiffness: warning: --mass is 2 t, above a tonne",
        ),
    ],
)
def test_an_unusual_clearance_or_mass_gets_one_warning_line(
    options: list[str], warning: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = _run(["stiffness", *JOINT, *options], capsys)
    assert code == 0
    assert "k_d" in out  # it still runs: legal values
    assert err.count("\n") == 1
    assert err.startswith(warning)


def test_usual_values_get_no_warning(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _run(["stiffness", *JOINT, "--clearance", "0.106mm", "--mass", "999kg"], capsys)
    assert (code, err) == (0, "")


@pytest.mark.parametrize(
    ("start", "hz"),
    [("100rpm", "1.667"), ("30rpm", "0.5")],  # 100 / 60 and 30 / 60 revolutions a second
)
def test_a_frequency_in_rpm_is_said_in_hz(
    start: str,
    hz: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    def curve(*_args: object, **_kwargs: object) -> None:
        raise ParameterError("stopped before the curve")

    monkeypatch.setattr(studies, "frequency_response_of", curve)
    args = ["frf", FRF, "--from", start, "--to", "360Hz", "--quiet"]
    code, _, err = _run([*args, "--out", str(tmp_path / "f.nc")], capsys)
    assert code == 2
    number = start.removesuffix("rpm")
    assert err.splitlines() == [
        f"clearjoint frf: warning: --from {start} is {hz} Hz (rpm counts revolutions per "
        f"minute); write {number}Hz if hertz was meant",
        "clearjoint frf: error: stopped before the curve",
    ]
    code, _, err = _run([*args[:3], "2Hz", *args[4:], "--out", str(tmp_path / "g.nc")], capsys)
    assert err == "clearjoint frf: error: stopped before the curve\n"  # Hz: no warning


def test_progress_without_a_terminal_is_a_line_now_and_then(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """stderr is no terminal under pytest: a first line, then the share done and the time
    left (every report here, the interval set to 0); --quiet: none of it."""
    monkeypatch.setattr(cli_progress, "PROGRESS_EVERY_S", 0.0)
    monkeypatch.setattr(
        cli_progress, "PROGRESS_LINES_IN_PROCESS", True
    )  # as the command prints them
    args = ["modes", FRF, "--amplitude", "10um..100um", "--points", "4", "--harmonics", "3"]
    code, _, err = _run([*args, "--out", str(tmp_path / "a.nc")], capsys)
    assert code == 0, err
    # a first run in this process may say it compiles (tests/test_cli_first_run.py)
    lines = [
        line
        for line in err.splitlines()
        if "warning" not in line and "compiling the solvers" not in line
    ]
    assert lines[0] == "clearjoint modes: mode 1 at 4 amplitudes"
    shares = [line.split(": ")[1].split(" %")[0] for line in lines[1:]]
    # one amplitude of 4 at a time; the first report starts the clock the time left is
    # estimated from (a compile may come before it), so the first share said is 50 %
    assert shares == ["50", "75", "100"]
    assert all(line.endswith(" left") for line in lines[1:])
    code, _, err = _run([*args, "--out", str(tmp_path / "b.nc"), "--quiet"], capsys)
    assert code == 0
    assert [line for line in err.splitlines() if "warning" not in line] == []


def _subcommands() -> dict[str, argparse.ArgumentParser]:
    from clearjoint.cli_parser import build_parser

    parser = build_parser()
    (sub,) = (a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_every_default_is_shown_in_help() -> None:
    """Each option with a default value names it in its --help text (none forgotten)."""
    missing = []
    for name, sub in _subcommands().items():
        for action in sub._actions:
            shown = action.default not in (None, False, argparse.SUPPRESS)
            if not action.option_strings or not shown:
                continue
            if "default" not in sub._get_formatter()._expand_help(action):  # as --help prints
                missing.append(f"{name} {action.option_strings[-1]}")
    assert missing == []
    help_text = " ".join(_subcommands()["reproduce"].format_help().split())
    assert "(default clearjoint-reproduction)" in help_text  # one argparse did not show


def test_options_mean_one_thing_with_one_default_everywhere() -> None:
    commands = _subcommands()
    for name in ("rig", "reproduce", "identify"):
        (jobs,) = (a for a in commands[name]._actions if "--jobs" in a.option_strings)
        assert jobs.default is None, name  # every core, in each
        assert "every core" in (jobs.help or ""), name
    for name in ("rig", "identify", "sweep", "reproduce", "report", "frf", "modes", "structure"):
        assert any("--quiet" in a.option_strings for a in commands[name]._actions), name
    (region,) = (a for a in commands["dissipation"]._actions if a.dest == "friction_region")
    assert "free-play stroke only" in (region.help or "")
    for name in ("stiffness", "dissipation", "modes"):
        (amplitude,) = (a for a in commands[name]._actions if a.dest == "amplitude")
        assert "one (5um), a list (1um,5um,20um) or a range (1um..1mm" in (amplitude.help or "")


def test_an_amplitude_range_reads_the_same_in_stiffness_as_in_modes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """1um..100um with 3 points is 1, 10 and 100 um (log spacing), as the list says them."""
    joint = ["--mass", "2kg", "--stiffness", "8e7N/m", "--clearance", "0.106mm", "--json"]
    code, ranged, _ = _run(
        ["stiffness", *joint, "--amplitude", "1um..100um", "--points", "3"], capsys
    )
    assert code == 0
    code, listed, _ = _run(["stiffness", *joint, "--amplitude", "1um,10um,100um"], capsys)
    assert code == 0
    assert json.loads(ranged)["amplitude_m"] == pytest.approx([1e-6, 1e-5, 1e-4], rel=1e-12)
    ranged_table, listed_table = json.loads(ranged), json.loads(listed)
    assert ranged_table.keys() == listed_table.keys()
    for key, value in ranged_table.items():  # pytest 9.2's approx takes no nested dicts
        if isinstance(value, str):
            assert value == listed_table[key], key
        else:
            assert value == pytest.approx(listed_table[key], rel=1e-12), key

    seen: list[list[float]] = []

    def solver(_study: object, _mode: int, amplitudes: Any, **_: object) -> None:
        seen.append(list(amplitudes))
        raise ParameterError("stopped")

    monkeypatch.setattr(studies, "nonlinear_modes_of", solver)
    out = ["--out", str(tmp_path / "m.nc"), "--quiet"]
    assert cli.main(["modes", FRF, "--amplitude", "1um,10um,100um", *out]) == 2
    assert len(seen) == 1
    assert seen[0] == pytest.approx([1e-6, 1e-5, 1e-4], rel=1e-12)
    assert cli.main(["modes", FRF, "--amplitude", "10um,1um", *out]) == 2
    assert "must be above zero and ascending" in capsys.readouterr().err


_JOINT = ["--mass", "2kg", "--stiffness", "8e7N/m", "--clearance", "0.1mm"]


@pytest.mark.parametrize(
    "command",
    [
        ["stiffness", *_JOINT],
        ["dissipation", "--study", str(ROOT / "examples" / "study.toml")],
    ],
)
def test_a_hundred_million_table_amplitudes_are_refused_up_front(
    command: list[str], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """stiffness and dissipation take microseconds a point: the limit is memory. 1e8 points
    at 500 bytes (clearjoint.budget's published cost) are 5e10 bytes, 46.6 GiB, above 4 GiB;
    the machine this was measured on had 23 GiB. 8e6 points (3.7 GiB) pass."""
    from clearjoint import units

    args = [*command, "--amplitude", "1um..1mm", "--points"]
    code, out, err = _run([*args, "100000000"], capsys)
    assert (code, out) == (2, "")
    assert err == (
        f"clearjoint {command[0]}: error: --points 100000000: about 47 GiB of table in memory "
        "(500 bytes a point), above the limit of 4 GiB; ask for fewer, or pass --allow-long "
        "to run it anyway\n"
    )

    def reached(*_args: object) -> None:
        raise ParameterError("reached the range")

    monkeypatch.setattr(units, "parse_amplitude_range", reached)
    for points in (["8000000"], ["100000000", "--allow-long"]):
        code, out, err = _run([*args, *points], capsys)
        assert (code, err) == (2, f"clearjoint {command[0]}: error: reached the range\n")
