"""Test configuration: hypothesis runs the same examples on every machine.

Derandomised so that CI and a developer see the same cases; set
HYPOTHESIS_PROFILE=explore to draw new ones (and then add what they find as
explicit regression tests, as tests/test_simulate.py does).
"""

from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("repeatable", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, max_examples=200)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))
