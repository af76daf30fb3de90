"""periodic: exact orbits, their stability and whole frequency-response curves.

Independent routes: steady_state (time marching from a perturbed start, no
Newton), time_response from perturbed orbits, the energy ledger, the linear
closed form inside the gap, frequency_sweep for the period-2 region, and eq 7.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from clearjoint import Friction, Joint, Losses, ParameterError
from clearjoint.periodic import FrequencyResponse, frequency_response, periodic_orbit
from clearjoint.simulate import SimulationError, frequency_sweep, steady_state, time_response
from clearjoint.stiffness import equivalent_linear_response
from helpers import with_losses

#: pyHarm's SDOF clearance case: m = 1, c_v = 0.05, k0 = 1, edges at +-0.1745, contact adds 3.
PYHARM = Joint(
    mass=1.0,
    clearance=2 * 0.1745,
    gap_stiffness=1.0,
    compression_stiffness=3.0,
    tension_stiffness=3.0,
)
ZETA = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 2 zeta sqrt(m k_c) = 0.05
F0 = 0.03

#: One-sided soft contact with period doubling between about 2.29 and 3.28 rad/s.
ONE_SIDED = Joint(
    mass=1.0,
    clearance=0.2,
    gap_stiffness=1.0,
    compression_stiffness=20.0,
    tension_stiffness=1e-3,
)


@pytest.fixture(scope="module")
def curve() -> FrequencyResponse:
    return frequency_response(PYHARM, F0, 0.05, 1.8, losses=Losses(damping_ratio=ZETA))


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(b)))


@pytest.mark.parametrize(
    ("omega", "losses"),
    [
        (1.3, {"damping_ratio": ZETA}),
        (1.2, {"damping_ratio": ZETA, "restitution": 0.7}),
        (1.0, {"damping_ratio": ZETA, "friction": Friction(0.3, 0.01)}),
    ],
)
def test_stable_orbit_agrees_with_steady_state(omega: float, losses: dict[str, object]) -> None:
    orbit = periodic_orbit(PYHARM, F0, omega, **with_losses(losses))  # type: ignore[arg-type]
    assert orbit.stable
    ss = steady_state(PYHARM, F0, omega, initial=orbit.initial_state, **with_losses(losses))  # type: ignore[arg-type]
    assert ss.period_multiple == 1
    scale = np.array([orbit.amplitude, orbit.amplitude * omega])
    assert np.max(np.abs(np.subtract(ss.initial_state[:2], orbit.initial_state)) / scale) < 1e-9
    assert orbit.x_max == pytest.approx(ss.x_max, rel=1e-9)
    assert orbit.x_min == pytest.approx(ss.x_min, rel=1e-9)
    assert orbit.cycle.energy.balance_error < 1e-9
    assert "PeriodicOrbit(period-1" in repr(orbit)
    assert "[" not in repr(orbit)


def test_period_2_orbit_is_found_and_matches_steady_state() -> None:
    omega = 2.786
    ss = steady_state(ONE_SIDED, 1.0, omega, losses=Losses(damping_ratio=0.05))
    assert ss.period_multiple == 2
    orbit = periodic_orbit(
        ONE_SIDED, 1.0, omega, losses=Losses(damping_ratio=0.05), period_multiple=2
    )
    assert orbit.stable
    assert orbit.cycle.period_multiple == 2
    # the same orbit, possibly started one forcing period later
    starts = [np.array(ss.initial_state[:2])]
    back = time_response(
        ONE_SIDED,
        1.0,
        omega,
        2 * math.pi / omega,
        initial=ss.initial_state[:2],
        losses=Losses(damping_ratio=0.05),
    )
    starts.append(np.array(back.final_state))
    scale = np.array([orbit.amplitude, orbit.amplitude * omega])
    assert min(np.max(np.abs(s - orbit.initial_state) / scale) for s in starts) < 1e-8


def _distance_after(orbit_state: tuple[float, float], omega: float, periods: int) -> float:
    """Relative distance from the orbit's start after ``periods`` periods from a 1e-6 offset."""
    start = np.array(orbit_state) + np.array([1e-6, 0.0])
    motion = time_response(
        PYHARM,
        F0,
        omega,
        periods * 2 * math.pi / omega,
        initial=start,
        losses=Losses(damping_ratio=ZETA),
    )
    return float(abs(motion.final_state[0] - orbit_state[0]))


def test_unstable_orbit_leaves_and_stable_orbit_returns(curve: FrequencyResponse) -> None:
    omega = 1.4
    middle = [
        i
        for i in range(curve.omega.size - 1)
        if (curve.omega[i] - omega) * (curve.omega[i + 1] - omega) <= 0
    ]
    unstable = [i for i in middle if not curve.stable[i]]
    stable = [i for i in middle if curve.stable[i]]
    assert len(unstable) == 1
    assert len(stable) == 2
    orbit_u = periodic_orbit(
        PYHARM,
        F0,
        omega,
        losses=Losses(damping_ratio=ZETA),
        initial=curve.initial_state[unstable[0]],
    )
    assert not orbit_u.stable
    assert np.max(np.abs(orbit_u.multipliers)) > 1.0
    assert _distance_after(orbit_u.initial_state, omega, 60) > 1e-3  # left: 1000x the offset
    for i in stable:
        orbit_s = periodic_orbit(
            PYHARM, F0, omega, losses=Losses(damping_ratio=ZETA), initial=curve.initial_state[i]
        )
        assert orbit_s.stable
        assert _distance_after(orbit_s.initial_state, omega, 60) < 1e-7  # came back


