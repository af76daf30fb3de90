"""clearjoint.identify.weak: the friction term's weights from a replicate's own velocity."""

from __future__ import annotations

import numpy as np

from clearjoint.identify.weak import stage_runs, weak_fit, weak_system


def test_friction_weights_follow_each_rows_own_velocity_sign() -> None:
    """int(phi sgn v) by a loop over the equations, for a velocity and its sign-flipped
    copy; the system's own weights are those of the velocity it was built with."""
    m, step = 300, 1.0 / 12_000
    t = np.arange(m) / m
    x = -np.cos(2 * np.pi * t)
    v = np.sin(2 * np.pi * t)
    system = weak_system(x, v, step, stage_runs(x, (-0.5, 0.5), 0.05))
    assert system is not None
    shifted = np.sin(2 * np.pi * (t - 0.02))  # reversals 6 samples later
    got = system.friction_of(np.vstack((v, shifted)))
    for row, vel in enumerate((v, shifted)):
        by_hand = [
            sum(np.sign(vel[c]) * w for c, w in zip(cols, phi, strict=True))
            for cols, phi in zip(system.columns, system.phi, strict=True)
        ]
        np.testing.assert_allclose(got[row], by_hand, atol=1e-15)
    np.testing.assert_allclose(got[0], system.friction, atol=1e-15)
    assert not np.allclose(got[1], got[0])  # the shift moves some equations' weights


def test_a_replicates_own_sign_changes_only_its_friction() -> None:
    """An exact loop, piecewise-linear restoring force (slopes 10, 1, 10) plus Coulomb
    friction 2 sgn(v): the replicate given the true sign recovers 2; the same data with the
    sign of a velocity whose reversals lag by 9 samples does not."""
    m, step = 300, 1.0 / 12_000
    t = np.arange(m) / m
    x = -np.cos(2 * np.pi * t)
    v = np.sin(2 * np.pi * t)
    k = np.where(np.abs(x) > 0.5, 10.0, 1.0)
    force = k * x - np.where(x > 0.5, 4.5, 0.0) + np.where(x < -0.5, 4.5, 0.0) + 2.0 * np.sign(v)
    system = weak_system(x, v, step, stage_runs(x, (-0.5, 0.5), 0.05))
    assert system is not None
    late = np.sin(2 * np.pi * (t - 0.03))
    fit = weak_fit(
        system,
        np.vstack((x, x)),
        np.vstack((force, force)),
        mass=0.0,
        velocity=np.vstack((v, late)),
    )
    np.testing.assert_allclose(fit.friction[0], 2.0, rtol=1e-6)
    assert abs(fit.friction[1] - 2.0) > 1e-3
