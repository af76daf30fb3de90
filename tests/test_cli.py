"""The command line: stiffness table and JSON, one-line errors with exit code 2, reproduce."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from clearjoint.cli import main

BASE = ["stiffness", "--mass", "2kg", "--stiffness", "8e7N/m", "--clearance", "0.106mm"]


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    try:
        code = main(args)
    except SystemExit as exc:  # argparse exits on usage errors
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def test_json_keys_and_arrays_for_several_amplitudes(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run([*BASE, "--amplitude", "1um,5um,20um", "--json"], capsys)
    assert code == 0
    data = json.loads(out)
    for key in (
        "period_s",
        "natural_frequency_hz",
        "dynamic_stiffness_n_per_m",
        "stiffness_coefficient",
    ):
        assert len(data[key]) == 3
    # eq 9 by hand, independent of the library
    for a, c_d in zip((1e-6, 5e-6, 20e-6), data["stiffness_coefficient"], strict=True):
        assert c_d == pytest.approx((math.pi * a / (math.pi * a + 0.106e-3)) ** 2, rel=1e-9)
    f1 = math.sqrt(8e7 / 2.0) / (2 * math.pi)
    assert data["natural_frequency_hz"][2] == pytest.approx(
        f1 / (1 + 0.106e-3 / (math.pi * 20e-6)), rel=1e-9
    )
    assert data["dynamic_stiffness_n_per_m"][1] == pytest.approx(
        2.0 * (2 * math.pi * data["natural_frequency_hz"][1]) ** 2, rel=1e-12
    )


def test_json_scalar_for_one_amplitude(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        [*BASE, "--amplitude", "5um", "--json", "--tension-stiffness", "4e7N/m"], capsys
    )
    assert code == 0
    assert isinstance(json.loads(out)["period_s"], float)


@pytest.mark.parametrize(
    ("option", "bare", "line"),
    [
        ("--clearance", "0.106", "--clearance 0.106: give a unit, e.g. 0.106mm"),
        ("--mass", "2", "--mass 2: give a unit, e.g. 2kg"),
        ("--stiffness", "8e7", "--stiffness 8e7: give a unit, e.g. 8e7N/m"),
        ("--amplitude", "5", "--amplitude 5: give a unit, e.g. 5mm"),
        ("--gap-stiffness", "1e5", "--gap-stiffness 1e5: give a unit, e.g. 1e5N/m"),
    ],
)
def test_bare_numbers_are_refused_with_the_way_to_write_them(
    option: str, bare: str, line: str, capsys: pytest.CaptureFixture[str]
) -> None:
    args = [*BASE, "--amplitude", "5um", "--json"]
    if option in args:
        args[args.index(option) + 1] = bare
    else:
        args += [option, bare]
    code, out, err = run(args, capsys)
    assert code == 2
    assert out == ""
    assert err.strip() == f"clearjoint stiffness: error: {line}"


def test_table_is_printed(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run([*BASE, "--amplitude", "0,20um"], capsys)
    assert code == 0
    assert "c_d" in out
    assert "0.1385" in out  # eq 9 at A = 20 um, c = 0.106 mm
    assert "inf" in out  # A = 0: the mass never moves


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--amplitude", "-1um"], "--amplitude"),
        (["--amplitude=-1um"], "amplitude must be >= 0"),
        (["--amplitude", "nan um"], "amplitude must be finite"),
        (["--amplitude", "5kg"], "is not a length"),
        (["--amplitude", "5furlongz"], "cannot read"),
        (["--amplitude", "1um,,2um"], "empty entry"),
        (["--amplitude", "1um", "--gap-offset", "1mm"], "gap_offset must lie within"),
        (["--amplitude", "1um", "--gap-stiffness", "5N"], "is not a stiffness"),
        ([], "required"),
    ],
)
def test_bad_input_is_one_line_and_exit_code_2(
    extra: list[str], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run([*BASE, *extra], capsys)
    assert code == 2
    assert out == ""
    assert len(err.strip().splitlines()) == 1
    assert words in err


def test_runs_as_a_module() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "clearjoint", *BASE, "--amplitude", "5um", "--json"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "period_s" in json.loads(result.stdout)


DISSIPATION = ["dissipation", "--mass", "2kg", "--stiffness", "8e7N/m", "--clearance", "0.106mm"]


def test_dissipation_json_keys_and_values(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        [
            *DISSIPATION,
            "--amplitude",
            "20um",
            "--json",
            "--friction-coefficient",
            "0.2",
            "--lateral-load",
            "300N",
            "--restitution",
            "0.8",
            "--pin-radius",
            "5mm",
            "--pin-length",
            "25mm",
            "--contact-friction-coefficient",
            "0.15",
        ],
        capsys,
    )
    assert code == 0
    data = json.loads(out)
    for key in (
        "sliding_friction_j",
        "sliding_friction_paper_j",
        "contact_friction_j",
        "impact_j",
        "total_j",
        "loss_factor",
        "hertz_half_width_m",
    ):
        assert isinstance(data[key], float)
    a, x = 20e-6, 20e-6 + 0.106e-3 / 2
    assert data["sliding_friction_j"] == pytest.approx(4 * 60.0 * x, rel=1e-9)  # 4 mu P X
    w1 = math.sqrt(8e7 / 2.0)
    assert data["impact_j"] == pytest.approx(2 * 0.18 * 2.0 * (a * w1) ** 2, rel=1e-9)
    assert data["total_j"] == pytest.approx(
        data["sliding_friction_j"] + data["contact_friction_j"] + data["impact_j"], rel=1e-12
    )


def test_dissipation_from_a_study_with_an_override(capsys: pytest.CaptureFixture[str]) -> None:
    study = str(Path(__file__).resolve().parents[1] / "examples" / "study.toml")
    code, out, _ = run(["dissipation", "--study", study, "--amplitude", "20um", "--json"], capsys)
    assert code == 0
    assert json.loads(out)["impact_j"] > 0.0
    code, out, _ = run(
        ["dissipation", "--study", study, "--amplitude", "20um", "--json", "--restitution", "1"],
        capsys,
    )
    assert json.loads(out)["impact_j"] == 0.0


def test_dissipation_table(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run([*DISSIPATION, "--amplitude", "5um,20um", "--restitution", "0.9"], capsys)
    assert code == 0
    assert "E_I (mJ)" in out
    assert len(out.strip().splitlines()) == 5


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--amplitude", "5um", "--pin-radius", "5mm"], "--pin-length is missing"),
        (["--amplitude", "5um", "--restitution", "2"], "restitution must satisfy"),
        (
            ["--amplitude", "5um", "--lateral-load", "3m", "--friction-coefficient", "0.1"],
            "is not a force",
        ),
    ],
)
def test_dissipation_bad_input(
    extra: list[str], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run([*DISSIPATION, *extra], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert words in err


def test_dissipation_needs_a_joint(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(["dissipation", "--amplitude", "5um"], capsys)
    assert code == 2
    assert "--mass is missing: give --mass or put it in the study file" in err


EXAMPLE_AS_OPTIONS = [
    "--stiffness", "8e7N/m", "--tension-stiffness", "5e7N/m",
    "--damping-ratio", "0.01", "--restitution", "0.8",
    "--friction-coefficient", "0.2", "--lateral-load", "300N",
    "--contact-friction-coefficient", "0.15",
    "--pin-radius", "5mm", "--pin-length", "25mm",
]  # fmt: skip


@pytest.mark.parametrize(
    "override",
    [
        ["--clearance", "0.196mm"],
        ["--mass", "4kg"],
        ["--stiffness", "1e8N/m"],
        ["--tension-stiffness", "7e7N/m"],
        ["--lateral-load", "100N"],
        ["--friction-region", "free-play"],
        ["--pin-radius", "6mm"],
        ["--youngs-modulus", "150GPa"],
        ["--contact-friction-coefficient", "0.3"],
        ["--damping-ratio", "0.05"],
        ["--gap-stiffness", "1e6N/m"],
        ["--gap-stiffness", "1e6N/m", "--gap-offset=-0.01mm"],  # the offset matters when k0 > 0
        ["--restitution", "0.5"],
        ["--friction-coefficient", "0.3"],
        ["--pin-length", "30mm"],
        ["--hole-radius", "5.1mm"],
        ["--poisson-ratio", "0.33"],
    ],
)
def test_every_option_beside_study_overrides_it(
    override: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    """study + one option == the same joint written out in options alone (no study)."""
    study = str(Path(__file__).resolve().parents[1] / "examples" / "study.toml")
    common = ["dissipation", "--amplitude", "20um", "--json"]
    code, out, err = run([*common, "--study", study, *override], capsys)
    assert code == 0, err
    by_study = json.loads(out)
    explicit = [*common, "--mass", "2kg", "--clearance", "0.106mm", *EXAMPLE_AS_OPTIONS]
    code, out, err = run([*explicit, *override], capsys)  # argparse: the last one wins
    assert code == 0, err
    assert by_study == pytest.approx(json.loads(out), rel=1e-12)
    if override[0] == "--mass":  # at a given amplitude every energy is free of m: see the table
        code, out, _ = run([*common[:-1], "--study", study, *override], capsys)
        assert "m = 4 kg" in out
        return
    code, out, _ = run([*common, "--study", study], capsys)
    assert json.loads(out) != pytest.approx(by_study, rel=1e-9)  # the override mattered


def test_an_overridden_clearance_reaches_the_closed_form(
    capsys: pytest.CaptureFixture[str],
) -> None:
    study = str(Path(__file__).resolve().parents[1] / "examples" / "study.toml")
    args = ["dissipation", "--study", study, "--amplitude", "20um", "--json"]
    code, out, _ = run([*args, "--clearance", "0.196mm"], capsys)
    assert code == 0
    # eq 10 over the whole path of the free orbit, mu_s P = 60 N in the study: the path is
    # 2 (c + A + A_t), the tension penetration A_t = A sqrt(k_c / k_t) by equal energy
    path = 2.0 * (0.196e-3 + 20e-6 * (1.0 + math.sqrt(8e7 / 5e7)))
    assert json.loads(out)["sliding_friction_j"] == pytest.approx(60.0 * path, rel=1e-9)


# ---- issue 16: no traceback for any input ----------------------------------------------------


def _inputs(tmp_path: Path) -> dict[str, Path]:
    """A folder, a missing path, an empty file, a binary file and files of the wrong kind."""
    folder = tmp_path / "a-folder"
    folder.mkdir()
    (tmp_path / "empty.toml").write_bytes(b"")
    (tmp_path / "binary.toml").write_bytes(bytes(range(256)) * 4)
    (tmp_path / "record.toml").write_text("time [s],force [N],displacement [m]\n0,0,0\n")
    (tmp_path / "study.csv").write_text('[joint]\nmass = "2kg"\n')
    return {
        "folder": folder,
        "missing": tmp_path / "no-such-file",
        "empty": tmp_path / "empty.toml",
        "binary": tmp_path / "binary.toml",
        "wrong kind": tmp_path / "record.toml",
        "wrong kind for records": tmp_path / "study.csv",
    }


def _command(name: str, path: Path, out: Path) -> list[str]:
    return {
        "simulate": ["simulate", str(path)],
        "dissipation": ["dissipation", "--study", str(path), "--amplitude", "5um"],
        "rig": ["rig", str(path), "--out", str(out), "--quiet"],
        "reproduce": ["reproduce", "--campaign", str(path), "--out", str(out)],
        "identify": ["identify", str(path), "--out", str(out / "r.csv"), "--quiet"],
        "report": ["report", "--records", str(path), "--out", str(out)],
    }[name]


@pytest.mark.parametrize(
    "command", ["simulate", "dissipation", "rig", "reproduce", "identify", "report"]
)
@pytest.mark.parametrize("case", ["folder", "missing", "empty", "binary", "wrong kind"])
def test_every_command_says_what_and_where_in_one_line_for_bad_input(
    command: str, case: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    inputs = _inputs(tmp_path)
    if command == "identify" and case == "wrong kind":
        case = "wrong kind for records"
    path = inputs[case]
    # report wants a folder: the folder case is an empty one, the others are not folders
    code, out, err = run(_command(command, path, tmp_path / "out"), capsys)
    assert code == 2, (out, err)
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith("- ")]
    assert len(lines) == 1, err
    assert lines[0].startswith(f"clearjoint {command}: error: ")
    assert str(path) in lines[0]


@pytest.mark.parametrize("command", ["rig", "simulate", "identify"])
def test_an_output_path_under_a_file_is_one_line(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    study = str(Path(__file__).resolve().parents[1] / "examples" / "study.toml")
    args = {
        "rig": ["rig", "--out", str(blocker / "records"), "--quiet"],
        "simulate": ["simulate", study, "--out", str(blocker / "x.nc")],
        "identify": ["identify", study, "--out", str(blocker / "r.csv"), "--quiet"],
    }[command]
    code, _, err = run(args, capsys)
    assert code == 2
    assert "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert str(blocker) in err


def test_a_reader_that_stops_early_gets_no_traceback_and_no_error() -> None:
    """`clearjoint dissipation ... | head -2`: a broken pipe is the reader's choice."""
    amplitudes = ",".join(f"{i}um" for i in range(1, 3000))  # far more than a pipe buffers
    command = [sys.executable, "-m", "clearjoint", "dissipation", "--mass", "2kg", "--stiffness",
               "8e7N/m", "--clearance", "0.106mm", "--amplitude", amplitudes]  # fmt: skip
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE) as proc:
        assert proc.stdout is not None
        assert proc.stderr is not None
        proc.stdout.readline()
        proc.stdout.close()  # as head does after its lines
        err = proc.stderr.read().decode()
        assert proc.wait(timeout=120) == 0
    assert err == ""