def test_curve_turns_back_at_two_folds_through_an_unstable_branch(
    curve: FrequencyResponse,
) -> None:
    assert curve.stop_reason == "reached"
    assert curve.omega.size >= 300
    folds = [e for e in curve.events if e.kind == "fold"]
    assert len(folds) == 2
    # omega turns back at each fold: larger (upper fold) or smaller (lower) than its neighbours
    upper, lower = sorted(folds, key=lambda e: -e.amplitude)
    assert upper.omega > lower.omega
    assert upper.omega == pytest.approx(curve.omega[curve.amplitude > 0.3].max(), rel=1e-4)
    # the lower fold is the kink where the middle branch meets the linear orbit that just
    # touches the edges: F0 / |1 - w^2 + 0.05 i w| = 0.1745 (closed form)
    w2 = 1.0 + math.sqrt((F0 / PYHARM.compression_gap) ** 2 - 0.05**2 * 1.0785**2)
    assert lower.omega == pytest.approx(math.sqrt(w2), rel=1e-3)
    # between the folds the orbits are unstable with a real multiplier > 1 (saddle)
    unstable = ~curve.stable
    assert unstable.sum() > 20
    assert np.all(np.abs(curve.multipliers[unstable, 0].imag) < 1e-9)
    assert np.all(curve.multipliers[unstable, 0].real > 1.0)
    # pyHarm (12 harmonics) puts the peak at 0.3973 near 1.5339 and the upper fold near 1.5348
    peak = int(np.argmax(curve.amplitude))
    assert curve.amplitude[peak] == pytest.approx(0.3973, abs=5e-4)
    assert upper.omega == pytest.approx(1.5348, abs=2e-3)


def test_grazing_kink_is_reported_and_crossed(curve: FrequencyResponse) -> None:
    grazings = [e for e in curve.events if e.kind == "grazing"]
    assert len(grazings) == 2  # the lower branch leaves the gap on the way up, re-enters after
    for event in grazings:
        assert event.amplitude == pytest.approx(PYHARM.compression_gap, rel=1e-3)
    # where the linear orbit reaches the edges: F0 / |1 - w^2 + 0.05 i w| = 0.1745
    touch = [
        float(w)
        for w in np.linspace(0.8, 1.2, 400001)
        if abs(F0 / math.hypot(1.0 - w * w, 0.05 * w) - PYHARM.compression_gap) < 2e-6
    ]
    assert grazings[0].omega == pytest.approx(min(touch), rel=2e-3)
    assert grazings[1].omega == pytest.approx(max(touch), rel=2e-3)
    # inside the gap the orbit is linear: X = F0 / |k0 - m w^2 + i c w| exactly
    inside = curve.amplitude < PYHARM.compression_gap * 0.999
    w = curve.omega[inside]
    linear = F0 / np.hypot(1.0 - w**2, 0.05 * w)
    assert _relative(curve.amplitude[inside], linear) < 1e-9
    # points on both sides of each grazing: the continuation went on
    assert curve.omega[-1] == pytest.approx(1.8)


