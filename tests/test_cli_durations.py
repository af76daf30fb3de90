"""Runaway durations on the command line, refused up front with an estimate (issue 28, Build 3).

A transient's duration, a structure's [excitation] periods and [decay] duration, and a
stepped sine's --points x (--settle-periods + --record-periods): above an hour estimated,
exit 2 with one line giving the estimate and --allow-long, before any work. The estimates
below are written out from clearjoint.budget's published costs (1e-4 s a joint forcing
period; 1e-4 s x DOF^2 a structure period), not taken from the code under test.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from clearjoint import cli, studies
from clearjoint.errors import ParameterError

ROOT = Path(__file__).resolve().parents[1]
CHAIN = (ROOT / "examples" / "chain.toml").read_text(encoding="utf-8")  # 5 DOF, 40 Hz
STUDY = (ROOT / "examples" / "study.toml").read_text(encoding="utf-8")  # a joint at 400 Hz


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = cli.main(args)
    return code, capsys.readouterr().err


def _refused(err: str, start: str) -> None:
    assert err.count("\n") == 1, err
    assert err.startswith(start), err
    assert "above the limit of 60 min" in err
    assert err.endswith("pass --allow-long to run it anyway\n")


def _study(tmp_path: Path, text: str, name: str = "s.toml") -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_a_stepped_sine_settling_a_hundred_thousand_periods_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 100 x (100000 + 100) periods x 1e-4 s x 5^2 = 25,025 s = 6.95 h
    out = tmp_path / "m.nc"
    args = ["structure", str(ROOT / "examples" / "chain.toml"), "stepped-sine"]
    args += ["--from", "2Hz", "--to", "60Hz", "--settle-periods", "100000", "--out", str(out)]
    code, err = _run(args, capsys)
    assert code == 2
    _refused(
        err,
        "clearjoint structure: error: --points 100 x (--settle-periods 100000 + "
        "--record-periods 100) periods: about 7.0 h of computing (0.0025 s per period of "
        "this 5-DOF structure)",
    )
    assert not out.exists()
    code, err = _run([*args, "--direction", "both"], capsys)  # up and down: twice the periods
    assert code == 2
    assert "x 2 directions: about 13.9 h" in err  # 50,050 s


def test_a_stepped_sine_of_usual_size_and_allow_long_reach_the_test(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def stepped(*_args: object, **kwargs: object) -> None:
        raise ParameterError(f"reached the test, settling {kwargs['settle_periods']}")

    monkeypatch.setattr(studies, "stepped_sine_of", stepped)
    args = ["structure", str(ROOT / "examples" / "chain.toml"), "stepped-sine", "--quiet"]
    args += ["--from", "2Hz", "--to", "60Hz", "--out", str(tmp_path / "m.nc")]
    code, err = _run(args, capsys)  # 100 x 300 periods: 75 s estimated
    assert (code, err) == (2, "clearjoint structure: error: reached the test, settling 200\n")
    code, err = _run([*args, "--settle-periods", "100000", "--allow-long"], capsys)
    assert (code, err) == (2, "clearjoint structure: error: reached the test, settling 100000\n")


def test_a_response_over_ten_million_periods_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert "periods = 20\n" in CHAIN
    study = _study(tmp_path, CHAIN.replace("periods = 20\n", "periods = 10000000\n"))
    code, err = _run(["structure", study, "respond", "--out", str(tmp_path / "r.nc")], capsys)
    assert code == 2
    # 1e7 periods x 1e-4 s x 5^2 = 25,000 s = 6.94 h
    _refused(err, "clearjoint structure: error: [excitation] periods 10000000: about 6.9 h")


def test_a_decay_of_a_million_seconds_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    decay = '\n[decay]\ndof = "n5x"\ninitial_amplitude = "1mm"\nduration = "1e6s"\n'
    study = _study(tmp_path, CHAIN + decay)
    code, err = _run(["structure", study, "decay", "--out", str(tmp_path / "d.nc")], capsys)
    assert code == 2
    _refused(err, "clearjoint structure: error: [decay] duration 1e+06 s (")
    # the chain's lowest closed mode, fixed-free, 5 masses m = 0.5 kg on joints of
    # k = k0 + k_c = 4.2e5 N/m (rigid members): w1 = 2 sqrt(k / m) sin(pi / 22), 41.5 Hz
    f1 = 2.0 * math.sqrt(4.2e5 / 0.5) * math.sin(math.pi / 22.0) / (2.0 * math.pi)
    periods = float(err.split(" s (")[1].split(" periods")[0])
    assert periods == pytest.approx(1e6 * f1, rel=5e-3)  # printed to 3 digits
    hours = 1e6 * f1 * 1e-4 * 25 / 3600.0  # 28.8 h
    assert f"about {hours:.1f} h of computing (0.0025 s per period of this 5-DOF" in err


def test_a_transient_of_a_million_seconds_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    assert "[excitation]\n" in STUDY
    long = '[excitation]\nmode = "transient"\nduration = "1e6s"\n'
    study = _study(tmp_path, STUDY.replace("[excitation]\n", long))
    code, err = _run(["simulate", study], capsys)
    assert code == 2
    # 1e6 s x 400 Hz = 4e8 forcing periods x 1e-4 s = 40,000 s = 11.1 h
    _refused(
        err,
        "clearjoint simulate: error: [excitation] duration 1e+06 s (4e+08 forcing periods): "
        "about 11.1 h of computing (0.0001 s per joint forcing period)",
    )

    def run(*_args: object) -> None:
        raise ParameterError("reached the run")

    monkeypatch.setattr(studies, "run_study", run)
    code, err = _run(["simulate", study, "--allow-long"], capsys)
    assert (code, err) == (2, "clearjoint simulate: error: reached the run\n")
    short = _study(tmp_path, STUDY.replace("[excitation]\n", long.replace("1e6s", "1s")), "t")
    code, err = _run(["simulate", short], capsys)  # 400 periods: 0.04 s, no check in the way
    assert (code, err) == (2, "clearjoint simulate: error: reached the run\n")


def test_a_steady_state_written_over_ten_million_periods_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Its cost is memory, not time: 1e7 periods x 256 samples x 110 bytes = 262 GiB
    (clearjoint.budget's published bytes a sample), against a limit of 4 GiB."""
    path = _study(tmp_path, STUDY + "\n[output]\nperiods = 10000000\n")
    assert studies.load_study(path).mode == "steady"  # the example study's default mode
    out = tmp_path / "s.nc"
    code, err = _run(["simulate", path, "--out", str(out)], capsys)
    assert code == 2
    assert err.count("\n") == 1, err
    assert err.startswith(
        "clearjoint simulate: error: [output] periods 10000000 x samples_per_period 256: "
        "about 262 GiB of series in memory and on disk"
    ), err
    assert err.endswith("ask for fewer periods, or pass --allow-long to write it anyway\n")
    assert not out.exists()


