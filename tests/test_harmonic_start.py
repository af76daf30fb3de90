"""The start of a harmonic-balance curve (harmonic.response._start): its force continuation
has a limit, reports progress, and ends in one clear error when it finds no orbit."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from clearjoint.harmonic import HarmonicError, frequency_response, response
from clearjoint.structure import Structure

FORCE = np.array([0.0, 0.0, 40.0])
#: At 800 rad/s Newton from the linear responses misses this chain's orbit; the start's
#: force continuation reaches it in 45 points (measured).
OMEGA = 800.0


def test_the_force_continuation_reports_progress_and_finds_the_start(
    three_links: Structure, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.INFO, logger="clearjoint.harmonic"):
        curve = frequency_response(three_links, FORCE, OMEGA, 810.0, max_points=3, check_points=0)
    assert curve.force_amplitude[0] == pytest.approx(40.0)
    lines = [r.getMessage() for r in caplog.records if r.name == "clearjoint.harmonic"]
    assert "following the force up" in lines[0]
    assert "at most 2000 points" in lines[0]  # START_BUDGET // 45 unknowns, capped
    assert any("force continuation at" in line for line in lines[1:])


def test_a_start_past_the_limit_is_one_clear_error(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(response, "START_POINTS", (10, 10))
    with pytest.raises(response.NoPeriodicResponse) as info:
        frequency_response(three_links, FORCE, OMEGA, 810.0, max_points=3, check_points=0)
    error = info.value
    assert isinstance(error, HarmonicError)
    assert error.omega == OMEGA
    assert 0.0 < error.reached < 1.0
    message = str(error)
    assert "\n" not in message
    assert "max_points after 10 points" in message
    assert f"reached only {error.reached * 40:.3g} N of 40 N" in message
    assert "start at a lower force" in message


def test_the_force_continuation_does_not_report_into_the_curves_progress(
    three_links: Structure,
) -> None:
    # the start's force continuation counts the force, not the curve's frequency range; a
    # display ends at the first series of reports that finishes (cli_progress), so the
    # start's reports reaching the full force would end the curve's bar before the curve
    from clearjoint.progress import listening

    heard: list[tuple[float, float]] = []
    with listening(lambda done, total: heard.append((done, total))):
        frequency_response(three_links, FORCE, OMEGA, 810.0, max_points=3, check_points=0)
    assert heard
    assert [total for _, total in heard] == pytest.approx([10.0] * len(heard)), heard[:3]  # rad/s
    assert all(done < total for done, total in heard[:-1])