def test_stable_points_agree_with_steady_state(curve: FrequencyResponse) -> None:
    stable = np.nonzero(curve.stable)[0]
    for i in stable[:: max(1, stable.size // 8)]:
        omega = float(curve.omega[i])
        start = curve.initial_state[i] * (1.0 + 1e-4)  # off the orbit: steady_state must converge
        ss = steady_state(PYHARM, F0, omega, losses=Losses(damping_ratio=ZETA), initial=start)
        scale = curve.amplitude[i]
        assert abs(ss.x_max - curve.x_max[i]) / scale < 1e-9
        assert abs(ss.x_min - curve.x_min[i]) / scale < 1e-9
        assert abs(ss.initial_state[0] - curve.initial_state[i, 0]) / scale < 1e-9


def test_energy_ledger_closes_on_every_point(curve: FrequencyResponse) -> None:
    worst = max(curve.cycle(i).energy.balance_error for i in range(curve.omega.size))
    assert worst < 1e-9
    # and the orbit closes: the mechanical energy change over the period vanishes
    assert abs(curve.cycle(int(np.argmax(curve.amplitude))).energy.mechanical_energy_change) < 1e-12


def test_period_doubling_where_a_sweep_finds_period_2_orbits() -> None:
    grid = np.array([2.0, 2.6, 3.0, 3.6])
    sweep = frequency_sweep(ONE_SIDED, 1.0, grid, direction="up", losses=Losses(damping_ratio=0.05))
    assert list(sweep.multiple_up) == [1, 2, 2, 1]
    fr = frequency_response(ONE_SIDED, 1.0, 1.8, 3.8, losses=Losses(damping_ratio=0.05))
    doublings = sorted(e.omega for e in fr.events if e.kind == "period_doubling")
    assert len(doublings) == 2
    assert 2.0 < doublings[0] < 2.6
    assert 3.0 < doublings[1] < 3.6
    between = (fr.omega > doublings[0] + 1e-3) & (fr.omega < doublings[1] - 1e-3)
    assert not fr.stable[between].any()
    assert np.all(fr.multipliers[between, 0].real < -1.0)  # through -1, not +1
    assert all("period-2" in e.note for e in fr.events if e.kind == "period_doubling")


def test_force_continuation_is_linear_inside_the_gap_and_meets_steady_state() -> None:
    omega = 0.6
    fr = frequency_response(
        PYHARM,
        0.01,
        omega,
        None,
        losses=Losses(damping_ratio=ZETA),
        parameter="force",
        force_stop=0.2,
    )
    assert fr.stop_reason == "reached"
    assert np.all(fr.omega == omega)
    assert fr.force_amplitude[-1] == pytest.approx(0.2)
    inside = fr.amplitude < PYHARM.compression_gap * 0.999
    gain = 1.0 / math.hypot(1.0 - omega**2, 0.05 * omega)
    assert _relative(fr.amplitude[inside], fr.force_amplitude[inside] * gain) < 1e-9
    assert any(e.kind == "grazing" for e in fr.events)
    ss = steady_state(PYHARM, 0.2, omega, losses=Losses(damping_ratio=ZETA))
    assert fr.amplitude[-1] == pytest.approx(ss.amplitude, rel=1e-9)


def test_eq7_shortcut_holds_off_the_peak_and_misses_the_fold(curve: FrequencyResponse) -> None:
    def exact_at(omega: float) -> list[float]:
        out = []
        for i in range(curve.omega.size - 1):
            a, b = curve.omega[i], curve.omega[i + 1]
            if (a - omega) * (b - omega) <= 0 and a != b:
                f = (omega - a) / (b - a)
                out.append(
                    float(curve.amplitude[i] + f * (curve.amplitude[i + 1] - curve.amplitude[i]))
                )
        return sorted(out)

    for omega in (1.1, 1.2, 1.3, 1.4, 1.5):
        eq7 = sorted(
            b.displacement_amplitude
            for b in equivalent_linear_response(PYHARM, F0, omega, ZETA, method="period")
        )
        exact = exact_at(omega)
        assert len(eq7) == len(exact) == 3
        assert np.allclose(eq7, exact, rtol=1e-2)
    # near the peak the shortcut's fold comes too early: no contacting orbit at 1.53 rad/s
    near_peak = equivalent_linear_response(PYHARM, F0, 1.53, ZETA, method="period")
    assert len(near_peak) == 1
    assert len(exact_at(1.53)) == 3


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"omega_start": 1.0, "omega_stop": 1.0}, "zero width"),
        ({"omega_start": -1.0, "omega_stop": 1.0}, "omega_start must be > 0"),
        ({"omega_start": 1.0, "omega_stop": 0.0}, "omega_stop must be > 0"),
        ({"omega_start": float("nan"), "omega_stop": 1.0}, "must be finite"),
        ({"omega_start": 1.0, "omega_stop": 2.0, "parameter": "force"}, "force_stop is required"),
        ({"omega_start": 1.0, "omega_stop": 2.0, "parameter": "amplitude"}, "'omega' or 'force'"),
    ],
)
def test_bad_input_is_one_clear_error(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        frequency_response(PYHARM, F0, **with_losses(kwargs))  # type: ignore[arg-type]


def test_result_repr_plot_and_xarray(curve: FrequencyResponse) -> None:
    import matplotlib

    matplotlib.use("Agg")
    text = repr(curve)
    assert "FrequencyResponse(" in text
    assert "2 fold" in text
    assert "[" not in text
    ax = curve.plot()
    assert ax.get_xlabel() == "frequency (Hz)"
    styles = {line.get_linestyle() for line in ax.get_lines() if len(line.get_xdata()) > 1}
    assert {"-", "--"} <= styles
    data = curve.to_xarray()
    assert data["amplitude"].attrs["units"] == "m"
    assert data["frequency"].attrs["units"] == "Hz"
    assert data.sizes["point"] == curve.omega.size
    assert list(data["event_kind"].values).count("fold") == 2


def test_repr_and_plot_show_event_kinds_beyond_the_exact_ones(curve: FrequencyResponse) -> None:
    """Harmonic balance adds "neimark_sacker" and "untrusted" events: the repr counts them,
    the plot marks a Neimark-Sacker point (the exact curve's own kinds are unchanged)."""
    import dataclasses

    import matplotlib

    from clearjoint.periodic import ResponseEvent

    matplotlib.use("Agg")
    w = float(curve.omega[len(curve.omega) // 2])
    extra = (
        ResponseEvent("neimark_sacker", w, float(curve.force_amplitude[0]), 1e-3, "test"),
        ResponseEvent("untrusted", w, float(curve.force_amplitude[0]), 1e-3, "test"),
    )
    marked = dataclasses.replace(curve, events=tuple(curve.events) + extra)
    text = repr(marked)
    assert "2 fold" in text
    assert "1 neimark_sacker" in text
    assert "1 untrusted" in text
    assert "neimark_sacker" not in repr(curve)
    labels = marked.plot().get_legend_handles_labels()[1]
    assert "neimark_sacker" in labels
    assert "neimark_sacker" not in curve.plot().get_legend_handles_labels()[1]


def _study_losses() -> tuple[Joint, dict[str, object]]:
    """examples/study.toml's joint and losses, mapped as ``clearjoint frf`` maps them."""
    from clearjoint.simulate.study import load_study

    study = load_study(Path(__file__).parents[1] / "examples" / "study.toml")
    losses = {
        "damping_ratio": study.damping_ratio,
        "friction": study.friction,
        "restitution": study.restitution,
    }
    return study.joint, {"force": study.force_amplitude, **losses}


def test_study_curve_crosses_the_grazing_with_impacts_near_69_hz() -> None:
    # examples/study.toml (k0 = 0, friction, e = 0.8): near 69.4853 Hz a short free-play
    # excursion appears inside the tension stage, and with e < 1 the map has a square-root
    # singularity there, on which the arclength corrector fails at any step.
    joint, kw = _study_losses()
    force = float(kw.pop("force"))  # type: ignore[arg-type]
    hz = 2.0 * math.pi
    curve = frequency_response(joint, force, 20.0 * hz, 72.0 * hz, **with_losses(kw))  # type: ignore[arg-type]
    assert curve.stop_reason == "reached"
    assert curve.omega[-1] == pytest.approx(72.0 * hz)
    kinks = [e for e in curve.events if e.kind == "grazing" and 69.0 < e.omega / hz < 70.0]
    assert len(kinks) == 1
    assert kinks[0].omega / hz == pytest.approx(69.4853, abs=2e-3)
    # past the kink the orbit has an extra free-play stage: two more events a period
    before = curve.cycle(int(np.argmin(np.abs(curve.omega - 69.0 * hz))))
    after = curve.cycle(int(np.argmin(np.abs(curve.omega - 69.9 * hz))))
    assert len(after.stages) == len(before.stages) + 2
    # every stable point past the kink, checked by time marching (no Newton) from off the orbit
    past = np.nonzero(curve.stable & (curve.omega > 69.5 * hz))[0]
    assert past.size > 5
    for i in past[:: max(1, past.size // 4)]:
        start = curve.initial_state[i] * (1.0 + 1e-6)
        ss = steady_state(joint, force, float(curve.omega[i]), initial=start, **with_losses(kw))  # type: ignore[arg-type]
        assert ss.period_multiple == 1
        scale = curve.amplitude[i]
        assert abs(ss.x_max - curve.x_max[i]) / scale < 1e-9
        assert abs(ss.x_min - curve.x_min[i]) / scale < 1e-9


def test_study_curve_turns_back_where_sticking_begins_near_74_hz() -> None:
    # examples/study.toml: the unstable branch coming down from the fold near 76.9 Hz meets,
    # at 74.2232 Hz, an orbit whose velocity zero in the free play becomes tangent: past it
    # the mass sticks for a moment. The map stays continuous but its Jacobian jumps (a
    # corner), the no-stick branch ends there, and a stable sticking branch leaves it back
    # up in frequency (a nonsmooth fold). The curve used to stop at this point.
    joint, kw = _study_losses()
    force = float(kw.pop("force"))  # type: ignore[arg-type]
    hz = 2.0 * math.pi
    curve = frequency_response(joint, force, 72.0 * hz, 78.0 * hz, **with_losses(kw))  # type: ignore[arg-type]
    assert curve.stop_reason == "reached"
    corner = [e for e in curve.events if "sticking begins" in e.note and "turns back" in e.note]
    assert len(corner) == 1
    assert corner[0].omega / hz == pytest.approx(74.2232, abs=2e-3)
    assert any(e.kind == "fold" and abs(e.omega - corner[0].omega) < 1e-3 for e in curve.events)
    # two orbits just above the corner, one on each piece: unstable without sticking, stable
    # with it, each the orbit of the exact map there (the fold has two sides)
    near = np.nonzero(np.abs(curve.omega / hz - 74.5) < 0.2)[0]
    pieces = {bool(curve.stable[i]): int(i) for i in near}
    assert set(pieces) == {True, False}
    unstable, stable = curve.cycle(pieces[False]), curve.cycle(pieces[True])
    assert unstable.stick_time == 0.0
    assert stable.stick_time > 0.0
    # the stable sticking orbits past the corner, by time marching from off the orbit
    past = np.nonzero(curve.stable & (curve.omega > 74.3 * hz))[0]
    past = past[np.argsort(curve.omega[past])]
    assert past.size > 5
    for i in past[:: max(1, past.size // 3)]:
        start = curve.initial_state[i] * (1.0 + 1e-6)
        ss = steady_state(joint, force, float(curve.omega[i]), initial=start, **with_losses(kw))  # type: ignore[arg-type]
        assert ss.period_multiple == 1
        assert ss.stick_time > 0.0
        scale = curve.amplitude[i]
        assert abs(ss.x_max - curve.x_max[i]) / scale < 1e-9
        assert abs(ss.x_min - curve.x_min[i]) / scale < 1e-9


def test_restitution_curve_of_the_pyharm_case_passes_both_grazings() -> None:
    # e = 0.8: the impacts make the map square-root singular where the orbit first touches
    # the edges (omega ~ 0.913) and where the unstable branch meets the lower one (~1.0785)
    curve = frequency_response(
        PYHARM, F0, 0.05, 1.8, losses=Losses(damping_ratio=ZETA, restitution=0.8)
    )
    assert curve.stop_reason == "reached"
    assert curve.omega[-1] == pytest.approx(1.8)
    grazing = sorted(e.omega for e in curve.events if e.kind == "grazing")
    # where the linear orbit reaches the edges: F0 / |1 - w^2 + 0.05 i w| = 0.1745
    touch = [
        float(w)
        for w in np.linspace(0.8, 1.2, 400001)
        if abs(F0 / math.hypot(1.0 - w * w, 0.05 * w) - PYHARM.compression_gap) < 2e-6
    ]
    assert grazing[0] == pytest.approx(min(touch), rel=2e-3)
    assert grazing[-1] == pytest.approx(max(touch), rel=2e-3)
    # both stable branches and the unstable one are there
    assert (~curve.stable).sum() > 10
    # steady_state stops when one period moves the state by ~1e-12; with a multiplier
    # of modulus 0.995 (next to the grazing) that leaves it ~1e-10 / (1 - 0.995) from the
    # fixed point: compare where its own error is below the 1e-9 asked
    stable = np.nonzero(curve.stable & (np.abs(curve.multipliers).max(axis=1) < 0.99))[0]
    for i in stable[:: max(1, stable.size // 6)]:
        start = curve.initial_state[i] * (1.0 + 1e-6)
        ss = steady_state(
            PYHARM,
            F0,
            float(curve.omega[i]),
            losses=Losses(damping_ratio=ZETA, restitution=0.8),
            initial=start,
        )
        scale = curve.amplitude[i]
        assert abs(ss.x_max - curve.x_max[i]) / scale < 1e-9
        assert abs(ss.x_min - curve.x_min[i]) / scale < 1e-9


def test_compiled_corrector_matches_the_generic_one() -> None:
    # the continuation hands its Newton loop to periodic's compiled corrector: on the same
    # prediction it must land where continuation's own Python loop lands
    from clearjoint.continuation import ContinuationSettings, _correct
    from clearjoint.exact.single import parameters as _parameters
    from clearjoint.periodic import _map_residual

    orbit = periodic_orbit(PYHARM, F0, 1.3, losses=Losses(damping_ratio=ZETA))
    p = _parameters(PYHARM, F0, 1.3, ZETA, None, 1.0)
    residual = _map_residual(p, "omega")
    scale = np.array([0.2, 0.26, 1.75])
    y0 = np.array([*orbit.initial_state, 1.3]) / scale + np.array([1e-3, -2e-3, 4e-3])
    tangent = np.array([0.3, -0.2, 0.9])
    tangent /= np.linalg.norm(tangent)
    settings = ContinuationSettings(chord_parameter=True)

    def generic(u: np.ndarray, lam: float, derivative: bool = True) -> object:
        return residual(u, lam, derivative)

    for fixed in (False, True):
        fast = residual.corrector(y0, tangent, scale, settings, fixed)
        slow = _correct(generic, y0, tangent, scale, settings, fixed)  # type: ignore[arg-type]
        assert fast is not None
        assert slow is not None
        assert fast[3] == slow[3]
        assert np.allclose(fast[0], slow[0], rtol=0.0, atol=1e-12)
        assert np.allclose(fast[1], slow[1], rtol=1e-9, atol=1e-12)
        assert np.allclose(fast[2][:2], 0.0, atol=1e-11 * 0.2)


def test_branch_switching_at_each_period_doubling_finds_the_period_2_orbit() -> None:
    fr = frequency_response(ONE_SIDED, 1.0, 1.8, 3.8, losses=Losses(damping_ratio=0.05))
    doublings = [e for e in fr.events if e.kind == "period_doubling"]
    assert len(doublings) == 2
    for event in doublings:
        orbit = fr.period_2_orbit(event)
        assert orbit.period_multiple == 2
        omega = orbit.omega
        assert abs(omega - event.omega) < 0.1
        period = 2 * math.pi / omega
        z = np.array(orbit.initial_state)
        scale = np.array([orbit.amplitude, orbit.amplitude * omega])
        # by time marching (no Newton): back after two forcing periods, not after one
        one = time_response(
            ONE_SIDED, 1.0, omega, period, initial=z, losses=Losses(damping_ratio=0.05)
        )
        two = time_response(
            ONE_SIDED, 1.0, omega, 2 * period, initial=z, losses=Losses(damping_ratio=0.05)
        )
        assert np.max(np.abs(np.array(two.final_state) - z) / scale) < 1e-9
        assert np.max(np.abs(np.array(one.final_state) - z) / scale) > 1e-3
        if orbit.stable:  # and steady_state from off the orbit settles on it
            ss = steady_state(
                ONE_SIDED, 1.0, omega, losses=Losses(damping_ratio=0.05), initial=z * (1.0 + 1e-6)
            )
            assert ss.period_multiple == 2
            assert abs(ss.x_max - orbit.x_max) / orbit.amplitude < 1e-9
            assert abs(ss.x_min - orbit.x_min) / orbit.amplitude < 1e-9
    assert any(fr.period_2_orbit(e).stable for e in doublings)
    with pytest.raises(ParameterError, match="period_doubling"):
        fr.period_2_orbit(next(e for e in fr.events if e.kind != "period_doubling"))


def test_study_curve_goes_on_past_the_grazing_fold_near_104_hz_from_an_orbit_further_on(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # examples/study.toml: the branch comes down from the fold at 106.66 Hz, loses a short
    # low-speed compression contact at 104.466 Hz (a grazing) and ends at 104.4545 Hz, where
    # it meets, at a grazing fold, the piece with that contact that leads on up in frequency.
    # No step from the lower piece finds that one (it stopped there: "ran back along its own
    # path" / "step too small"); from a period-1 orbit further up (a transient and Newton)
    # the branch is followed back down to where it stopped, crossing from the other side.
    import clearjoint.periodic as periodic

    joint, kw = _study_losses()
    force = float(kw.pop("force"))  # type: ignore[arg-type]
    hz = 2.0 * math.pi
    monkeypatch.setattr(periodic, "_REJOINS", 0)
    stuck = frequency_response(joint, force, 100.0 * hz, 115.0 * hz, **with_losses(kw))  # type: ignore[arg-type]
    assert stuck.stop_reason.startswith(("ran back", "step too small"))
    assert stuck.omega.max() / hz < 106.7
    monkeypatch.undo()
    curve = frequency_response(joint, force, 100.0 * hz, 115.0 * hz, **with_losses(kw))  # type: ignore[arg-type]
    assert curve.stop_reason == "reached"
    assert curve.omega[-1] / hz == pytest.approx(115.0)
    # the part past the old stop: each sampled stable orbit by time marching from off it
    past = np.nonzero(
        curve.stable
        & (np.arange(curve.omega.size) > stuck.omega.size)
        & (np.abs(curve.multipliers).max(axis=1) < 0.99)
    )[0]
    assert past.size >= 3
    for i in past:
        start = curve.initial_state[i] * (1.0 + 1e-6)
        ss = steady_state(joint, force, float(curve.omega[i]), initial=start, **with_losses(kw))  # type: ignore[arg-type]
        assert ss.period_multiple == 1
        scale = curve.amplitude[i]
        assert abs(ss.x_max - curve.x_max[i]) / scale < 1e-9
        assert abs(ss.x_min - curve.x_min[i]) / scale < 1e-9
    # and the stable orbit a long transient from rest settles on at 105 Hz is on the curve
    rest = steady_state(joint, force, 105.0 * hz, **with_losses(kw))  # type: ignore[arg-type]
    assert rest.period_multiple == 1
    on = np.nonzero(np.abs(curve.omega / hz - 105.0) < 0.05)[0]
    assert np.min(np.abs(curve.amplitude[on] - rest.amplitude)) < 1e-3 * rest.amplitude


def test_compiled_ordinary_step_follows_the_same_branch_as_the_python_one() -> None:
    # the continuation hands its ordinary step (predictor, corrector, tangent) to the
    # residual's compiled ``step``; without that hook it predicts and orients in Python:
    # the two must give the same points, bit for bit (the same arithmetic, compiled)
    from clearjoint.continuation import ContinuationSettings, continue_branch
    from clearjoint.exact.single import parameters as _parameters
    from clearjoint.periodic import _map_residual

    orbit = periodic_orbit(PYHARM, F0, 1.0, losses=Losses(damping_ratio=ZETA))
    p = _parameters(PYHARM, F0, 1.0, ZETA, None, 1.0)
    residual = _map_residual(p, "omega")

    class WithoutStep:
        corrector = staticmethod(residual.corrector)

        def __call__(self, u: np.ndarray, lam: float, derivative: bool = True) -> object:
            return residual(u, lam, derivative)

    settings = ContinuationSettings(
        step=0.002, min_step=1e-7, max_step=0.023, max_points=60, chord_parameter=True
    )
    kw = {"u_scale": np.array([0.2, 0.3]), "lam_scale": 0.8, "settings": settings}
    fast = continue_branch(residual, np.array(orbit.initial_state), 1.0, 1.8, **kw)  # type: ignore[arg-type]
    slow = continue_branch(WithoutStep(), np.array(orbit.initial_state), 1.0, 1.8, **kw)  # type: ignore[arg-type]
    assert fast.lam.size == slow.lam.size == 60
    assert np.array_equal(fast.u, slow.u)
    assert np.array_equal(fast.lam, slow.lam)
    assert np.array_equal(fast.tangent, slow.tangent)
    assert np.array_equal(fast.iterations, slow.iterations)
    assert int(np.sum(fast.iterations == 1)) > 10  # the polynomial predictor was used on the way


def test_study_unstable_branch_passes_where_the_section_sits_on_an_impact_near_636_hz() -> None:
    # examples/study.toml: the unstable branch coming down from the fold at 704.8 Hz used to
    # stop at 636.04 Hz. There its tension impact passes through forcing phase 0, so the
    # state at phase 0 jumps (v -> v / e) while the orbit itself changes smoothly
    # (multipliers about 2.36 and 0.13 on both sides): not a fold.
    joint, kw = _study_losses()
    force = float(kw.pop("force"))  # type: ignore[arg-type]
    hz = 2.0 * math.pi
    curve = frequency_response(joint, force, 500.0 * hz, 720.0 * hz, **with_losses(kw))  # type: ignore[arg-type]
    assert curve.stop_reason == "reached"
    f = curve.omega / hz
    assert f.min() < 490.0  # on down past 636.04 Hz, the way it was going
    folds = [e.omega / hz for e in curve.events if e.kind == "fold"]
    assert any(e == pytest.approx(704.78, abs=0.01) for e in folds)
    assert not any(600.0 < e < 700.0 for e in folds)
    assert curve.free_play is not None
    top = int(np.argmax(np.where(curve.free_play, 0.0, f)))  # the fold at 704.78 Hz
    # where the phase-0 state crosses the tension edge: after the impact (in contact) above,
    # before it (in the gap) below, the parameter still going down
    gap = joint.tension_gap
    x0 = curve.initial_state[:, 0]
    above = top + int(np.nonzero(x0[top:] > -gap)[0][0]) - 1
    below = above + 1
    assert 636.0 < f[below] < f[above] < 636.1
    ratio = curve.initial_state[above, 1] / curve.initial_state[below, 1]
    assert ratio == pytest.approx(kw["restitution"], rel=1e-3)  # v after = e v before
    assert np.abs(curve.multipliers[above]) == pytest.approx(
        np.abs(curve.multipliers[below]), rel=1e-3
    )
    # independent route: time marching closes both orbits after a period; perturbed, they leave
    unstable_branch = (np.arange(f.size) > top) & ~curve.free_play
    for i in (above, below, int(np.argmin(np.where(unstable_branch, abs(f - 620.0), np.inf)))):
        assert not curve.stable[i]
        w = float(curve.omega[i])
        z = curve.initial_state[i]
        size = np.array([curve.amplitude[i], curve.amplitude[i] * w])
        one = time_response(joint, force, w, 2.0 * math.pi / w, initial=z, **with_losses(kw))  # type: ignore[arg-type]
        assert np.max(np.abs(np.array(one.final_state) - z) / size) < 1e-8
        kicked = time_response(
            joint,
            force,
            w,
            60 * 2.0 * math.pi / w,
            initial=z + 1e-6 * size,
            **with_losses(kw),  # type: ignore[arg-type]
        )
        assert np.max(np.abs(np.array(kicked.final_state) - z) / size) > 1e-3


def test_reached_means_the_curve_ends_at_the_end_of_the_range() -> None:
    # examples/study.toml (k0 = 0, friction, e = 0.8) followed down in force at 400 Hz: the
    # orbits below 680 N stay in the gap (a multiplier exactly 1, a continuum). The branch
    # used to wander into them and end short of 100 N, which must not be called "reached"
    # (the CLI prints no warning for it); it now goes on along the centred free-play orbits
    # to 100 N itself (tests/test_periodic_free_play.py). continue_branch's own check:
    # tests/test_continuation.py::test_a_step_past_the_end_with_no_point_there_is_not_called_reached
    joint, kw = _study_losses()
    kw.pop("force")
    fr = frequency_response(
        joint,
        2000.0,
        2 * math.pi * 400.0,
        None,
        parameter="force",
        force_stop=100.0,
        **with_losses(kw),
    )  # type: ignore[arg-type]
    if fr.stop_reason == "reached":
        assert fr.force_amplitude[-1] == pytest.approx(100.0, rel=1e-12)
    else:
        assert "100" in fr.stop_reason
        assert f"{fr.force_amplitude[-1]:.6g}" in fr.stop_reason


def test_a_period_doubling_at_a_kink_is_not_said_to_pass_minus_1() -> None:
    # examples/study.toml from 400 down to 300 Hz: the period-1 orbit loses stability through
    # -1 near 314.4 Hz, regains it at a sticking corner near 310.27 Hz, where its multiplier
    # jumps from about -1.24 to -0.55 (the Jacobian jumps), and loses it again near 302.1 Hz.
    # Only where the multipliers on both sides are near -1 does one pass -1 smoothly.
    joint, kw = _study_losses()
    force = kw.pop("force")
    fr = frequency_response(
        joint, force, 2 * math.pi * 400.0, 2 * math.pi * 300.0, **with_losses(kw)
    )  # type: ignore[arg-type]
    doublings = [e for e in fr.events if e.kind == "period_doubling"]
    assert len(doublings) == 3
    f = fr.omega / (2 * math.pi)
    for event in doublings:
        hz = event.omega / (2 * math.pi)
        i = int(np.argmin(np.abs(f - hz)))
        near = fr.multipliers[max(i - 1, 0) : i + 2, 0].real  # the -1-side multiplier around it
        smooth = bool(np.all(np.abs(near + 1.0) < 0.15))
        assert ("passes -1" in event.note) == smooth, (hz, near, event.note)
        assert ("jumps across -1" in event.note) == (not smooth)
    assert sum("jumps across -1" in e.note for e in doublings) == 1


def test_plot_marks_each_event_at_its_frequency_in_hz_and_dashes_the_middle_branch(
    curve: FrequencyResponse,
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    ax = curve.plot()
    lines = {line.get_label(): line for line in ax.get_lines()}
    for kind in ("fold", "grazing"):
        hz = sorted(e.omega / (2 * math.pi) for e in curve.events if e.kind == kind)
        assert sorted(lines[kind].get_xdata()) == pytest.approx(hz)
        assert lines[kind].get_linestyle() == "None"
    # the dashed pieces lie between the two folds (0.17 to 0.25 Hz), in Hz, in mm
    folds = sorted(e.omega / (2 * math.pi) for e in curve.events if e.kind == "fold")
    dashed = [
        line for line in ax.get_lines() if line.get_linestyle() == "--" and len(line.get_xdata())
    ]
    assert dashed
    for line in dashed:
        x = np.asarray(line.get_xdata())
        assert folds[0] - 1e-3 <= x.min()
        assert x.max() <= folds[1] + 1e-3
        # in mm: the unstable orbits' X (0.17 to 0.40 m here) times 1e3
        assert np.max(line.get_ydata()) == pytest.approx(
            1e3 * curve.amplitude[~curve.stable].max(), rel=1e-12
        )
    matplotlib.pyplot.close("all")


def test_an_undamped_start_at_a_whole_fraction_of_the_gap_frequency_gets_the_right_advice() -> None:
    # no damping (the default) and omega_start = sqrt(k0/m) / 2: the linear orbit inside the
    # gap has the multipliers exp(+-2 pi i sqrt(k0/m) / omega) = 1, a continuum of orbits
    # (any free oscillation can be added). gap_stiffness is already > 0 here, so the advice
    # to give gap_stiffness > 0 would be wrong: it must name the damping.
    with pytest.raises(SimulationError, match="damping_ratio > 0") as caught:
        frequency_response(PYHARM, F0, 0.5, 1.8)
    assert "give gap_stiffness > 0" not in str(caught.value)
    assert "1.0 rad/s" in str(caught.value)  # sqrt(k0/m), the gap's natural frequency


def test_structure_curve_plot_has_one_colour_and_label_per_dof() -> None:
    """X of shape (n, N): each DOF its own colour, the 8 largest labelled, the rest grey."""
    import matplotlib.colors

    n, dofs = 6, 10
    omega = np.linspace(10.0, 20.0, n)
    amp = np.outer(np.ones(n), np.arange(1, dofs + 1) * 1e-4)  # DOF k moves (k + 1) x 0.1 mm
    stable = np.array([True, True, False, False, True, True])
    curve = FrequencyResponse(
        omega=omega,
        force_amplitude=np.ones(n),
        x_max=amp,
        x_min=-amp,
        amplitude=amp,
        stable=stable,
        multipliers=np.zeros((n, 2), dtype=np.complex128),
        initial_state=np.zeros((n, 2 * dofs)),
        events=[],
        parameter="omega",
        stop_reason="reached",
        settings={"dof_names": [f"n{k}x" for k in range(dofs)]},
        method="harmonic",
    )
    ax = curve.plot()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[:8] == [f"n{k}x" for k in range(9, 1, -1)]  # largest first
    assert "other DOFs" in labels
    drawn = [line for line in ax.get_lines() if len(line.get_xdata())]
    assert len(drawn) == 3 * dofs  # stable, unstable, stable segments per DOF
    top = {matplotlib.colors.to_hex(line.get_color()) for line in drawn[-3:]}
    assert top == {matplotlib.colors.to_hex("C0")}  # DOF 9, the largest, in C0 throughout
    styles = {line.get_linestyle() for line in drawn[-3:]}
    assert styles == {"-", "--"}
    colours = {matplotlib.colors.to_hex(line.get_color()) for line in drawn}
    assert len(colours) == 9  # 8 own colours and the grey of the other two
