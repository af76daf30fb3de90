"""simulate.study and `clearjoint simulate`: study files, defaults, netCDF and JSON."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from clearjoint import Losses
from clearjoint.cli import main
from clearjoint.simulate import steady_state
from clearjoint.simulate.study import StudyError, load_study

ROOT = Path(__file__).resolve().parents[1]

MINIMAL = """
[joint]
mass = "2kg"
clearance = "0.106mm"
compression_stiffness = "8e7N/m"

[excitation]
force_amplitude = "1kN"
frequency = "400Hz"

[losses]
damping_ratio = 0.02
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "study.toml"
    path.write_text(text)
    return path


def test_defaults_are_merged_and_units_converted(tmp_path: Path) -> None:
    study = load_study(write(tmp_path, MINIMAL))
    assert study.joint.clearance == pytest.approx(0.106e-3)
    assert study.joint.tension_stiffness == study.joint.compression_stiffness
    assert study.joint.gap_stiffness == 0.0
    assert study.force_amplitude == pytest.approx(1000.0)
    assert study.omega == pytest.approx(2 * math.pi * 400.0)
    assert study.restitution == 1.0
    assert study.friction is None
    assert study.pin is None
    assert study.mode == "steady"


def test_shipped_example_study_loads_and_its_pin_takes_the_clearance() -> None:
    study = load_study(ROOT / "examples" / "study.toml")
    assert study.pin is not None
    assert study.pin.hole_radius == pytest.approx(5e-3 + 0.053e-3)
    assert study.friction is not None
    assert study.friction.force == pytest.approx(60.0)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        (MINIMAL.replace("mass", "mas"), "unknown key(s) ['mas'] in [joint]"),
        (MINIMAL + "\n[solver]\nx = 1\n", "unknown section(s) ['solver']"),
        (MINIMAL.replace('mass = "2kg"\n', ""), "[joint] mass is required"),
        (MINIMAL.replace('"0.106mm"', '"-0.1mm"'), "clearance must be >= 0"),
        (MINIMAL.replace('"400Hz"', '"400N"'), "is not a frequency"),
        (MINIMAL.replace('"400Hz"', '"0Hz"'), "frequency must be > 0"),
        (MINIMAL.replace('"1kN"', '"nan N"'), "force_amplitude must be a finite force"),
        (MINIMAL.replace('"1kN"', '"-5N"'), "force_amplitude must be a finite force >= 0"),
        (MINIMAL + 'restitution = "high"\n', "cannot read 'high'"),
        ("this is not = = toml", "not valid TOML"),
    ],
)
def test_bad_studies_name_file_and_key(tmp_path: Path, text: str, words: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(StudyError) as info:
        load_study(path)
    assert words in str(info.value)
    assert str(path) in str(info.value)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(StudyError, match="no such study file"):
        load_study(tmp_path / "nope.toml")


def test_cli_json_and_netcdf_match_the_library(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path, MINIMAL)
    out = tmp_path / "result.nc"
    assert main(["simulate", str(path), "--json", "--out", str(out)]) == 0
    result = json.loads(capsys.readouterr().out)
    study = load_study(path)
    direct = steady_state(study.joint, 1000.0, study.omega, losses=Losses(damping_ratio=0.02))
    assert result["amplitude_m"] == pytest.approx(direct.amplitude, rel=1e-12)
    assert result["energy_j"]["input"] == pytest.approx(direct.energy.input, rel=1e-12)
    assert result["balance_error"] < 1e-9
    with xr.open_dataset(out, engine="h5netcdf") as data:
        n = direct.time.size  # the exact orbit, repeated over [output] periods = 8
        np.testing.assert_allclose(data["displacement"].values[:n], direct.displacement)
        np.testing.assert_allclose(data["displacement"].values[n : 2 * n], direct.displacement)
        assert data["time"].size == n * math.ceil(8 / direct.period_multiple)
        assert data["displacement"].attrs["units"] == "m"
        assert data.attrs["clearance_m"] == pytest.approx(0.106e-3)
        assert set(data["stage_name"].values) <= {"free-play", "compression", "tension"}
    # never overwrite without being asked, and say so in one line
    before = out.stat().st_mtime_ns
    assert main(["simulate", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "will not overwrite" in err
    assert len(err.strip().splitlines()) == 1
    assert out.stat().st_mtime_ns == before


def test_cli_table_and_transient(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = MINIMAL.replace(
        'frequency = "400Hz"',
        'frequency = "400Hz"\nmode = "transient"\nduration = "5ms"\ninitial_displacement = "10um"',
    )
    assert main(["simulate", str(write(tmp_path, text))]) == 0
    out = capsys.readouterr().out
    assert "transient" in out
    assert "balance error" in out


def test_cli_bad_study_exit_code_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", str(tmp_path / "missing.toml")]) == 2
    assert "no such study file" in capsys.readouterr().err


# ---- issue 16: units by dimension, bare numbers only where the key names the unit ----------


@pytest.mark.parametrize(
    ("frequency", "omega"),
    [
        ('frequency = "2513rad/s"', 2513.0),  # was run at 2513 Hz
        ('frequency = "400rpm"', 2.0 * math.pi * 400.0 / 60.0),  # was run at 41.89 Hz
        ('frequency = "0.4kHz"', 2.0 * math.pi * 400.0),
        ("frequency_hz = 400", 2.0 * math.pi * 400.0),
    ],
)
def test_study_frequencies_convert_by_dimension(
    tmp_path: Path, frequency: str, omega: float
) -> None:
    study = load_study(write(tmp_path, MINIMAL.replace('frequency = "400Hz"', frequency)))
    assert study.omega == pytest.approx(omega, rel=1e-12)


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ('mass = "2kg"', "mass = 2", '[joint] mass = 2: give a unit, e.g. "2kg"'),
        ('mass = "2kg"', "mass = 2", "or name the SI unit in the key (mass_kg = 2)"),
        ('"400Hz"', '"0.4m"', "is not a frequency"),
        ('frequency = "400Hz"', 'frequency_hz = "400Hz"', "the key names its unit"),
        ('frequency = "400Hz"', 'frequency = "400Hz"\nfrequency_hz = 400', "given twice"),
    ],
)
def test_bare_numbers_only_where_the_key_names_the_unit(
    tmp_path: Path, old: str, new: str, words: str
) -> None:
    path = write(tmp_path, MINIMAL.replace(old, new))
    with pytest.raises(StudyError) as info:
        load_study(path)
    assert words in str(info.value)
    assert len(str(info.value).splitlines()) == 1


def test_unit_named_keys_and_dimensionless_bare_numbers(tmp_path: Path) -> None:
    text = MINIMAL.replace('mass = "2kg"', "mass_kg = 2").replace(
        'clearance = "0.106mm"', "clearance_m = 1.06e-4"
    )
    study = load_study(write(tmp_path, text))
    assert (study.joint.mass, study.joint.clearance) == (2.0, 1.06e-4)
    assert study.damping_ratio == 0.02  # a bare number: the key is dimensionless


def test_simulate_output_is_a_record_that_identify_reads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One netCDF layout: identify recovers the study's joint from simulate's file."""
    from clearjoint.records import read_record

    study_path = ROOT / "examples" / "study.toml"
    out = tmp_path / "x.nc"
    assert main(["simulate", str(study_path), "--out", str(out), "--json"]) == 0
    ledger = json.loads(capsys.readouterr().out)["energy_j"]
    record = read_record(out)
    assert record.control == "force"
    assert record.mass == 2.0
    assert record.frequency_hz == pytest.approx(400.0)
    results = tmp_path / "r.csv"
    assert main(["identify", str(out), "--out", str(results), "--quiet"]) == 0
    capsys.readouterr()
    with results.open() as handle:
        row = next(csv.DictReader(handle))
    # identify sees only the record; the study's truth: c, k_c, k_t, mu_s P, input per cycle
    assert float(row["clearance_m"]) == pytest.approx(0.106e-3, rel=1e-6)
    assert float(row["compression_stiffness_n_per_m"]) == pytest.approx(8e7, rel=1e-6)
    assert float(row["tension_stiffness_n_per_m"]) == pytest.approx(5e7, rel=1e-6)
    assert float(row["friction_force_n"]) == pytest.approx(60.0, rel=1e-6)
    assert float(row["energy_per_cycle_j"]) == pytest.approx(ledger["input"], rel=1e-3)


def test_simulate_refuses_an_output_suffix_that_is_not_netcdf(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "result.csv"
    assert main(["simulate", str(ROOT / "examples" / "study.toml"), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "simulate writes netCDF; name the file .nc" in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


# ---- review: a loss given without what it needs is an error, not a silent zero ----------------


@pytest.mark.parametrize(
    ("losses", "words"),
    [
        ("friction_coefficient = 0.2", "friction_coefficient is given without lateral_load"),
        ('lateral_load = "300N"', "lateral_load is given without friction_coefficient"),
        ('friction_coefficient = -0.2\nlateral_load = "300N"', "friction coefficient must be >= 0"),
        ("contact_friction_coefficient = 0.15", "add a [pin] table"),
        ('damping_ratio = "1,5%"', "write the decimal point as '.'"),
    ],
)
def test_a_loss_without_what_it_needs_is_refused(tmp_path: Path, losses: str, words: str) -> None:
    path = write(tmp_path, MINIMAL.replace("damping_ratio = 0.02", losses))
    with pytest.raises(StudyError) as info:
        load_study(path)
    assert words in str(info.value)
    assert len(str(info.value).splitlines()) == 1


def test_friction_switched_off_explicitly_and_percent(tmp_path: Path) -> None:
    text = 'friction_coefficient = 0.2\nlateral_load = "0N"\ndamping_ratio = "2%"'
    study = load_study(write(tmp_path, MINIMAL.replace("damping_ratio = 0.02", text)))
    assert study.friction is None
    assert study.damping_ratio == pytest.approx(0.02)


def test_a_key_the_caller_does_not_need_may_be_left_out(tmp_path: Path) -> None:
    # a force curve (frf --parameter force) takes its forces from the command line
    path = tmp_path / "s.toml"
    path.write_text(MINIMAL.replace('force_amplitude = "1kN"', ""), encoding="utf-8")
    with pytest.raises(StudyError, match=r"\[excitation\] force_amplitude is required"):
        load_study(path)
    study = load_study(path, optional=("excitation.force_amplitude",))
    assert math.isnan(study.force_amplitude)
    assert study.omega == pytest.approx(2.0 * math.pi * 400.0)
    # given, it is read as usual
    full = load_study(write(tmp_path, MINIMAL), optional=("excitation.force_amplitude",))
    assert full.force_amplitude == 1000.0
