"""The start of a harmonic-balance curve (harmonic.response._start): its force continuation
has a limit, reports progress, and ends in one clear error when it finds no orbit."""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from clearjoint import ClearanceJoint
from clearjoint.harmonic import HarmonicError, aft, frequency_response, response, solve
from clearjoint.harmonic.system import LinearSystem, from_structure
from clearjoint.structure import Structure, chain, mast

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


def _start_of(
    structure: Structure, force: np.ndarray, omega: float
) -> tuple[np.ndarray, LinearSystem, aft.Basis]:
    """The start's orbit at H = 7, its model and basis (as frequency_response makes them)."""
    model = from_structure(structure)
    basis = aft.Basis.make(*aft.check_harmonics(7, None))
    return (
        response._start_plain(model, basis, omega, force, model.reference_stiffness),
        model,
        basis,
    )


def _residual(
    model: LinearSystem, basis: aft.Basis, q: np.ndarray, omega: float, force: np.ndarray
) -> float:
    """max abs of HB's residual at q, relative to the model's reference stiffness."""
    ev = aft.evaluate(model, basis, q, omega, force, jacobian=False)
    return float(np.max(np.abs(ev.residual))) / model.reference_stiffness


def _paths(
    monkeypatch: pytest.MonkeyPatch,
    change: Callable[[float, Any], Any] | None = None,
) -> list[tuple[float, Any]]:
    """Record each force path the start follows, as (its tolerance, its branch), in order;
    ``change(tolerance, branch)``, if given, replaces the branch the start sees."""
    runs: list[tuple[float, Any]] = []
    real = response.continue_branch

    def recorded(*args: Any, **kwargs: Any) -> Any:
        tolerance = kwargs["settings"].tolerance
        branch = real(*args, **kwargs)
        if change is not None:
            branch = change(tolerance, branch)
        runs.append((tolerance, branch))
        return branch

    monkeypatch.setattr(response, "continue_branch", recorded)
    return runs


def _examples_chain() -> Structure:
    """examples/chain.toml's chain: five 0.5 kg masses, rigid links, 0.2 mm joints."""
    joint = ClearanceJoint(clearance=0.2e-3, compression_stiffness=4e5, gap_stiffness=2e4)
    return chain([0.5] * 5, [np.inf] * 5, [joint] * 5, dampers=[2.0] * 5)


def test_the_loose_force_path_ends_on_the_tight_paths_orbit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # the 20-bay mast (sparse route): the homotopy follows its path to START_TOLERANCE
    # and Newton polishes the end at the full force: the orbit must be the one the path
    # followed to TOLERANCE (as before) ends on, to that tolerance, and it must be a
    # converged HB orbit by a residual evaluated here, not by the solver's own report
    structure = mast(20, joints=ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5), rayleigh=(0.0, 2e-6))
    force = np.zeros(structure.n_dof)
    force[list(structure.dof_names).index("n41x")] = 0.1
    omega = 0.8 * float(structure.modes("open").omega[0])
    runs = _paths(monkeypatch)
    loose, model, basis = _start_of(structure, force, omega)
    # the homotopy ran (Newton from the linear guesses failed), once, on the loose path
    assert [tolerance for tolerance, _ in runs] == [response.START_TOLERANCE]
    assert response.START_TOLERANCE > response.TOLERANCE
    monkeypatch.setattr(response, "START_TOLERANCE", response.TOLERANCE)
    tight, *_ = _start_of(structure, force, omega)
    largest = float(np.max(np.abs(tight)))
    assert np.max(np.abs(loose - tight)) <= 1e-8 * largest
    assert _residual(model, basis, loose, omega, force) <= 1e-9 * largest


