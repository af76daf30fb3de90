"""clearjoint frf --method harmonic and clearjoint modes: outputs and one-line errors."""

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


def test_frf_by_harmonic_balance(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import xarray as xr

    out = tmp_path / "frf.nc"
    args = ["frf", str(EXAMPLE), "--from", "200Hz", "--to", "330Hz", "--out", str(out)]
    code, text, err = run([*args, "--method", "harmonic", "--harmonics", "9", "--json"], capsys)
    assert code == 0, err
    data = json.loads(text)
    # the example is pyHarm's case scaled to a 200 Hz free-play resonance: exact folds at
    # 1.0797 and 1.5350 x 200 Hz (clearjoint.periodic)
    folds = sorted(e["frequency_hz"] for e in data["events"] if e["kind"] == "fold")
    assert len(folds) == 2
    assert folds[0] == pytest.approx(215.94, rel=2e-3)
    assert folds[1] == pytest.approx(307.0, rel=2e-3)
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["method"] == "harmonic"
        assert ds["coefficients"].shape[1] == 19


def test_modes_json_netcdf_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import xarray as xr

    out, png = tmp_path / "modes.nc", tmp_path / "modes.png"
    args = ["modes", str(EXAMPLE), "--mode", "1", "--amplitude", "0.3mm..3mm", "--points", "5"]
    code, text, err = run([*args, "--out", str(out), "--plot", str(png), "--json"], capsys)
    assert code == 0, err
    data = json.loads(text)
    assert set(data) == {"amplitude_m", "frequency_hz", "damping_ratio", "energy_per_cycle_j"}
    assert data["amplitude_m"][0] == pytest.approx(0.3e-3)
    assert data["amplitude_m"][-1] == pytest.approx(3e-3)
    # free-play 200 Hz, contact 400 Hz: the mode lies between and rises with amplitude
    assert all(200.0 < f < 400.0 for f in data["frequency_hz"])
    assert data["frequency_hz"] == sorted(data["frequency_hz"])
    # c_v fixed: zeta = c_v / (2 m w) falls as w rises
    c_v = 2 * 0.014434 * math.sqrt(4.7374e6)
    for f, z in zip(data["frequency_hz"], data["damping_ratio"], strict=True):
        assert z == pytest.approx(c_v / (2 * 2 * math.pi * f), rel=1e-6)
    assert png.stat().st_size > 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["frequency"].attrs["units"] == "Hz"
    code, _, err = run([*args, "--out", str(out)], capsys)
    assert code == 2
    assert "will not overwrite" in err


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["modes", "--amplitude", "0um..1mm"], "--amplitude must start above zero"),
        (["modes", "--amplitude=-1um..1mm"], "--amplitude must start above zero"),
        (["modes", "--amplitude", "1um..1mm", "--mode", "2"], "a Joint has only mode 1"),
        (["modes", "--amplitude", "1um..1mm", "--harmonics", "0"], "harmonics must be"),
        (["modes", "--amplitude", "1kg..1mm"], "--amplitude"),
        (["frf", "--from", "10Hz", "--to", "20Hz", "--harmonics", "5"], "--method harmonic"),
        (
            ["frf", "--from", "10Hz", "--to", "20Hz", "--method", "harmonic", "--harmonics", "0"],
            "harmonics must be an integer >= 1",
        ),
    ],
)
def test_bad_input_is_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    command, *rest = extra
    code, _, err = run([command, str(EXAMPLE), *rest, "--out", str(tmp_path / "x.nc")], capsys)
    assert code == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err
