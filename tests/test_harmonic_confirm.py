"""Harmonic balance's "stable" on a structure counts only where the exact motion confirms it.

Issue 24, item 4: a two-mass chain with clearance joints at 5 N near 14.8 Hz, where
harmonic balance (H = 7) calls points stable whose exact motion is something else. The
refutation is checked by a route that does not use the monodromy: the exact motion started
on the harmonic-balance orbit leaves it.
"""

from __future__ import annotations

import math

import numpy as np

import clearjoint as cj
from clearjoint import harmonic
from clearjoint.structure import chain, time_response
from clearjoint.studies.text import curve_warnings


def _chain():
    law = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4)
    return chain([0.5, 0.5], [math.inf] * 2, [law] * 2, [2.0] * 2)


def test_stable_points_the_exact_motion_refutes_are_not_stable():
    s = _chain()
    force = np.array([0.0, 5.0])
    curve = harmonic.frequency_response(
        s, force, 2 * math.pi * 14.0, 2 * math.pi * 16.0, harmonics=7, max_points=300
    )
    said = curve.settings["harmonic_stable"]
    found = curve.settings["stability_check"]
    assert said.sum() >= 3  # harmonic balance calls these stable
    assert found.index.size == said.sum()
    assert not found.confirmed.any()
    assert not curve.stable.any()  # so the curve does not
    notes = [e.note for e in curve.events if "not stable here" in e.note]
    assert notes
    warnings = curve_warnings(curve)
    assert any("does not confirm" in w for w in warnings)
    # independently of any monodromy: the exact motion started on one of those orbits
    # does not stay on it
    i = int(found.index[0])
    w = float(curve.omega[i])
    z = curve.initial_state[i]
    motion = time_response(
        s, force, w, 60 * 2 * math.pi / w, initial=(z[:2], z[2:]), samples_per_period=8
    )
    phase0 = np.concatenate((motion.u[::8], motion.v[::8]), axis=1)
    scale = np.array([w, w, 1.0, 1.0])
    away = np.max(np.linalg.norm((phase0 - z) * scale, axis=1))
    assert away > 0.2 * np.linalg.norm(z * scale)


def test_confirmed_where_the_exact_orbit_is_stable():
    s = _chain()
    force = np.array([0.0, 0.01])  # small: the joints stay in their gaps, a linear chain
    curve = harmonic.frequency_response(
        s, force, 2 * math.pi * 5.0, 2 * math.pi * 6.0, harmonics=3, max_points=30
    )
    found = curve.settings["stability_check"]
    assert found.confirmed.all()
    assert found.index.size == curve.omega.size
    assert curve.stable.all()
