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

from clearjoint import cli, cli_progress
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
