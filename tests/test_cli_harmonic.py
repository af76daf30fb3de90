"""clearjoint frf --method harmonic and clearjoint modes: outputs and one-line errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from clearjoint.cli import main
from helpers import with_losses

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "frf.toml"


#: `clearjoint modes --json`: the issue's four keys, and EPMC's own ratio beside them.
MODES_JSON_KEYS = {
    "amplitude_m",
    "frequency_hz",
    "damping_ratio",
    "energy_per_cycle_j",
    "epmc_damping_ratio",
}


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
    assert set(data) == MODES_JSON_KEYS
    assert data["amplitude_m"][0] == pytest.approx(0.3e-3)
    assert data["amplitude_m"][-1] == pytest.approx(3e-3)
    # free-play 200 Hz, contact 400 Hz: the mode lies between and rises with amplitude
    assert all(200.0 < f < 400.0 for f in data["frequency_hz"])
    assert data["frequency_hz"] == sorted(data["frequency_hz"])
    # c_v fixed: EPMC's zeta = c_v / (2 m w) falls as w rises (one mass: xi = c_v / m);
    # the energy ratio E_diss / (4 pi E_max) lies above it, the motion not a sinusoid
    c_v = 2 * 0.014434 * math.sqrt(4.7374e6)
    for f, z, z_e in zip(
        data["frequency_hz"], data["epmc_damping_ratio"], data["damping_ratio"], strict=True
    ):
        assert z == pytest.approx(c_v / (2 * 2 * math.pi * f), rel=1e-6)
        assert z_e > z
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
        (["modes", "--amplitude", "1mm..10um"], "runs downwards; write it from the smaller"),
        (["modes", "--amplitude", "1um..1mm", "--samples", "29"], "at least 2 (2H + 1) = 30"),
        (
            ["frf", "--from", "10Hz", "--to", "20Hz", "--method", "harmonic", "--samples", "8"],
            "--samples 8 is too few for --harmonics 7",
        ),
        (["frf", "--from", "10Hz", "--to", "20Hz", "--samples", "64"], "--method harmonic"),
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


CHAIN_STUDY = """
[structure]
kind = "chain"
masses = ["1kg", "1kg", "1kg"]
stiffnesses = [{stiffness}, {stiffness}, {stiffness}]
dampers = ["150N*s/m", "150N*s/m", "150N*s/m"]
joints = [true, true, true]

[joint]
clearance = "0.1mm"
compression_stiffness = "1e7N/m"
gap_stiffness = "1e5N/m"
{restitution}
[excitation]
frequency = "60Hz"
force_dof = "n3x"
force_amplitude = "40N"
"""


def _chain_study(tmp_path: Path, restitution: str = "", stiffness: str = '"1e6N/m"') -> Path:
    path = tmp_path / "chain.toml"
    path.write_text(CHAIN_STUDY.format(restitution=restitution, stiffness=stiffness))
    return path


def test_frf_of_a_structure_study(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The CLI reads the chain study (units: mm, N*s/m) into the same structure and force as
    the Python API, and writes per-DOF extremes."""
    import numpy as np
    import xarray as xr

    from clearjoint import ClearanceJoint
    from clearjoint.harmonic import frequency_response
    from clearjoint.structure import chain

    study, out = _chain_study(tmp_path), tmp_path / "frf.nc"
    args = ["frf", str(study), "--from", "50Hz", "--to", "52Hz", "--out", str(out)]
    code, text, err = run([*args, "--method", "harmonic", "--harmonics", "5", "--json"], capsys)
    assert code == 0, err
    data = json.loads(text)
    assert data["dofs"] == ["n1x", "n2x", "n3x"]
    assert np.shape(data["x_max_m"])[1] == 3
    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    s = chain([1.0] * 3, [1e6] * 3, [j] * 3, dampers=[150.0] * 3)
    force = [0.0, 0.0, 40.0]
    direct = frequency_response(s, force, 2 * math.pi * 50, 2 * math.pi * 52, harmonics=5)
    np.testing.assert_allclose(data["x_max_m"], direct.x_max, rtol=1e-9, atol=1e-15)
    assert max(data["x_max_m"][0]) > 1e-4  # the joints open and close: nonlinear here
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["x_max"].dims == ("point", "dof")
        assert list(ds["dof"].values) == ["n1x", "n2x", "n3x"]  # the DOF names, as in --json
        assert ds.attrs["method"] == "harmonic"
    # the default method follows the structure's exact orbits by shooting (issue 24); its
    # points are the exact orbits clearjoint.structure.periodic_orbit closes
    from clearjoint.structure import periodic_orbit

    code, text, err = run([*args[:-2], "--out", str(tmp_path / "y.nc"), "--json"], capsys)
    assert code == 0, err
    exact = json.loads(text)
    with xr.open_dataset(tmp_path / "y.nc", engine="h5netcdf") as ds:
        assert ds.attrs["method"] == "shooting"
        omega = float(ds["omega"].values[-1])
        u0 = ds["initial_displacement"].values[-1]
        v0 = ds["initial_velocity"].values[-1]
    orbit = periodic_orbit(s, force, omega, initial=(u0, v0))
    np.testing.assert_allclose(exact["x_max_m"][-1], orbit.x_max, rtol=1e-4)
    # a force curve of a structure is harmonic balance's only: one line
    code, _, err = run(
        [
            *args[:-2],
            "--out",
            str(tmp_path / "z.nc"),
            "--parameter",
            "force",
            "--from",
            "10N",
            "--to",
            "20N",
        ],
        capsys,
    )
    assert code == 2
    assert "follows the frequency only" in err
    assert len(err.strip().splitlines()) == 1


