"""periodic: where a k0 = 0 joint's curve meets the continuum of orbits inside the gap.

Independent routes: the free mass's closed forms (m v' + c v = F0 sin(w t): the
amplitude F0 / (w sqrt(m^2 w^2 + c^2)), the velocity multiplier exp(-c T / m), the
double-grazing frequency where that orbit spans the whole gap), and time_response,
which closes the orbit from any mean position (the position is not set).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from clearjoint import Joint, Losses
from clearjoint.periodic import FrequencyResponse, frequency_response
from clearjoint.simulate import SimulationError, steady_state, time_response
from helpers import with_losses

#: k0 = 0, symmetric contact 100 N/m, edges at +-0.1; forced past the contact resonance.
FREE = Joint(mass=1.0, clearance=0.2, compression_stiffness=100.0, tension_stiffness=100.0)
ZETA = 0.1  # c_v = 2 zeta sqrt(m k_c) = 2
C_V = 2.0


@pytest.fixture(scope="module")
def curve() -> FrequencyResponse:
    return frequency_response(
        FREE, 1.0, 2.0, 12.0, losses=Losses(damping_ratio=ZETA, restitution=0.8)
    )


def _free_mass_amplitude(w: np.ndarray | float) -> np.ndarray | float:
    return 1.0 / (w * np.sqrt(w**2 + C_V**2))


def test_curve_goes_on_along_the_centred_free_play_orbits(curve: FrequencyResponse) -> None:
    assert curve.stop_reason == "reached"
    assert curve.omega[-1] == pytest.approx(12.0)
    fp = curve.free_play
    assert fp is not None
    assert fp.sum() > 50
    # one run at the end of the curve, after the contact branch
    first = int(np.argmax(fp))
    assert fp[first:].all()
    assert not fp[:first].any()
    w = curve.omega[fp]
    assert np.max(np.abs(curve.amplitude[fp] / _free_mass_amplitude(w) - 1.0)) < 1e-9
    # centred in the gap, never touching an edge
    assert np.max(np.abs(curve.x_max[fp] + curve.x_min[fp])) < 1e-9 * 0.1
    assert np.all(curve.x_max[fp] < 0.1)
    # multipliers: exactly 1 (the position) and exp(-c T / m) (the velocity)
    mu = np.sort(np.abs(curve.multipliers[fp]), axis=1)
    assert np.max(np.abs(mu[:, 1] - 1.0)) < 1e-9
    assert np.max(np.abs(mu[:, 0] - np.exp(-C_V * 2.0 * math.pi / w))) < 1e-9
    assert not curve.stable[fp].any()  # a continuum: not asymptotically stable
    events = [e for e in curve.events if e.kind == "free_play"]
    assert len(events) == 1
    assert events[0].omega == pytest.approx(w[0])
    assert "position not set" in events[0].note


def test_contact_branch_ends_at_the_double_grazing_of_the_widest_free_play_orbit(
    curve: FrequencyResponse,
) -> None:
    # the free-mass orbit spans the whole gap (2 X = clearance) at w_g, in closed form
    w_g = brentq(lambda w: 2.0 * _free_mass_amplitude(w) - 0.2, 1.0, 10.0)
    fp = curve.free_play
    assert fp is not None
    last = int(np.argmax(fp)) - 1  # the last orbit with contact
    assert curve.omega[last] == pytest.approx(w_g, rel=1e-3)
    assert curve.x_max[last] == pytest.approx(0.1, rel=1e-3)
    assert curve.x_min[last] == pytest.approx(-0.1, rel=1e-3)
    assert w_g < curve.omega[last + 1] < w_g * (1.0 + 1e-3)  # the widest in-gap orbit


def test_free_play_orbit_closes_from_any_mean_position(curve: FrequencyResponse) -> None:
    # time marching (no Newton), from the curve's start and from it shifted in the gap
    fp = np.nonzero(curve.free_play)[0]
    i = int(fp[fp.size // 2])
    w = float(curve.omega[i])
    room = 0.1 - float(curve.x_max[i])
    for shift in (0.0, 0.5 * room, -0.9 * room):
        start = curve.initial_state[i] + np.array([shift, 0.0])
        motion = time_response(
            FREE,
            1.0,
            w,
            3 * 2.0 * math.pi / w,
            initial=start,
            losses=Losses(damping_ratio=ZETA, restitution=0.8),
        )
        end = np.array(motion.final_state)
        assert np.max(np.abs(end - start) / np.array([0.1, 0.1 * w])) < 1e-9
        assert motion.x_max == pytest.approx(curve.x_max[i] + shift, abs=1e-9)


def test_result_carries_the_free_play_flag(curve: FrequencyResponse) -> None:
    ds = curve.to_xarray()
    assert "free_play" in ds
    assert ds["free_play"].values.sum() == np.sum(curve.free_play)
    assert "free play" in repr(curve)


@pytest.fixture(scope="module")
def study_curve() -> tuple[FrequencyResponse, Joint, dict[str, object], float]:
    from clearjoint.simulate.study import load_study

    study = load_study(Path(__file__).parents[1] / "examples" / "study.toml")
    kw: dict[str, object] = {
        "damping_ratio": study.damping_ratio,
        "friction": study.friction,
        "restitution": study.restitution,
    }
    hz = 2.0 * math.pi
    curve = frequency_response(
        study.joint, study.force_amplitude, 20 * hz, 900 * hz, **with_losses(kw)
    )  # type: ignore[arg-type]
    return curve, study.joint, kw, study.force_amplitude


def test_study_curve_is_whole_from_20_to_900_hz_with_the_default_options(
    study_curve: tuple[FrequencyResponse, Joint, dict[str, object], float],
) -> None:
    # the README study (clearjoint frf examples/study.toml --from 20Hz --to 900Hz)
    curve, joint, kw, force = study_curve
    hz = 2.0 * math.pi
    assert curve.stop_reason == "reached"
    assert curve.omega.size <= 2000
    assert curve.omega[0] == pytest.approx(20 * hz)
    assert curve.omega[-1] == pytest.approx(900 * hz)
    folds = [e.omega / hz for e in curve.events if e.kind == "fold"]
    assert any(f == pytest.approx(704.78, abs=0.01) for f in folds)
    assert curve.free_play is not None
    first = int(np.argmax(curve.free_play))
    assert curve.free_play[first:].all()
    # the contact branch ends where its orbit touches both edges (the widest in-gap orbit)
    assert 487.0 < curve.omega[first - 1] / hz < 488.0
    assert curve.x_max[first - 1] == pytest.approx(joint.compression_gap, rel=1e-3)
    assert curve.x_min[first - 1] == pytest.approx(-joint.tension_gap, rel=1e-3)
    # stable orbits of the resonance's upper branch, by time marching (no Newton)
    upper = np.nonzero(curve.stable & (curve.omega > 400 * hz) & ~curve.free_play)[0]
    assert upper.size > 10
    for i in upper[:: max(1, upper.size // 3)]:
        start = curve.initial_state[i] * (1.0 + 1e-6)
        ss = steady_state(joint, force, float(curve.omega[i]), initial=start, **with_losses(kw))  # type: ignore[arg-type]
        assert ss.period_multiple == 1
        assert abs(ss.x_max - curve.x_max[i]) / curve.amplitude[i] < 1e-9


@pytest.mark.parametrize("hz", [720.0, 900.0])
def test_above_the_resonance_every_start_settles_inside_the_gap(
    study_curve: tuple[FrequencyResponse, Joint, dict[str, object], float], hz: float
) -> None:
    # long transients from starts across the gap and beyond it: each ends on an orbit inside
    # the gap of the curve's amplitude, at a mean position of its own (a continuum)
    curve, joint, kw, force = study_curve
    assert curve.free_play is not None
    i = int(np.argmin(np.where(curve.free_play, abs(curve.omega - 2 * math.pi * hz), np.inf)))
    w = float(curve.omega[i])
    means = []
    for start in ((0.0, 0.0), (4e-5, 0.0), (-6e-5, -0.5), (1e-4, 0.5)):
        motion = time_response(
            joint, force, w, 150 * 2 * math.pi / w, initial=start, **with_losses(kw)
        )  # type: ignore[arg-type]
        last = time_response(
            joint,
            force,
            w,
            2 * math.pi / w,
            initial=motion.final_state,
            **with_losses(kw),  # type: ignore[arg-type]
        )
        assert last.x_max < joint.compression_gap
        assert last.x_min > -joint.tension_gap
        assert last.amplitude == pytest.approx(curve.amplitude[i], rel=1e-9)
        means.append(0.5 * (last.x_max + last.x_min))
    assert np.ptp(means) > 1e-6  # not one orbit: the position is not set


def test_a_curve_started_on_a_free_play_orbit_is_followed_from_the_other_end(
    curve: FrequencyResponse,
) -> None:
    down = frequency_response(
        FREE, 1.0, 12.0, 2.0, losses=Losses(damping_ratio=ZETA, restitution=0.8)
    )
    assert down.stop_reason == "reached"
    assert down.omega[0] == pytest.approx(12.0)
    assert down.omega[-1] == pytest.approx(2.0)
    assert down.free_play is not None
    assert down.free_play[0]
    assert not down.free_play[-1]
    w = down.omega[down.free_play]
    assert np.max(np.abs(down.amplitude[down.free_play] / _free_mass_amplitude(w) - 1.0)) < 1e-9
    assert np.array_equal(down.omega, curve.omega[::-1])
    # both ends on free-play orbits: no single curve, said so
    with pytest.raises(SimulationError, match="multiplier of exactly 1"):
        frequency_response(
            FREE, 1.0, 10.0, 12.0, losses=Losses(damping_ratio=ZETA, restitution=0.8)
        )


#: the fixed frequency of the force curves (rad/s), below the contact resonance sqrt(100/1)
W_F = 4.0


@pytest.fixture(scope="module")
def force_curve() -> FrequencyResponse:
    return frequency_response(
        FREE,
        0.5,
        W_F,
        None,
        parameter="force",
        force_stop=5.0,
        losses=Losses(damping_ratio=ZETA, restitution=0.8),
    )


def test_force_curve_starts_on_free_play_orbits_linear_in_the_force(
    force_curve: FrequencyResponse,
) -> None:
    # at 0.5 N the free mass's orbit (X = 0.0559) stays in the gap: a continuum; the curve
    # follows its centred member, X = F0 / (w sqrt(m^2 w^2 + c^2)), linear in F0
    curve = force_curve
    assert curve.stop_reason == "reached"
    assert curve.force_amplitude[0] == pytest.approx(0.5, rel=1e-12)
    assert curve.force_amplitude[-1] == pytest.approx(5.0, rel=1e-12)
    assert np.all(curve.omega == W_F)
    fp = curve.free_play
    assert fp is not None
    end = int(np.argmin(fp))  # one run at the start, then the contact branch to the end
    assert end > 20
    assert fp[:end].all()
    assert not fp[end:].any()
    f = curve.force_amplitude[fp]
    assert np.all(np.diff(f) > 0.0)
    expected = f * _free_mass_amplitude(W_F)
    assert np.max(np.abs(curve.amplitude[fp] / expected - 1.0)) < 1e-9
    assert np.max(np.abs(curve.x_max[fp] + curve.x_min[fp])) < 1e-9 * 0.1
    mu = np.sort(np.abs(curve.multipliers[fp]), axis=1)
    assert np.max(np.abs(mu[:, 1] - 1.0)) < 1e-9
    assert np.max(np.abs(mu[:, 0] - math.exp(-C_V * 2.0 * math.pi / W_F))) < 1e-9
    assert not curve.stable[fp].any()
    events = [e for e in curve.events if e.kind == "free_play"]
    assert len(events) == 1
    assert events[0].force_amplitude == pytest.approx(f[-1])


def test_force_curve_joins_the_contact_branch_where_2x_equals_the_clearance(
    force_curve: FrequencyResponse,
) -> None:
    curve = force_curve
    # closed form: the free-mass orbit spans the gap, 2 F0 / (w sqrt(w^2 + c^2)) = 0.2
    f_g = 0.1 * W_F * math.sqrt(W_F**2 + C_V**2)
    fp = curve.free_play
    assert fp is not None
    first = int(np.argmin(fp))  # the first orbit with contact
    assert curve.force_amplitude[first] == pytest.approx(f_g, rel=1e-3)
    assert curve.x_max[first] == pytest.approx(0.1, rel=1e-3)
    assert curve.x_min[first] == pytest.approx(-0.1, rel=1e-3)
    assert f_g * (1.0 - 1e-3) < curve.force_amplitude[first - 1] < f_g  # the widest in-gap orbit


def test_force_curve_contact_orbits_by_time_marching(force_curve: FrequencyResponse) -> None:
    # contact points, stable and unstable: one forcing period of time_response from the
    # curve's initial state closes the orbit (no Newton); stable ones are steady_state's
    curve = force_curve
    assert curve.free_play is not None
    contact = np.nonzero(~curve.free_play)[0]
    stable = contact[curve.stable[contact]]
    unstable = contact[~curve.stable[contact]]
    assert stable.size > 10
    assert unstable.size > 10
    kw = {"damping_ratio": ZETA, "restitution": 0.8}
    for i in (*stable[:: stable.size // 3], *unstable[:: unstable.size // 3]):
        f, z = float(curve.force_amplitude[i]), curve.initial_state[i]
        size = np.array([curve.amplitude[i], curve.amplitude[i] * W_F])
        one = time_response(FREE, f, W_F, 2.0 * math.pi / W_F, initial=z, **with_losses(kw))  # type: ignore[arg-type]
        assert np.max(np.abs(np.array(one.final_state) - z) / size) < 1e-8
        assert one.x_max == pytest.approx(curve.x_max[i], abs=1e-8 * size[0])
        assert one.x_max > 0.1 or one.x_min < -0.1  # it does reach an edge
        if curve.stable[i]:
            ss = steady_state(FREE, f, W_F, initial=z * (1.0 + 1e-6), **with_losses(kw))  # type: ignore[arg-type]
            assert ss.period_multiple == 1
            assert abs(ss.x_max - curve.x_max[i]) / curve.amplitude[i] < 1e-9


def test_force_curve_followed_down_ends_on_the_free_play_orbits(
    force_curve: FrequencyResponse,
) -> None:
    down = frequency_response(
        FREE,
        5.0,
        W_F,
        None,
        parameter="force",
        force_stop=0.5,
        losses=Losses(damping_ratio=ZETA, restitution=0.8),
    )
    assert down.stop_reason == "reached"
    assert down.free_play is not None
    assert down.free_play[-1]
    assert not down.free_play[0]
    assert down.force_amplitude[-1] == pytest.approx(0.5, rel=1e-12)
    f = down.force_amplitude[down.free_play]
    expected = f * _free_mass_amplitude(W_F)
    assert np.max(np.abs(down.amplitude[down.free_play] / expected - 1.0)) < 1e-9
    # the curve started on the free-play orbits is this one turned round
    assert np.array_equal(down.force_amplitude, force_curve.force_amplitude[::-1])
    # both ends only inside the gap (below the fold at 1.24 N): no single curve, said so
    with pytest.raises(SimulationError, match="multiplier of exactly 1"):
        frequency_response(
            FREE,
            0.5,
            W_F,
            None,
            parameter="force",
            force_stop=1.0,
            losses=Losses(damping_ratio=ZETA, restitution=0.8),
        )


def test_study_force_curve_from_inside_the_gap_by_time_marching() -> None:
    # the example (examples/study.toml at 400 Hz, 100 N to 2 kN: friction 60 N, so
    # no closed form): the free-play points close under time_response from their centred
    # start and from it shifted in the gap (the position is not set), and the contact
    # branch starts where the orbit touches both edges
    from clearjoint.simulate.study import load_study

    study = load_study(Path(__file__).parents[1] / "examples" / "study.toml")
    kw: dict[str, object] = {
        "damping_ratio": study.damping_ratio,
        "friction": study.friction,
        "restitution": study.restitution,
    }
    w = 2.0 * math.pi * 400.0
    curve = frequency_response(
        study.joint,
        100.0,
        w,
        None,
        parameter="force",
        force_stop=2000.0,
        **with_losses(kw),  # type: ignore[arg-type]
    )
    assert curve.stop_reason == "reached"
    assert curve.free_play is not None
    first = int(np.argmin(curve.free_play))
    assert curve.free_play[:first].all()
    assert not curve.free_play[first:].any()
    gap = study.joint.compression_gap
    assert curve.x_max[first] == pytest.approx(gap, rel=1e-3)
    assert curve.x_min[first] == pytest.approx(-study.joint.tension_gap, rel=1e-3)
    for i in (0, first // 2, first - 1):
        f = float(curve.force_amplitude[i])
        room = gap - float(curve.x_max[i])
        for shift in (0.0, 0.8 * room):
            start = curve.initial_state[i] + np.array([shift, 0.0])
            one = time_response(
                study.joint, f, w, 2.0 * math.pi / w, initial=start, **with_losses(kw)
            )  # type: ignore[arg-type]
            size = np.array([curve.amplitude[i], curve.amplitude[i] * w])
            assert np.max(np.abs(np.array(one.final_state) - start) / size) < 1e-8
            assert one.amplitude == pytest.approx(curve.amplitude[i], rel=1e-8)
    # between the fold (220 N) and the junction (680 N) both kinds coexist, by time marching:
    # near 400 N a free-play start kicked by 1 % in velocity stays in the gap with the
    # curve's amplitude; from rest the joint settles on the stable contact orbit, which
    # steady_state confirms
    free = np.nonzero(curve.free_play)[0]
    contact = np.nonzero(curve.stable)[0]
    j = int(free[np.argmin(abs(curve.force_amplitude[free] - 400.0))])
    k = int(contact[np.argmin(abs(curve.force_amplitude[contact] - 400.0))])
    period = 2.0 * math.pi / w
    for i, start, inside in ((j, curve.initial_state[j] * np.array([1.0, 1.01]), True),
                             (k, np.zeros(2), False)):  # fmt: skip
        f = float(curve.force_amplitude[i])
        motion = time_response(study.joint, f, w, 100 * period, initial=start, **with_losses(kw))  # type: ignore[arg-type]
        last = time_response(
            study.joint, f, w, period, initial=motion.final_state, **with_losses(kw)
        )  # type: ignore[arg-type]
        assert (last.x_max < gap) == inside
        if inside:
            assert last.amplitude == pytest.approx(curve.amplitude[i], rel=1e-8)
    ss = steady_state(
        study.joint, f, w, initial=curve.initial_state[k] * (1.0 + 1e-6), **with_losses(kw)
    )  # type: ignore[arg-type]
    assert ss.period_multiple == 1
    assert abs(ss.x_max - curve.x_max[k]) / curve.amplitude[k] < 1e-9
    assert last.amplitude == pytest.approx(curve.amplitude[k], rel=1e-6)


def test_force_curve_from_the_coexistence_region_goes_round_the_fold_to_the_free_play() -> None:
    # at 1.5 N (between the fold, 1.24 N, and the junction, 1.79 N) the transient finds the
    # stable contact orbit; followed down, the curve goes round the fold, up the unstable
    # branch past the start to the junction (2 X = clearance), then down the free play
    curve = frequency_response(
        FREE,
        1.5,
        W_F,
        None,
        parameter="force",
        force_stop=0.5,
        losses=Losses(damping_ratio=ZETA, restitution=0.8),
    )
    assert curve.stop_reason == "reached"
    assert curve.free_play is not None
    assert not curve.free_play[0]
    assert curve.free_play[-1]
    assert curve.force_amplitude[-1] == pytest.approx(0.5, rel=1e-12)
    f_g = 0.1 * W_F * math.sqrt(W_F**2 + C_V**2)
    assert np.max(curve.force_amplitude) == pytest.approx(f_g, rel=1e-3)
    assert [e.kind for e in curve.events].count("fold") >= 1
    fp = curve.free_play
    expected = curve.force_amplitude[fp] * _free_mass_amplitude(W_F)
    assert np.max(np.abs(curve.amplitude[fp] / expected - 1.0)) < 1e-9


def test_without_impact_loss_the_curve_goes_on_along_the_free_play_too() -> None:
    # restitution 1: past the junction the orbits that reach past an edge by a hair
    # (members of the continuum pushed against it) used to be followed, 1e-5 N a step,
    # to max_points; they count as not touching, and the curve goes on as with e < 1
    f_g = 0.1 * W_F * math.sqrt(W_F**2 + C_V**2)
    w_g = brentq(lambda w: 2.0 * _free_mass_amplitude(w) - 0.2, 1.0, 10.0)
    by_force = frequency_response(
        FREE, 5.0, W_F, None, parameter="force", force_stop=0.5, losses=Losses(damping_ratio=ZETA)
    )
    by_omega = frequency_response(FREE, 1.0, 2.0, 12.0, losses=Losses(damping_ratio=ZETA))
    for curve, junction in ((by_force, f_g), (by_omega, w_g)):
        assert curve.stop_reason == "reached"
        fp = curve.free_play
        assert fp is not None
        first = int(np.argmax(fp))
        assert first > 10
        assert fp[first:].all()
        lam = curve.force_amplitude if curve.parameter == "force" else curve.omega
        assert lam[first - 1] == pytest.approx(junction, rel=1e-3)
        expected = curve.force_amplitude[fp] * _free_mass_amplitude(curve.omega[fp])
        assert np.max(np.abs(curve.amplitude[fp] / expected - 1.0)) < 1e-9
        # the last contact orbit closes under one period of time marching
        i = first - 1
        f, w, z = float(curve.force_amplitude[i]), float(curve.omega[i]), curve.initial_state[i]
        one = time_response(
            FREE, f, w, 2.0 * math.pi / w, initial=z, losses=Losses(damping_ratio=ZETA)
        )
        size = np.array([curve.amplitude[i], curve.amplitude[i] * w])
        assert np.max(np.abs(np.array(one.final_state) - z) / size) < 1e-8
