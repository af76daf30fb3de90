"""clearjoint frf: the curve as JSON, netCDF and a figure; one-line errors with exit code 2."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from clearjoint.cli import main

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "frf.toml"


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    try:
        code = main(args)
    except SystemExit as exc:  # argparse exits on usage errors
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def test_frequency_curve_as_json_netcdf_and_png(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import xarray as xr

    out, png = tmp_path / "frf.nc", tmp_path / "frf.png"
    args = ["frf", str(EXAMPLE), "--from", "10Hz", "--to", "360Hz", "--out", str(out)]
    code, text, err = run([*args, "--plot", str(png), "--json"], capsys)
    assert code == 0, err
    data = json.loads(text)
    assert set(data) >= {"frequency_hz", "amplitude_m", "x_max_m", "x_min_m", "stable", "events"}
    n = len(data["frequency_hz"])
    assert n >= 300
    assert all(len(data[k]) == n for k in ("amplitude_m", "x_max_m", "x_min_m", "stable"))
    assert data["frequency_hz"][0] == pytest.approx(10.0)
    assert data["frequency_hz"][-1] == pytest.approx(360.0)
    kinds = [e["kind"] for e in data["events"]]
    assert kinds.count("fold") == 2
    assert kinds.count("grazing") == 2
    for event in data["events"]:
        assert set(event) == {"kind", "frequency_hz", "force_n", "amplitude_m"}
    # the study scales pyHarm's case to w0 = 2 pi 200 Hz and 1 mm: its peak 0.3973 near 1.534 w0
    peak = max(range(n), key=lambda i: data["amplitude_m"][i])
    assert data["amplitude_m"][peak] == pytest.approx(0.3973e-3, rel=2e-3)
    assert data["frequency_hz"][peak] == pytest.approx(1.534 * 200.0, rel=2e-3)
    assert png.stat().st_size > 1000
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.sizes["point"] == n
        assert ds["frequency"].attrs["units"] == "Hz"
    # and it will not overwrite what it wrote without --force
    code, _, err = run(args, capsys)
    assert code == 2
    assert "--force" in err


def test_force_curve_at_a_fixed_frequency(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["frf", str(EXAMPLE), "--parameter", "force", "--from", "10N", "--to", "0.2kN"]
    args += ["--frequency", "300Hz", "--out", str(tmp_path / "f.nc"), "--json"]
    code, text, err = run(args, capsys)
    assert code == 0, err
    data = json.loads(text)
    assert data["force_n"][0] == pytest.approx(10.0)
    assert data["force_n"][-1] == pytest.approx(200.0)
    assert all(f == pytest.approx(300.0) for f in data["frequency_hz"])
    # inside the gap the orbit is linear: X = F0 / |k0 - m w^2 + i c w|
    w = 2 * math.pi * 300.0
    k0, c = 1.5791e6, 2 * 0.014434 * math.sqrt(4.7374e6)
    gain = 1.0 / math.hypot(k0 - w * w, c * w)
    assert data["amplitude_m"][0] == pytest.approx(10.0 * gain, rel=1e-9)


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--from", "20Hz", "--to", "20Hz"], "zero width"),
        (["--from=-5Hz", "--to", "20Hz"], "must be finite and > 0"),
        (["--from", "NaN Hz", "--to", "20Hz"], "must be finite and > 0"),
        (["--from", "20N", "--to", "90Hz"], "--from"),
        (["--parameter", "force", "--from", "10N"], "--to"),
        (["--from", "20Hz", "--to", "90Hz", "--frequency", "5Hz"], "--parameter force"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(
    extra: list[str], match: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run(["frf", str(EXAMPLE), *extra, "--out", str(tmp_path / "x.nc")], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert match in err
    assert "Traceback" not in err


def test_a_study_without_a_force_is_one_line_and_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    study = tmp_path / "s.toml"
    text = EXAMPLE.read_text(encoding="utf-8").replace('force_amplitude = "47.37N"', "")
    study.write_text(text, encoding="utf-8")
    args = ["frf", str(study), "--from", "10Hz", "--to", "20Hz", "--out", str(tmp_path / "x.nc")]
    code, _, err = run(args, capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert "force_amplitude" in err


def test_free_play_orbits_are_flagged_and_said_to_have_no_set_position(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # k0 = 0, forced past the contact resonance: the curve ends on the continuum of orbits
    # inside the gap (the free mass: X = F0 / (w sqrt(m^2 w^2 + c^2)), c = 2 N s/m here)
    study = tmp_path / "free.toml"
    study.write_text(
        '[joint]\nmass = "1kg"\nclearance = "0.2m"\ncompression_stiffness = "100N/m"\n'
        '[excitation]\nforce_amplitude = "1N"\nfrequency = "1Hz"\n'
        "[losses]\ndamping_ratio = 0.1\nrestitution = 0.8\n"
    )
    args = ["frf", str(study), "--from", "0.32Hz", "--to", "1.9Hz", "--out", str(tmp_path / "a.nc")]
    code, text, err = run(args, capsys)
    assert code == 0, err
    assert err == ""
    assert "free play from 0.4558" in text  # 2.8632 rad/s: 2 X = clearance
    assert "its position is not" in text
    code, text, err = run([*args, "--json", "--force"], capsys)
    assert code == 0, err
    data = json.loads(text)
    free = data["free_play"]
    assert len(free) == len(data["frequency_hz"])
    assert sum(free) > 20
    assert free[-1]
    assert not any(f for f, s in zip(free, data["stable"], strict=True) if s)
    assert "free_play" in [e["kind"] for e in data["events"]]
    w = 2.0 * math.pi * data["frequency_hz"][-1]
    assert data["amplitude_m"][-1] == pytest.approx(1.0 / (w * math.sqrt(w * w + 4.0)), rel=1e-9)


@pytest.mark.parametrize("frequency", ["0Hz", "--frequency=-3Hz", "1e400Hz"])
def test_a_bad_fixed_frequency_names_the_option(
    frequency: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the fixed frequency of --parameter force: the message names --frequency, not the
    # Python argument omega_start in rad/s that the user never wrote
    option = [frequency] if frequency.startswith("--") else ["--frequency", frequency]
    args = ["frf", str(EXAMPLE), "--parameter", "force", "--from", "10N", "--to", "20N", *option]
    code, _, err = run([*args, "--out", str(tmp_path / "x.nc")], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert "--frequency must be finite and > 0" in err
    assert "omega_start" not in err
    assert not (tmp_path / "x.nc").exists()


@pytest.mark.parametrize("force", ['"0N"', '"nan N"'])
def test_a_study_with_a_zero_or_nan_force_names_the_file_and_the_key(
    force: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    study = tmp_path / "zero.toml"
    text = EXAMPLE.read_text(encoding="utf-8").replace('"47.37N"', force)
    study.write_text(text, encoding="utf-8")
    args = ["frf", str(study), "--from", "10Hz", "--to", "20Hz", "--out", str(tmp_path / "x.nc")]
    code, _, err = run(args, capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert "zero.toml" in err
    assert "[excitation] force_amplitude" in err
    assert not (tmp_path / "x.nc").exists()


@pytest.mark.parametrize("points", ["1", "0", "-3"])
def test_too_few_max_points_names_the_option(
    points: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["frf", str(EXAMPLE), "--from", "10Hz", "--to", "20Hz", f"--max-points={points}"]
    code, _, err = run([*args, "--out", str(tmp_path / "x.nc")], capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert "--max-points must be >= 2" in err


def test_json_says_why_the_curve_stopped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a curve cut short (here by --max-points) is partial: the JSON itself must say so, not
    # only the warning line on stderr that a script reading stdout never sees
    args = ["frf", str(EXAMPLE), "--from", "10Hz", "--to", "360Hz", "--max-points", "5"]
    code, text, err = run([*args, "--out", str(tmp_path / "x.nc"), "--json"], capsys)
    assert code == 0, err
    data = json.loads(text)
    assert len(data["frequency_hz"]) == 5
    assert data["frequency_hz"][-1] < 360.0
    assert data["stop_reason"] == "max_points"
    assert "stopped early" in err
    code, text, err = run([*args[:-2], "--out", str(tmp_path / "y.nc"), "--json"], capsys)
    assert code == 0, err
    assert json.loads(text)["stop_reason"] == "reached"


def test_a_bad_fixed_frequency_of_a_structure_study_names_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mast = EXAMPLE.parent / "mast.toml"
    args = ["frf", str(mast), "--method", "harmonic", "--parameter", "force"]
    args += ["--from", "10N", "--to", "20N", "--frequency", "0Hz", "--out", str(tmp_path / "m.nc")]
    code, _, err = run(args, capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert "--frequency must be finite and > 0" in err


def test_the_issues_force_example_starts_on_free_play_orbits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the issue's own example: at 100 N and 400 Hz the study's joint (k0 = 0) stays inside
    # the gap (a continuum of orbits); the curve follows the centred one, then contact
    study = EXAMPLE.parent / "study.toml"
    args = ["frf", str(study), "--parameter", "force", "--from", "100N", "--to", "2kN"]
    args += ["--frequency", "400Hz", "--out", str(tmp_path / "x.nc")]
    code, text, err = run(args, capsys)
    assert code == 0, err
    assert err == ""
    assert "free play from 100 to 680" in text  # the widest in-gap orbit near 680 N
    assert "N at 400 Hz" in text
    assert "its position is not" in text
    code, text, err = run([*args, "--json", "--force"], capsys)
    assert code == 0, err
    data = json.loads(text)
    assert data["stop_reason"] == "reached"
    assert data["force_n"][0] == pytest.approx(100.0)
    assert data["force_n"][-1] == pytest.approx(2000.0)
    free = data["free_play"]
    assert free[0]
    assert not free[-1]
    assert sum(free) > 20
    assert not any(f for f, s in zip(free, data["stable"], strict=True) if s)
    assert "free_play" in [e["kind"] for e in data["events"]]
    # a force curve does not need the study's force: the same curve without it
    bare = tmp_path / "bare.toml"
    text_toml = study.read_text(encoding="utf-8").replace('force_amplitude = "1000N"', "")
    bare.write_text(text_toml, encoding="utf-8")
    args_bare = [str(bare) if a == str(study) else a for a in args]
    args_bare[args_bare.index(str(tmp_path / "x.nc"))] = str(tmp_path / "y.nc")
    code, text, err = run([*args_bare, "--json"], capsys)
    assert code == 0, err
    assert json.loads(text)["amplitude_m"] == data["amplitude_m"]
    # a frequency curve still does
    code, _, err = run(["frf", str(bare), "--from", "300Hz", "--to", "400Hz", "--out",
                        str(tmp_path / "z.nc")], capsys)  # fmt: skip
    assert code == 2
    assert "force_amplitude" in err
