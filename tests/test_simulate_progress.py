"""Progress of a joint's transient (issue 28, Build 2): the kernel run in pieces.

``time_response`` runs the event kernel in ``PROGRESS_PIECES`` pieces of whole forcing
periods, reporting the seconds of motion done after each; each period starts at forcing
phase 0 from the state the last one ended in, so the motion is the one run's to the bit.
Checked against the run in one piece on the example joint (impacts, stick-slip friction
and a pin, so every record and the whole ledger are exercised), and on the command line,
whose progress lines (stderr no terminal) come from these reports.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from clearjoint import Joint, Losses, cli, cli_progress
from clearjoint.exact import single
from clearjoint.progress import listening
from clearjoint.simulate import time_response
from clearjoint.studies import load_study
from helpers import check_progress_lines

ROOT = Path(__file__).resolve().parents[1]
STUDY = ROOT / "examples" / "study.toml"


def _transient(duration: float) -> tuple[object, list[tuple[float, float]]]:
    study = load_study(str(STUDY))
    heard: list[tuple[float, float]] = []
    with listening(lambda done, total: heard.append((done, total))):
        motion = time_response(
            study.joint,
            study.force_amplitude,
            study.omega,
            duration,
            losses=study.losses,
            samples_per_period=32,
        )
    return motion, heard


def test_a_transient_run_in_pieces_is_the_one_run_to_the_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    duration = 0.1013  # 40.52 periods at 400 Hz: the last one cut short
    pieces, heard = _transient(duration)
    assert pieces.events > 100  # type: ignore[attr-defined]
    assert len(pieces.impact_times) > 20  # type: ignore[attr-defined]
    assert len(heard) == 41  # one a period: 41 periods, fewer than PROGRESS_PIECES
    done = [d for d, _ in heard]
    assert done == sorted(done)
    assert done[0] == pytest.approx(1 / 400)
    assert heard[-1][0] == heard[-1][1] == pytest.approx(duration, rel=1e-12)
    monkeypatch.setattr(single, "PROGRESS_PIECES", 1)
    whole, heard_whole = _transient(duration)
    assert heard_whole == []  # in one piece: no report
    for field in dataclasses.fields(whole):  # type: ignore[arg-type]
        a, b = getattr(pieces, field.name), getattr(whole, field.name)
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b, err_msg=field.name)
        else:
            assert a == b, field.name


def test_a_long_transient_is_reported_in_at_most_the_stated_pieces() -> None:
    _, heard = _transient(0.5)  # 200 periods
    assert len(heard) == single.PROGRESS_PIECES
    assert heard[-1][0] == pytest.approx(0.5, rel=1e-12)


def test_simulate_says_how_far_a_transient_is_without_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    study = tmp_path / "transient.toml"
    text = STUDY.read_text(encoding="utf-8")
    study.write_text(
        text.replace('# mode = "steady"', 'mode = "transient"\nduration = "0.5s"'),
        encoding="utf-8",
    )
    monkeypatch.setattr(cli_progress, "PROGRESS_EVERY_S", 0.0)
    monkeypatch.setattr(cli_progress, "PROGRESS_LINES_IN_PROCESS", True)  # as the command
    assert cli.main(["simulate", str(study), "--json"]) == 0
    check_progress_lines(capsys.readouterr().err, f"clearjoint simulate: simulating {study}")


def test_a_campaign_run_here_reports_in_tests_not_in_its_transients_seconds(
    tmp_path: Path,
) -> None:
    """The rig's tests are transients (time_response); in this process (jobs=1) their own
    reports would reach the campaign's listener in seconds of motion, and the first to
    finish would end the command's display after one test."""
    from clearjoint.rig import load_campaign, run_campaign

    path = tmp_path / "campaign.toml"
    path.write_text(
        'seed = 7\nperiods = 12\n[grid]\nfrequencies = ["40Hz"]\n'
        'force_amplitudes = ["1200N", "2500N"]\n[[structures]]\nname = "joint-1"\n'
        'clearance = "0.106mm"\n',
        encoding="utf-8",
    )
    heard: list[tuple[float, float]] = []
    with listening(lambda done, total: heard.append((done, total))):
        run_campaign(load_campaign(path), tmp_path / "out", jobs=1)
    assert heard == [(1.0, 2.0), (2.0, 2.0)]