@pytest.mark.filterwarnings("default::clearjoint.contact.HertzValidityWarning")
def test_a_warning_is_one_line_naming_the_command(capsys: pytest.CaptureFixture[str]) -> None:
    # a 1 kN-class contact force on a short pin: Hertz's half-angle is far past 0.2 rad
    code = main(["dissipation", "--mass", "2kg", "--stiffness", "8e7N/m", "--clearance", "0.106mm",
                 "--amplitude", "300um", "--pin-radius", "5mm", "--pin-length", "5mm",
                 "--contact-friction-coefficient", "0.15"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 0
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("clearjoint dissipation: warning: Hertz contact half-angle")


# ---- review: a loss given without what it needs is an error, not a silent zero ----------------


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--friction-coefficient", "0.2"], "--friction-coefficient needs --lateral-load too"),
        (["--lateral-load", "300N"], "--lateral-load needs --friction-coefficient too"),
        (
            ["--friction-coefficient=-0.2", "--lateral-load", "300N"],
            "friction coefficient must be >= 0",
        ),
        (["--friction-coefficient", "0.2", "--lateral-load=-300N"], "lateral_load must be >= 0"),
        (["--friction-region", "free-play"], "--friction-region needs sliding friction"),
        (["--contact-friction-coefficient", "0.2"], "acts on the pin: give --pin-radius"),
        (["--damping-ratio", "0,02"], "write the decimal point as '.'"),
    ],
)
def test_a_loss_without_what_it_needs_is_one_line(
    extra: list[str], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run([*DISSIPATION, "--amplitude", "5um", *extra], capsys)
    assert (code, out) == (2, "")
    assert words in err
    assert len(err.strip().splitlines()) == 1


def test_friction_can_still_be_switched_off_over_a_study(
    capsys: pytest.CaptureFixture[str],
) -> None:
    study = str(Path(__file__).resolve().parents[1] / "examples" / "study.toml")
    code, out, err = run(
        ["dissipation", "--study", study, "--amplitude", "5um", "--json", "--lateral-load", "0N"],
        capsys,
    )
    assert code == 0, err
    assert json.loads(out)["sliding_friction_j"] == 0.0


def test_a_damping_ratio_in_percent_is_a_hundredth(capsys: pytest.CaptureFixture[str]) -> None:
    # "1%" is 0.01 (pint gives it as a unitless 1, which was taken as zeta = 1)
    args = [*DISSIPATION, "--amplitude", "5um", "--json", "--damping-ratio"]
    _, percent, _ = run([*args, "1%"], capsys)
    _, plain, _ = run([*args, "0.01"], capsys)
    assert json.loads(percent)["viscous_j"] == pytest.approx(json.loads(plain)["viscous_j"])


def test_a_negative_value_after_a_space_says_how_to_write_it(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, _, err = run([*BASE, "--amplitude", "5um", "--gap-offset", "-0.01mm"], capsys)
    assert code == 2
    assert "for a negative value write --gap-offset=-0.01mm" in err
    code, _, err = run([*BASE, "--amplitude", "5um", "--gap-offset=-0.01mm", "--json"], capsys)
    assert code == 0, err


@pytest.mark.parametrize("command", ["rig", "reproduce", "report", "identify --figures"])
def test_an_output_folder_that_is_a_file_is_refused_before_the_work(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    records = tmp_path / "records"
    records.mkdir()
    study = str(Path(__file__).resolve().parents[1] / "examples" / "study.toml")
    target = str(blocker / "sub")  # a folder to make under a file
    args = {
        "rig": ["rig", "--out", target, "--quiet"],
        "reproduce": ["reproduce", "--out", target],
        "report": ["report", "--records", str(records), "--out", target],
        "identify --figures": [
            "identify", study, "--out", str(tmp_path / "r.csv"), "--figures", target, "--quiet",
        ],
    }[command]  # fmt: skip
    code, out, err = run(args, capsys)
    assert (code, out) == (2, "")
    assert err.strip().endswith(f"{blocker} is a file; give a folder"), err
    assert not any(line.startswith("- ") for line in err.splitlines())  # before any stage
    assert not (tmp_path / "r.csv").exists()


def test_the_progress_bar_leaves_a_redirected_stdout_clean(tmp_path: Path) -> None:
    """`clearjoint identify FILE > out.txt`: the output, with no line drawn by a progress bar."""
    record = Path(__file__).parent / "data" / "brfd" / "2Hz36lbtension0.5amplitude.json"
    command = [sys.executable, "-m", "clearjoint", "identify", str(record)]
    result = subprocess.run(
        [*command, "--out", str(tmp_path / "r.csv")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[0].startswith("identified 1 of 1"), result.stdout