def test_modes_of_a_structure_study(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Mode 1 of the chain lies between its all-open (21.36 Hz) and all-closed (67.56 Hz)
    linear modes (MODEL.md 5.2) and stiffens with amplitude."""
    import xarray as xr

    study, out, png = _chain_study(tmp_path), tmp_path / "m.nc", tmp_path / "m.png"
    args = ["modes", str(study), "--amplitude", "0.2mm..20mm", "--points", "4", "--harmonics", "5"]
    code, text, err = run([*args, "--out", str(out), "--plot", str(png), "--json"], capsys)
    assert code == 0, err
    data = json.loads(text)
    assert set(data) == MODES_JSON_KEYS
    assert all(21.36 < f < 67.57 for f in data["frequency_hz"])
    assert data["frequency_hz"] == sorted(data["frequency_hz"])
    assert png.stat().st_size > 0
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["x_max"].dims == ("amplitude", "dof")
        assert list(ds["dof"].values) == ["n1x", "n2x", "n3x"]
    code, _, err = run([*args, "--mode", "4", "--out", str(tmp_path / "n.nc")], capsys)
    assert code == 2
    assert "modes 1 to 3" in err


FRICTION = '\n[losses]\ndamping_ratio = 0.01\nfriction_coefficient = 0.1\nlateral_load = "100N"\n'


@pytest.mark.parametrize(
    ("command", "losses", "message"),
    [
        (
            "modes",
            FRICTION + 'friction_region = "free-play"\n',
            'set friction_region = "everywhere"',
        ),
        ("modes", "\n[losses]\nrestitution = 0.8\n", "set restitution = 1"),
        ("frf", "\n[losses]\nrestitution = 0.8\n", "drop --method harmonic"),
        (
            "frf",
            FRICTION + 'friction_region = "free-play"\n',
            'set friction_region = "everywhere"',
        ),
    ],
)
def test_losses_harmonic_balance_cannot_carry_get_a_cli_answer(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, losses: str, message: str
) -> None:
    text = EXAMPLE.read_text()
    study = tmp_path / "lossy.toml"
    study.write_text(text[: text.index("[losses]")] + losses)
    rest = (
        ["--amplitude", "0.3mm..3mm"]
        if command == "modes"
        else ["--from", "200Hz", "--to", "300Hz", "--method", "harmonic"]
    )
    code, _, err = run([command, str(study), *rest, "--out", str(tmp_path / "x.nc")], capsys)
    assert code == 2
    assert message in err
    assert len(err.strip().splitlines()) == 1
    for python_advice in ("friction=None", "restitution=1", "clearjoint.periodic", "region="):
        assert python_advice not in err


def test_structure_study_with_impacts_is_refused_in_cli_terms(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # impacts need rigid links (a member in series has no mass to stop)
    study = _chain_study(tmp_path, restitution="restitution = 0.7\n", stiffness='"inf"')
    for command, rest in (
        ("modes", ["--amplitude", "1mm"]),
        ("frf", ["--from", "50Hz", "--to", "52Hz", "--method", "harmonic"]),
    ):
        code, _, err = run([command, str(study), *rest, "--out", str(tmp_path / "x.nc")], capsys)
        assert code == 2
        assert "set restitution = 1" in err
        assert "respond" in err
        assert len(err.strip().splitlines()) == 1


def test_frf_warns_where_the_orbit_is_not_the_exact_motion(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """At 200 rad/s one harmonic misses the chain's exact motion by about 0.24 of its
    state over a period (at 300 rad/s seven harmonics miss by 2.5e-3,
    tests/test_harmonic_check.py)."""
    study, out = _chain_study(tmp_path), tmp_path / "frf.nc"
    args = ["frf", str(study), "--from", "31.83Hz", "--to", "31.835Hz", "--out", str(out)]
    code, text, err = run([*args, "--method", "harmonic", "--harmonics", "1"], capsys)
    assert code == 0, err
    assert "untrusted:" in text
    (line,) = err.strip().splitlines()
    assert "not to be trusted; raise --harmonics" in line


def test_samples_reach_harmonic_balance(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--samples is the API's samples: the same numbers as a direct call with it, and not
    those of the default (the AFT grid changes the aliasing, so the result moves a little)."""
    import numpy as np

    from clearjoint.harmonic import frequency_response, nonlinear_modes
    from clearjoint.simulate.study import load_study

    study = load_study(EXAMPLE)
    joint = study.joint
    amplitudes = ["--amplitude", "0.3mm..3mm", "--points", "3", "--harmonics", "5"]
    out = ["--out", str(tmp_path / "m.nc"), "--json"]
    code, text, err = run(["modes", str(EXAMPLE), *amplitudes, "--samples", "22", *out], capsys)
    assert code == 0, err
    got = json.loads(text)["frequency_hz"]
    kwargs = {"harmonics": 5, "damping_ratio": study.damping_ratio}
    a = np.geomspace(0.3e-3, 3e-3, 3)
    with_22 = nonlinear_modes(joint, 1, a, samples=22, **with_losses(kwargs)).frequency / (
        2 * math.pi
    )
    default = nonlinear_modes(joint, 1, a, **with_losses(kwargs)).frequency / (2 * math.pi)
    np.testing.assert_allclose(got, with_22, rtol=1e-12)
    assert np.max(np.abs(with_22 / default - 1.0)) > 1e-6
    chain_study = _chain_study(tmp_path)
    args = ["frf", str(chain_study), "--from", "50Hz", "--to", "52Hz", "--method", "harmonic"]
    code, text, err = run(
        [*args, "--harmonics", "3", "--samples", "14", "--out", str(tmp_path / "f.nc"), "--json"],
        capsys,
    )
    assert code == 0, err
    from clearjoint import ClearanceJoint
    from clearjoint.structure import chain

    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    s = chain([1.0] * 3, [1e6] * 3, [j] * 3, dampers=[150.0] * 3)
    direct = frequency_response(
        s, [0.0, 0.0, 40.0], 2 * math.pi * 50, 2 * math.pi * 52, harmonics=3, samples=14
    )
    np.testing.assert_allclose(json.loads(text)["x_max_m"], direct.x_max, rtol=1e-9, atol=1e-15)


def test_frf_without_an_orbit_at_the_start_says_so_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The example mast at 20 N, H = 15 in small: the start's force continuation (which the
    chain needs at 800 rad/s) held to 10 points, so it gives up; progress lines, then one
    error line saying what to do, exit 2 (the mast itself: about 60 s, docs/harmonic.md)."""
    from clearjoint.harmonic import response

    monkeypatch.setattr(response, "START_POINTS", (10, 10))
    study, out = _chain_study(tmp_path), tmp_path / "frf.nc"
    start = f"{800 / (2 * math.pi)}Hz"
    args = ["frf", str(study), "--from", start, "--to", "130Hz", "--method", "harmonic"]
    code, _, err = run([*args, "--out", str(out)], capsys)
    assert code == 2
    *progress, last = err.strip().splitlines()
    assert progress
    assert progress[0].startswith("clearjoint frf: start at 127.324 Hz: Newton from the linear")
    assert last.startswith(f"clearjoint frf: error: {study}: no harmonic-balance orbit at 127.324")
    assert "lower [excitation] force_amplitude" in last
    assert f"clearjoint structure {study} respond" in last
    assert "Traceback" not in err
    assert not out.exists()


def test_modes_of_a_joint_study_with_friction(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Friction over the whole path used to be refused by `clearjoint modes`; now it runs,
    with the same --json keys, and (no viscous damping) its energy per cycle is Coulomb's
    work on the orbit, 2 mu_s P (x_max - x_min) with mu_s P = 10 N (MODEL.md section 2)."""
    import xarray as xr

    text = EXAMPLE.read_text()
    study = tmp_path / "rubbing.toml"
    study.write_text(text[: text.index("[losses]")] + FRICTION.replace("0.01", "0"))
    out = tmp_path / "m.nc"
    args = ["modes", str(study), "--amplitude", "0.1mm..2mm", "--points", "4", "--json"]
    code, printed, err = run([*args, "--out", str(out)], capsys)
    assert code == 0, err
    data = json.loads(printed)
    assert set(data) == MODES_JSON_KEYS
    assert all(z > 0.0 for z in data["damping_ratio"])
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        span = ds["x_max"].values - ds["x_min"].values
    np.testing.assert_allclose(data["energy_per_cycle_j"], 2.0 * 10.0 * span, rtol=2e-3)