def _linear_strobe(zeta: float, omega_n: float, omega: float, periods: int) -> np.ndarray:
    """The state at each forcing period's start of m x'' + 2 zeta omega_n x' + omega_n^2 x
    = F sin(omega t) from rest (m = 1, F = 1), in closed form: the steady sine plus the
    free decay that meets the start (an independent route: no clearjoint solver)."""
    wd = omega_n * np.sqrt(1.0 - zeta**2)
    # steady part X sin(omega t - phi)
    denominator = (omega_n**2 - omega**2) ** 2 + (2 * zeta * omega_n * omega) ** 2
    a = (omega_n**2 - omega**2) / denominator  # coefficient of sin
    b = -2 * zeta * omega_n * omega / denominator  # coefficient of cos
    x0, v0 = -b, -a * omega  # the free part cancels the steady part at t = 0
    t = np.arange(periods) * 2 * np.pi / omega
    decay = np.exp(-zeta * omega_n * t)
    c1, c2 = x0, (v0 + zeta * omega_n * x0) / wd
    x_free = decay * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
    v_free = decay * (
        -zeta * omega_n * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
        + wd * (-c1 * np.sin(wd * t) + c2 * np.cos(wd * t))
    )
    strobe = np.zeros((periods, 4))
    strobe[:, 0] = b + x_free  # sin(0) = 0, cos(0) = 1 at each period's start
    strobe[:, 1] = a * omega + v_free
    return strobe


@pytest.mark.parametrize(("zeta", "omega"), [(0.01, 0.7), (0.002, 0.9), (0.02, 1.3)])
def test_the_periods_left_to_settle_match_a_linear_oscillators_closed_form(
    zeta: float, omega: float
) -> None:
    """From its first 64 periods, the estimate of a linear oscillator's settling is within
    10 % (and two periods) of the period from which its closed-form transient repeats to
    the tolerance with some period of 1 to 8 forcing periods (steady_state's test)."""
    from clearjoint.simulate.core import periods_left

    tolerance = 1e-11
    strobe = _linear_strobe(zeta, 1.0, omega, 20_000)
    x_scale = float(np.max(np.abs(strobe[:, 0])))
    v_scale = float(np.max(np.abs(strobe[:, 1])))
    settled = strobe.shape[0]
    for lag in range(1, 9):
        step = np.maximum(
            np.abs(strobe[lag:, 0] - strobe[:-lag, 0]) / x_scale,
            np.abs(strobe[lag:, 1] - strobe[:-lag, 1]) / v_scale,
        )
        below = step.size - int(np.argmax(step[::-1] >= tolerance))  # below it from here on
        settled = min(settled, below + lag)
    assert settled > 200
    left = periods_left(strobe[:64], 8, tolerance, x_scale, v_scale)
    assert left is not None
    assert abs(64 + left - settled) <= 0.1 * settled + 2


def test_no_estimate_where_the_motion_does_not_settle() -> None:
    from clearjoint.simulate.core import periods_left

    t = np.arange(200.0)
    strobe = np.zeros((200, 4))
    strobe[:, 0] = np.sin(0.37 * t)  # undamped, incommensurate: never closes
    strobe[:, 1] = np.cos(0.37 * t)
    left = periods_left(strobe, 8, 1e-11, 1.0, 1.0)
    assert left is None or left > 1e4  # none, or beyond any sensible max_periods
    assert periods_left(strobe[:5], 8, 1e-11, 1.0, 1.0) is None  # too few periods