MAST = ROOT / "examples" / "mast.toml"  # 40 DOF


def test_the_mast_default_stepped_sine_is_refused_with_its_tangent_flow(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A recorded period also carries the (2N, 2N) tangent flow: 3e-5 s x N^3 more
    (clearjoint.budget's published cost). The default 100 x (200 + 100) periods of the
    40-DOF mast: 30,000 x 1e-4 x 40^2 = 4,800 s and 10,000 x 3e-5 x 40^3 = 19,200 s,
    24,000 s = 6.7 h, where the periods alone gave 80 min."""
    args = ["structure", str(MAST), "stepped-sine", "--from", "5Hz", "--to", "60Hz"]
    code, err = _run([*args, "--out", str(tmp_path / "m.nc")], capsys)
    assert code == 2
    _refused(
        err,
        "clearjoint structure: error: --points 100 x (--settle-periods 200 + "
        "--record-periods 100) periods: about 6.7 h of computing (0.16 s per period of "
        "this 40-DOF structure) plus the tangent flow of 10000 periods (1.92 s each)",
    )


def test_recorded_periods_alone_can_make_a_stepped_sine_too_long(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def stepped(*_args: object, **kwargs: object) -> None:
        raise ParameterError(f"reached the test, recording {kwargs['record_periods']}")

    monkeypatch.setattr(studies, "stepped_sine_of", stepped)
    args = ["structure", str(MAST), "stepped-sine", "--from", "5Hz", "--to", "60Hz"]
    args += ["--out", str(tmp_path / "m.nc"), "--points", "10", "--settle-periods", "1"]
    # 10 x (1 + 150) periods x 0.16 s = 242 s, and 1500 recorded x 1.92 s = 2,880 s: 52 min
    code, err = _run([*args, "--record-periods", "150"], capsys)
    assert (code, err) == (2, "clearjoint structure: error: reached the test, recording 150\n")
    # 10 x (1 + 200) x 0.16 = 322 s (the periods alone would pass) + 2000 x 1.92 = 4,162 s
    code, err = _run([*args, "--record-periods", "200"], capsys)
    assert code == 2
    _refused(err, "clearjoint structure: error: --points 10 x (--settle-periods 1 + ")
    assert "about 69 min of computing" in err
    assert "plus the tangent flow of 2000 periods (1.92 s each)" in err
    code, err = _run([*args, "--record-periods", "200", "--allow-long"], capsys)
    assert (code, err) == (2, "clearjoint structure: error: reached the test, recording 200\n")


def test_a_stepped_sine_of_no_periods_reaches_its_own_refusal(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The estimate's share of recorded periods has no periods to share here: the stepped
    sine's own one-line refusal, not a division by zero."""
    args = ["structure", str(MAST), "stepped-sine", "--from", "5Hz", "--to", "60Hz"]
    args += ["--settle-periods", "0", "--record-periods", "0", "--out", str(tmp_path / "m.nc")]
    code, err = _run(args, capsys)
    assert (code, err) == (
        2,
        "clearjoint structure: error: settle_periods must be an integer >= 1, got 0\n",
    )
