"""Test configuration: hypothesis runs the same examples on every machine.

Derandomised so that CI and a developer see the same cases; set
HYPOTHESIS_PROFILE=explore to draw new ones (and then add what they find as
explicit regression tests, as tests/test_simulate.py does).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

from clearjoint import ClearanceJoint
from clearjoint.structure import Structure, chain

settings.register_profile("repeatable", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, max_examples=200)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


#: A small campaign for the study tests: 3 structures x 3 frequencies x 3 forces.
SMALL_CAMPAIGN = """
seed = 5
periods = 12
[grid]
frequencies = ["20Hz", "60Hz", "100Hz"]
force_amplitudes = ["1000N", "2000N", "3000N"]
"""


@pytest.fixture(scope="session")
def reproduction(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A `clearjoint reproduce` of SMALL_CAMPAIGN (with its control run), shared by the tests."""
    from clearjoint.cli import main

    folder = tmp_path_factory.mktemp("reproduce")
    campaign = folder / "campaign.toml"
    campaign.write_text(SMALL_CAMPAIGN)
    out = folder / "out"
    assert main(["reproduce", "--out", str(out), "--campaign", str(campaign), "--jobs", "2"]) == 0
    return out


@pytest.fixture(scope="module")
def three_links() -> Structure:
    """Three 1 kg masses on 1 MN/m links, each with a 0.1 mm joint (1e7 N/m in contact, 1e5
    in the gap), dashpots across: the harmonic tests' 3-link chain."""
    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    return chain([1.0, 1.0, 1.0], [1e6] * 3, [j] * 3, dampers=[150.0] * 3)