def test_a_steady_state_reports_its_periods_and_an_estimate_then_ends_done() -> None:
    """A lightly damped joint inside its gap (linear: k0, zeta = 0.002) settles over some
    2,000 periods, run in chunks that double: each chunk reports the periods done and an
    estimate of the total, within a factor 2 of the periods the run took (its last chunk
    may overshoot the settling by up to its own length)."""
    from clearjoint.simulate import steady_state

    joint = Joint(mass=1.0, clearance=2.0, gap_stiffness=1.0, compression_stiffness=3.0)
    heard: list[tuple[float, float]] = []
    with listening(lambda done, total: heard.append((done, total))):
        cycle = steady_state(joint, 0.01, 0.9, losses=Losses(damping_ratio=0.002))
    assert cycle.amplitude < 1.0  # never left the gap: a linear oscillator
    done = [d for d, _ in heard]
    assert len(heard) >= 5
    assert done == sorted(done)
    assert all(d <= t for d, t in heard)
    assert heard[-1][0] == heard[-1][1]  # the last report closes the bar
    took = heard[-1][0]
    for d, total in heard[2:-1]:  # from 112 periods known
        assert took / 2 <= total <= 2 * took, (d, total, took)


def test_a_stepped_sine_reports_its_steps_not_each_steps_periods() -> None:
    from clearjoint.simulate import frequency_sweep

    study = load_study(str(STUDY))
    heard: list[tuple[float, float]] = []
    omegas = study.omega * np.array([0.9, 1.0, 1.1])
    with listening(lambda done, total: heard.append((done, total))):
        frequency_sweep(
            study.joint, study.force_amplitude, omegas, losses=study.losses, direction="both"
        )
    assert heard == [(float(i), 6.0) for i in range(1, 7)]


def test_a_steady_state_without_an_estimate_counts_its_periods_against_its_limit() -> None:
    """A lossless joint never settles: every chunk of periods is still reported (16, 48,
    ... doubling), against max_periods, the most the run will do, and the run then fails
    (it reported nothing where the fit gave no estimate: the first chunk, too short)."""
    from clearjoint.simulate import SimulationError, steady_state

    lossless = Joint(
        mass=1.0, clearance=0.349, gap_stiffness=1.0, compression_stiffness=3.0,
        tension_stiffness=3.0,
    )  # fmt: skip
    heard: list[tuple[float, float]] = []
    with (
        listening(lambda done, total: heard.append((done, total))),
        pytest.raises(SimulationError, match="never settles"),
    ):
        steady_state(lossless, 0.03, 1.1, max_periods=2000)
    assert [done for done, _ in heard] == [16.0, 48.0, 112.0, 240.0, 496.0, 1008.0, 2000.0]
    assert all(total == 2000.0 for _, total in heard)


def test_the_estimate_for_a_motion_that_never_settles_is_beyond_any_run() -> None:
    """Lossless, incommensurate: the stroboscopic distance does not shrink, so the fit's
    slope is noise; what it gives, if anything, is beyond a million periods."""
    from clearjoint.simulate.core import periods_left

    t = np.arange(200.0)
    for ratio in (0.37, 0.5, 1.1, 2.3):
        strobe = np.zeros((200, 4))
        strobe[:, 0] = np.sin(ratio * t)
        strobe[:, 1] = np.cos(ratio * t)
        left = periods_left(strobe, 8, 1e-11, 1.0, 1.0)
        assert left is None or left > 1e5, ratio


def test_no_time_left_is_told_from_the_milliseconds_after_a_compile(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without a terminal: a first report 40 s in (a compile came before) and a second
    10 ms later gave "2 % done, about 0 s left"; the rate now spans 10 s at least, and the
    time left is the one that rate gives (88 % at 1 % a second: 88 s)."""
    import argparse

    now = [0.0]
    monkeypatch.setattr(cli_progress.time, "perf_counter", lambda: now[0])
    args = argparse.Namespace(command="frf", quiet=False, progress_lines=True)
    with cli_progress.shown_progress(args, "following the curve") as listener:
        for at, done in ((40.0, 1.0), (40.01, 2.0), (51.0, 12.0)):
            now[0] = at
            listener(done, 100.0)
    lines = [line for line in capsys.readouterr().err.splitlines() if "% done" in line]
    assert lines == ["clearjoint frf: 12 % done, about 88 s left"]