def test_an_end_that_does_not_polish_is_followed_again_at_the_tolerance(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    runs = _paths(monkeypatch)
    monkeypatch.setattr(response, "_newton_at", lambda *args, **kwargs: None)
    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    with caplog.at_level(logging.INFO, logger="clearjoint.harmonic"):
        q, model, basis = _start_of(three_links, FORCE, OMEGA)
    assert [tolerance for tolerance, _ in runs] == [response.START_TOLERANCE, response.TOLERANCE]
    assert any("following it again" in r.getMessage() for r in caplog.records)
    assert _residual(model, basis, q, OMEGA, FORCE) <= 1e-9 * float(np.max(np.abs(q)))


def test_a_loose_path_that_does_not_reach_the_force_is_followed_again_at_the_tolerance(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    # examples/chain.toml's chain at 5 N and 42.5 Hz: the force path followed to
    # START_TOLERANCE runs out of points (its larger steps lose the path near a grazing),
    # the path followed to TOLERANCE (the start before issue 25's fifth round) reaches the
    # full force in about 400 points: the start must still find that orbit
    structure = _examples_chain()
    force = np.array([0.0, 0.0, 0.0, 0.0, 5.0])
    omega = 2.0 * np.pi * 42.5
    runs = _paths(monkeypatch)
    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    monkeypatch.setattr(response, "START_POINTS", (600, 600))  # the tight path: ~400
    with caplog.at_level(logging.INFO, logger="clearjoint.harmonic"):
        q, model, basis = _start_of(structure, force, omega)
    assert [tolerance for tolerance, _ in runs] == [response.START_TOLERANCE, response.TOLERANCE]
    assert runs[0][1].reason != "reached", runs
    assert runs[1][1].reason == "reached", runs
    assert any("did not reach the full force" in r.getMessage() for r in caplog.records)
    # an HB orbit at the full force by a residual evaluated here
    assert _residual(model, basis, q, omega, force) <= 1e-9 * float(np.max(np.abs(q)))


def test_a_small_structure_follows_the_tight_path_alone(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Below solve.SPARSE_ABOVE unknowns the start's homotopy is as before issue 25's fifth
    round: one path, to the curve's tolerance (small paths are cheap and fold often)."""
    runs = _paths(monkeypatch)
    _start_of(three_links, FORCE, OMEGA)
    assert [tolerance for tolerance, _ in runs] == [response.TOLERANCE]


def test_a_loose_path_that_turns_back_is_followed_again_at_the_tolerance(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    # examples/chain.toml's chain at 10 N and 50 Hz (on the sparse route): the path folds
    # in the force several times; followed to START_TOLERANCE it ended, polished, on an HB
    # orbit 32 % from the one the path followed to TOLERANCE ends on (review of issue 25).
    # A path that turns back is followed again at TOLERANCE: the start is that path's end
    structure = _examples_chain()
    force = np.array([0.0, 0.0, 0.0, 0.0, 10.0])
    omega = 2.0 * np.pi * 50.0
    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    runs = _paths(monkeypatch)
    with caplog.at_level(logging.INFO, logger="clearjoint.harmonic"):
        q, model, basis = _start_of(structure, force, omega)
    assert [tolerance for tolerance, _ in runs] == [response.START_TOLERANCE, response.TOLERANCE]
    assert np.any(np.diff(runs[0][1].lam) < 0.0)  # the loose path turned back
    assert any("turned back in the force" in r.getMessage() for r in caplog.records)
    monkeypatch.setattr(response, "START_TOLERANCE", response.TOLERANCE)
    tight, *_ = _start_of(structure, force, omega)
    np.testing.assert_array_equal(q, tight)
    assert _residual(model, basis, q, omega, force) <= 1e-9 * float(np.max(np.abs(q)))


def test_an_end_that_does_not_polish_falls_back_even_where_the_path_does_not_turn_back(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """The polish's own fallback, apart from the fold's: the 3-link chain's loose path turns
    back in the force, so in the test above the fold guard fires first and the polish is
    never reached. Here the loose path's parameter is made monotone (its end unchanged, at
    the full force), so only a failed polish can send the start to the tight path: the
    start must then be the tight path's end, as before issue 25's fifth round."""

    def monotone(tolerance: float, branch: Any) -> Any:
        if tolerance == response.TOLERANCE:
            return branch
        return dataclasses.replace(branch, lam=np.maximum.accumulate(branch.lam))

    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    monkeypatch.setattr(response, "_newton_at", lambda *args, **kwargs: None)
    runs = _paths(monkeypatch, monotone)
    with caplog.at_level(logging.INFO, logger="clearjoint.harmonic"):
        q, *_ = _start_of(three_links, FORCE, OMEGA)
    assert [tolerance for tolerance, _ in runs] == [response.START_TOLERANCE, response.TOLERANCE]
    messages = [r.getMessage() for r in caplog.records]
    assert any("did not polish" in m for m in messages), messages
    assert not any("turned back" in m for m in messages), messages
    monkeypatch.setattr(response, "START_TOLERANCE", response.TOLERANCE)
    tight, *_ = _start_of(three_links, FORCE, OMEGA)
    np.testing.assert_array_equal(q, tight)
