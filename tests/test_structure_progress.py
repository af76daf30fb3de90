"""Progress of a structure's exact motion (issue 28, Build 2): the march in pieces.

``time_response`` and ``free_decay`` march in ``PROGRESS_PIECES`` pieces, reporting the
seconds of motion done after each; a piece ends between two steps and the next resumes
from the march's clock, so the motion is the one march's to the bit. Checked against the
march in one piece (no pause) on the chain at 30 N, a motion of hundreds of impacts (a
step made differently would move every event after it), and on the command line, whose
progress lines (stderr no terminal) come from these reports.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from clearjoint import cli, cli_progress
from clearjoint.progress import listening
from clearjoint.structure import motion as structure_motion
from clearjoint.structure.study import load_structure_study
from helpers import check_progress_lines

ROOT = Path(__file__).resolve().parents[1]
CHAIN = ROOT / "examples" / "chain.toml"


def _same(a: structure_motion.StructureMotion, b: structure_motion.StructureMotion) -> None:
    for name in ("t", "u", "v", "pattern", "event_times", "event_joints", "event_states"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.energy == b.energy
    assert a.steps == b.steps
    assert a.patterns_visited == b.patterns_visited
    for x, y in zip(a.final_state, b.final_state, strict=True):
        np.testing.assert_array_equal(x, y)


def test_a_response_marched_in_pieces_is_the_whole_march_to_the_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    study = load_structure_study(str(CHAIN))
    assert study.omega is not None
    assert study.force is not None
    duration = 20 * 2.0 * math.pi / study.omega  # the study's 20 periods
    heard: list[tuple[float, float]] = []
    with listening(lambda done, total: heard.append((done, total))):
        pieces = structure_motion.time_response(
            study.structure, study.force, study.omega, duration, samples_per_period=64
        )
    assert pieces.events > 100  # a motion with many impacts, not a linear one
    assert len(heard) == structure_motion.PROGRESS_PIECES
    done = [d for d, _ in heard]
    assert done == sorted(done)
    assert done[0] > 0.0
    assert heard[-1] == (duration, duration)
    monkeypatch.setattr(structure_motion, "PROGRESS_PIECES", 1)
    with listening(lambda done, total: heard.append((done, total))):
        whole = structure_motion.time_response(
            study.structure, study.force, study.omega, duration, samples_per_period=64
        )
    assert len(heard) == len(done)  # in one piece: no report
    _same(pieces, whole)


def test_a_decay_marched_in_pieces_is_the_whole_march_to_the_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    study = load_structure_study(str(CHAIN))
    s = study.structure
    initial = (np.full(s.n_dof, 2e-3), np.zeros(s.n_dof))
    pieces = structure_motion.free_decay(s, initial, 0.5, samples_per_period=64)
    monkeypatch.setattr(structure_motion, "PROGRESS_PIECES", 1)
    whole = structure_motion.free_decay(s, initial, 0.5, samples_per_period=64)
    assert whole.events > 10
    _same(pieces, whole)


def test_structure_respond_says_how_far_it_is_without_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(cli_progress, "PROGRESS_EVERY_S", 0.0)
    monkeypatch.setattr(cli_progress, "PROGRESS_LINES_IN_PROCESS", True)  # as the command
    args = ["structure", str(CHAIN), "respond", "--out", str(tmp_path / "r.nc")]
    assert cli.main(args) == 0
    check_progress_lines(capsys.readouterr().err, f"clearjoint structure: respond of {CHAIN}")
