"""The one-period check of harmonic-balance orbits against the exact motion (harmonic/check.py)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from clearjoint import Joint, ParameterError
from clearjoint.harmonic import frequency_response
from clearjoint.harmonic.check import RESIDUAL_TOLERANCE, check_orbits, untrusted_events
from clearjoint.periodic import FrequencyResponse
from clearjoint.structure import Structure

FORCE = np.array([0.0, 0.0, 40.0])


def test_residual_is_small_and_shrinks_with_harmonics(three_links: Structure) -> None:
    """At 300 rad/s (a joint contacting, tests/test_harmonic_structure.py) the HB orbit
    is the exact one up to its truncation: one period of the exact event-driven motion
    returns to within a few 1e-3 of its state, and closer at H = 15 than at H = 7."""
    residuals = []
    for h in (7, 15):
        fr = frequency_response(
            three_links, FORCE, 300.0, 300.3, harmonics=h, max_points=2, check_points=2
        )
        found = fr.settings["orbit_check"]
        assert found.index.tolist() == [0, 1]
        assert found.trusted.all()
        assert found.exact_events[0] > 0
        assert found.orbit_crossings[0] > 0
        assert not [e for e in fr.events if e.kind == "untrusted"]
        residuals.append(float(found.residual[0]))
    assert residuals[0] < 1e-2
    assert residuals[1] < 0.5 * residuals[0]


@pytest.fixture(scope="module")
def curve(three_links: Structure) -> FrequencyResponse:
    return frequency_response(
        three_links, FORCE, 300.0, 300.3, harmonics=3, max_points=2, check_points=0
    )


def test_a_wrong_orbit_is_flagged(curve: FrequencyResponse) -> None:
    """An orbit scaled by 1.1 is not periodic under the exact motion: flagged untrusted."""
    fr = curve
    assert "orbit_check" not in fr.settings
    assert fr.coefficients is not None
    wrong = dataclasses.replace(
        fr, coefficients=1.1 * fr.coefficients, initial_state=1.1 * fr.initial_state
    )
    found = check_orbits(wrong, [0])
    assert found.residual[0] > RESIDUAL_TOLERANCE
    assert not found.trusted[0]
    (event,) = untrusted_events(wrong, found)
    assert event.kind == "untrusted"
    assert "raise harmonics=" in event.note
    assert "1 not trusted" in repr(found)
    assert found.to_xarray()["residual"].attrs["units"] == "1"
    assert found.plot() is not None


def test_bad_input(three_links: Structure, curve: FrequencyResponse) -> None:
    fr = curve
    with pytest.raises(ParameterError, match="indices 0 to 1"):
        check_orbits(fr, [2])
    with pytest.raises(ParameterError, match="tolerance"):
        check_orbits(fr, tolerance=0.0)
    with pytest.raises(ParameterError, match="check_points"):
        frequency_response(three_links, FORCE, 300.0, 300.3, max_points=2, check_points=-1)
    joint = Joint(mass=1.0, clearance=0.35, compression_stiffness=3.0, gap_stiffness=1.0)
    with pytest.raises(ParameterError, match="shooting"):
        check_orbits(dataclasses.replace(fr, settings={**fr.settings, "system": joint}))


def test_the_checks_motion_does_not_report_into_the_curves_progress(
    three_links: Structure,
) -> None:
    # the exact motion reports seconds of motion; the curve reports its parameter range
    # (0.3 rad/s here): a listener of the curve must hear only the latter
    from clearjoint.progress import listening

    heard: list[float] = []
    with listening(lambda done, total: heard.append(total)):
        frequency_response(
            three_links, FORCE, 300.0, 300.3, harmonics=3, max_points=2, check_points=2
        )
    assert heard
    assert heard == pytest.approx([0.3] * len(heard))
