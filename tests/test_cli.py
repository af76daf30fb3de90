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
        [*BASE, "--amplitude", "5um", "--json", "--tension-stiffness", "4e7"], capsys
    )
    assert code == 0
    assert isinstance(json.loads(out)["period_s"], float)


def test_bare_numbers_are_si(capsys: pytest.CaptureFixture[str]) -> None:
    _, with_units, _ = run([*BASE, "--amplitude", "5um", "--json"], capsys)
    _, bare, _ = run(
        [
            "stiffness",
            "--mass",
            "2",
            "--stiffness",
            "8e7",
            "--clearance",
            "0.000106",
            "--amplitude",
            "0.000005",
            "--json",
        ],
        capsys,
    )
    assert json.loads(bare)["period_s"] == pytest.approx(
        json.loads(with_units)["period_s"], rel=1e-12
    )


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
        (["--amplitude", "nan"], "amplitude must be finite"),
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
        (["--amplitude", "5um", "--pin-radius", "5mm"], "give both --pin-radius and --pin-length"),
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
    assert "--mass is required" in err
