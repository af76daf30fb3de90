"""stiffness.py against independent routes: numerical integration, closed forms, limits."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from clearjoint import Joint, ParameterError
from clearjoint import stiffness as sk
from helpers import C1, CASES, joint, reference_describing_stiffness, reference_period


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("amplitude", [3e-8, 1e-6, 2e-5, 4e-4])
def test_period_matches_solve_ivp_with_events(name: str, amplitude: float) -> None:
    j = CASES[name]
    exact = float(sk.period(j, amplitude))
    numeric = reference_period(j, amplitude, rtol=1e-11)
    assert abs(exact - numeric) / numeric < 1e-8


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    mass=st.floats(0.1, 20.0),
    k_c=st.floats(1e5, 1e9),
    tension_ratio=st.floats(0.2, 5.0),
    gap_ratio=st.one_of(st.just(0.0), st.floats(1e-3, 0.5)),
    clearance=st.floats(1e-6, 1e-3),
    offset_fraction=st.floats(-0.5, 0.5),
    amplitude_fraction=st.floats(1e-3, 20.0),
)
def test_period_matches_solve_ivp_for_generated_joints(
    mass: float,
    k_c: float,
    tension_ratio: float,
    gap_ratio: float,
    clearance: float,
    offset_fraction: float,
    amplitude_fraction: float,
) -> None:
    j = Joint(
        mass=mass,
        clearance=clearance,
        compression_stiffness=k_c,
        tension_stiffness=tension_ratio * k_c,
        gap_stiffness=gap_ratio * k_c,
        gap_offset=offset_fraction * clearance,
    )
    amplitude = amplitude_fraction * clearance
    exact = float(sk.period(j, amplitude))
    numeric = reference_period(j, amplitude, rtol=1e-11)
    assert abs(exact - numeric) / numeric < 1e-8


def test_eq9_for_the_symmetric_joint_without_gap_spring() -> None:
    a = np.linspace(0.0, 1e-3, 101)
    expected = (math.pi * a / (math.pi * a + C1)) ** 2
    np.testing.assert_allclose(sk.stiffness_coefficient(joint(), a), expected, rtol=1e-13)


def test_eq6_natural_frequency_for_the_symmetric_joint() -> None:
    j = joint()
    a = np.array([1e-6, 1e-5, 1e-4])
    omega_1 = math.sqrt(8e7 / 2.0)
    np.testing.assert_allclose(
        sk.natural_frequency(j, a), omega_1 / (1.0 + C1 / (math.pi * a)), rtol=1e-13
    )


def test_asymmetric_joint_without_gap_spring_uses_the_mean_penetration() -> None:
    # MODEL.md sec. 1: A_t = A_c sqrt(k_c / k_t) and c_d = (pi Abar / (pi Abar + c))^2
    j = joint(tension_stiffness=2e7)
    a_c = np.geomspace(1e-7, 1e-3, 30)
    a_t = a_c * math.sqrt(8e7 / 2e7)
    a_bar = 0.5 * (a_c + a_t)
    np.testing.assert_allclose(
        sk.stiffness_coefficient(j, a_c),
        (math.pi * a_bar / (math.pi * a_bar + C1)) ** 2,
        rtol=1e-12,
    )
    orbit = sk.free_orbit(j, a_c)
    np.testing.assert_allclose(orbit.tension_penetration, a_t, rtol=1e-12)
    np.testing.assert_allclose(orbit.displacement_amplitude, a_bar + C1 / 2, rtol=1e-12)


def test_no_clearance_gives_the_bilinear_oscillator_at_every_amplitude() -> None:
    j = joint(clearance=0.0, tension_stiffness=3e7, gap_stiffness=5e6)
    a = np.array([0.0, 1e-9, 1e-5, 1.0])
    expected = math.pi * math.sqrt(2.0 / 8.5e7) + math.pi * math.sqrt(2.0 / 3.5e7)
    np.testing.assert_allclose(sk.period(j, a), expected, rtol=1e-14)
    np.testing.assert_allclose(sk.stiffness_coefficient(j, a), 1.0, rtol=1e-13)


def test_zero_amplitude_without_gap_spring_never_moves_and_warns_nothing() -> None:
    j = joint(tension_stiffness=3e7, gap_offset=1e-5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert math.isinf(float(sk.period(j, 0.0)))
        assert float(sk.natural_frequency(j, 0.0)) == 0.0
        assert float(sk.stiffness_coefficient(j, 0.0)) == 0.0


def test_zero_amplitude_with_gap_spring_is_the_free_play_oscillator() -> None:
    # centred gap: at A = 0 the mass grazes both edges and oscillates at w0
    j = joint(tension_stiffness=3e7, gap_stiffness=2e6)
    assert float(sk.period(j, 0.0)) == pytest.approx(2 * math.pi / math.sqrt(2e6 / 2.0), rel=1e-14)
    assert float(sk.dynamic_stiffness(j, 0.0)) == pytest.approx(2e6, rel=1e-13)


def test_small_amplitudes_approach_the_zero_amplitude_limit_continuously() -> None:
    for j in CASES.values():
        if j.gap_stiffness == 0.0:
            continue
        t0 = float(sk.period(j, 0.0))
        assert float(sk.period(j, 1e-14)) == pytest.approx(t0, rel=1e-7)


def test_tension_side_never_touched_at_small_amplitude() -> None:
    # gap pushed toward compression: with k0 > 0 a small orbit never reaches the tension edge;
    # its free-play time is (pi + 2 asin(g_c / X0)) / w0 (MODEL.md sec. 1)
    j = joint(gap_stiffness=4e6, gap_offset=-0.045e-3)
    a = 1e-7
    orbit = sk.free_orbit(j, a)
    assert not bool(orbit.tension_touched)
    assert float(orbit.tension_penetration) == 0.0
    w0 = math.sqrt(4e6 / 2.0)
    x0 = math.sqrt((j.compression_gap + a) ** 2 + 8e7 * a**2 / 4e6)
    assert float(orbit.x_min) == pytest.approx(-x0, rel=1e-13)
    free = (math.pi + 2 * math.asin(j.compression_gap / x0)) / w0
    assert float(orbit.free_play_time) == pytest.approx(free, rel=1e-12)


def test_large_amplitude_limit_is_one() -> None:
    for j in CASES.values():
        assert float(sk.stiffness_coefficient(j, 1e3)) == pytest.approx(1.0, rel=1e-6)


def test_stiffness_rises_with_amplitude_and_falls_with_clearance() -> None:
    a = np.geomspace(1e-7, 1e-3, 50)
    for j in CASES.values():
        assert np.all(np.diff(sk.dynamic_stiffness(j, a)) > 0.0)
    wide = joint(clearance=0.196e-3)
    assert np.all(sk.dynamic_stiffness(wide, a) < sk.dynamic_stiffness(joint(), a))


def test_orbit_conserves_energy_at_both_turning_points() -> None:
    for j in CASES.values():
        a = np.geomspace(1e-8, 1e-3, 20)
        orbit = sk.free_orbit(j, a)
        np.testing.assert_allclose(
            j.potential_energy(orbit.x_min), j.potential_energy(orbit.x_max), rtol=1e-10
        )
        np.testing.assert_allclose(
            orbit.compression_time + orbit.tension_time + orbit.free_play_time,
            orbit.period,
            rtol=1e-14,
        )


def test_shape_is_preserved() -> None:
    a = np.full((3, 4), 1e-5)
    assert sk.period(joint(), a).shape == (3, 4)
    assert sk.period(joint(), 1e-5).shape == ()


@pytest.mark.parametrize("bad", [-1e-6, math.nan, math.inf, [1e-6, -1e-9]])
def test_bad_amplitudes_are_refused_with_a_message(bad: object) -> None:
    with pytest.raises(ParameterError, match="amplitude"):
        sk.dynamic_stiffness(joint(), bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("displacement", [1e-5, 0.5e-4, 6e-5, 2e-4, 3e-3])
def test_describing_stiffness_matches_fourier_projection(name: str, displacement: float) -> None:
    j = CASES[name]
    numeric = reference_describing_stiffness(j, displacement)
    assert float(sk.describing_stiffness(j, displacement)) == pytest.approx(
        numeric, rel=1e-8, abs=1e-9 * j.compression_stiffness
    )


def test_describing_stiffness_limits() -> None:
    j = joint(tension_stiffness=3e7, gap_stiffness=1e6)
    assert float(sk.describing_stiffness(j, 1e-6)) == 1e6  # inside the gap: only k0
    assert float(sk.describing_stiffness(j, 0.0)) == 1e6
    assert float(sk.describing_stiffness(j, 1e3)) == pytest.approx(1e6 + 5.5e7, rel=1e-6)
    no_gap = joint(clearance=0.0)
    assert float(sk.describing_stiffness(no_gap, 0.0)) == 8e7


# ---- eq 7: the equivalent linear forced response -------------------------------------------


def eq7_residual_symmetric(a: float, f0: float, omega: float, c_v: float) -> float:
    """X |Z| - F0 with k_d from eq 9, for the symmetric k0 = 0 joint (independent of the code)."""
    k_d = 8e7 * (math.pi * a / (math.pi * a + C1)) ** 2
    return (a + C1 / 2) * math.hypot(k_d - 2.0 * omega**2, c_v * omega) - f0


def test_linear_limit_has_one_branch_with_the_textbook_amplitude() -> None:
    j = joint(clearance=0.0)
    omega, zeta, f0 = 3000.0, 0.02, 150.0
    (branch,) = sk.equivalent_linear_response(j, f0, omega, zeta)
    c_v = 2 * zeta * math.sqrt(2.0 * 8e7)
    expected = f0 / math.hypot(8e7 - 2.0 * omega**2, c_v * omega)
    assert branch.displacement_amplitude == pytest.approx(expected, rel=1e-10)
    assert branch.stable


@pytest.mark.parametrize(
    ("f0", "frequency", "zeta", "pattern"),
    [
        # F0 above (c/2) m w^2: no orbit fits in the gap, three contacting orbits
        (2800.0, 800.0, 0.001, [(True, True), (False, True), (True, True)]),
        # F0 below it: the in-gap orbit, then an unstable and a stable contacting one
        (400.0, 500.0, 0.01, [(True, False), (False, True), (True, True)]),
    ],
)
def test_folds_give_three_branches_with_the_middle_unstable(
    f0: float, frequency: float, zeta: float, pattern: list[tuple[bool, bool]]
) -> None:
    j = joint()
    omega = 2 * math.pi * frequency
    branches = sk.equivalent_linear_response(j, f0, omega, zeta)
    assert [(b.stable, b.in_contact) for b in branches] == pattern
    c_v = 2 * zeta * math.sqrt(2.0 * 8e7)
    for b in branches:
        if b.in_contact:
            assert abs(eq7_residual_symmetric(b.penetration, f0, omega, c_v)) < 1e-8 * f0
            assert b.displacement_amplitude == pytest.approx(b.penetration + C1 / 2, rel=1e-12)
        else:
            expected = f0 / math.hypot(2.0 * omega**2, c_v * omega)
            assert b.displacement_amplitude == pytest.approx(expected, rel=1e-12)


def test_orbit_inside_the_gap_when_the_force_is_small() -> None:
    j = joint(gap_stiffness=1e6)
    omega, f0 = 100.0, 1.0
    branches = sk.equivalent_linear_response(j, f0, omega)
    assert branches[0].in_contact is False
    assert branches[0].displacement_amplitude == pytest.approx(f0 / abs(1e6 - 2.0 * omega**2))
    assert all(b.displacement_amplitude >= j.compression_gap for b in branches[1:])


def test_describing_method_solves_its_own_equation() -> None:
    j = joint(tension_stiffness=5e7)
    omega, zeta, f0 = 2 * math.pi * 300.0, 0.02, 500.0
    branches = sk.equivalent_linear_response(j, f0, omega, zeta, method="describing")
    assert branches
    c_v = 2 * zeta * math.sqrt(2.0 * 8e7)
    for b in branches:
        x = b.displacement_amplitude
        k_eq = reference_describing_stiffness(j, x)
        assert x * math.hypot(k_eq - 2.0 * omega**2, c_v * omega) == pytest.approx(f0, rel=1e-6)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"force_amplitude": -1.0}, "force_amplitude must be > 0"),
        ({"omega": 0.0}, "omega must be > 0"),
        ({"damping_ratio": -0.1}, "damping_ratio must be >= 0"),
        ({"method": "harmonic"}, "method must be"),
    ],
)
def test_equivalent_response_refuses_bad_input(kwargs: dict[str, object], words: str) -> None:
    args: dict[str, object] = {"force_amplitude": 100.0, "omega": 1000.0}
    args.update(kwargs)
    with pytest.raises(ParameterError, match=words):
        sk.equivalent_linear_response(joint(), **args)  # type: ignore[arg-type]


# ---- StiffnessCurve: the c_d curve as a result ----------------------------------------------


def _eq9(a: np.ndarray, clearance: float) -> np.ndarray:
    """Eq 9 by hand for a symmetric joint with k0 = 0: (pi A / (pi A + c))^2."""
    return (math.pi * a / (math.pi * a + clearance)) ** 2


def test_stiffness_curve_matches_eq_9_and_the_single_functions() -> None:
    j = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    a = np.array([1e-6, 5e-6, 20e-6, 100e-6])
    curve = sk.stiffness_curve(j, a)
    np.testing.assert_allclose(curve.stiffness_coefficient, _eq9(a, 0.106e-3), rtol=1e-12)
    np.testing.assert_allclose(curve.dynamic_stiffness, 8e7 * _eq9(a, 0.106e-3), rtol=1e-12)
    np.testing.assert_allclose(curve.natural_frequency, 2 * math.pi / curve.period, rtol=1e-15)
    np.testing.assert_array_equal(curve.period, sk.period(j, a))


def test_stiffness_curve_repr_is_short_and_names_the_range() -> None:
    j = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    a = np.linspace(1e-6, 100e-6, 5000)
    text = repr(sk.stiffness_curve(j, a))
    assert len(text) < 250
    assert "5000 amplitudes" in text
    assert f"{_eq9(a, 0.106e-3).max():.4g}" in text  # the largest c_d, by hand
    assert "0.106 mm" in text


def test_stiffness_curve_to_xarray_and_pandas_round_trip_with_units() -> None:
    j = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, gap_stiffness=1e6)
    a = np.array([0.0, 2e-6, 30e-6])
    curve = sk.stiffness_curve(j, a)
    data = curve.to_xarray()
    np.testing.assert_array_equal(data["amplitude"].values, a)
    assert data["amplitude"].attrs["units"] == "m"
    units = {"period": "s", "natural_frequency": "rad/s", "dynamic_stiffness": "N/m"}
    for name, unit in units.items():
        np.testing.assert_array_equal(data[name].values, getattr(curve, name))
        assert data[name].attrs["units"] == unit
    assert data.attrs["clearance_m"] == 0.106e-3
    table = curve.to_pandas()
    assert table.index.name == "amplitude_m"
    np.testing.assert_array_equal(
        table["stiffness_coefficient"].to_numpy(), curve.stiffness_coefficient
    )
    np.testing.assert_array_equal(table["period_s"].to_numpy(), curve.period)


def test_stiffness_curve_plot_draws_c_d_against_amplitude_in_um() -> None:
    from matplotlib.figure import Figure

    j = Joint(mass=2.0, clearance=0.196e-3, compression_stiffness=8e7)
    a = np.linspace(0.0, 300e-6, 50)
    ax = Figure().add_subplot()
    returned = sk.stiffness_curve(j, a).plot(ax)
    assert returned is ax
    line = ax.lines[-1]
    np.testing.assert_allclose(line.get_xdata(), a * 1e6)
    np.testing.assert_allclose(line.get_ydata(), _eq9(a, 0.196e-3), rtol=1e-12)


def test_stiffness_curve_refuses_a_grid_as_a_table() -> None:
    j = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7)
    curve = sk.stiffness_curve(j, np.full((2, 3), 1e-5))
    with pytest.raises(ParameterError, match="1-D amplitude"):
        curve.to_xarray()


def test_free_orbit_tables_and_plot() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a = np.array([1e-6, 2e-5, 1e-4])
    orbit = sk.free_orbit(joint(), a)
    data = orbit.to_xarray()
    np.testing.assert_array_equal(data["amplitude"].values, a)
    np.testing.assert_array_equal(data["period"].values, orbit.period)
    np.testing.assert_array_equal(data["x_max"].values, orbit.x_max)
    assert data["period"].attrs["units"] == "s"
    assert data["contact_action"].attrs["units"] == "m^2/s"
    table = orbit.to_pandas()
    np.testing.assert_array_equal(table["free_play_time"].to_numpy(), orbit.free_play_time)
    assert repr(orbit).startswith("FreeOrbit(3 amplitudes, A_c = 1-100 um")
    _, ax = plt.subplots()
    assert orbit.plot(ax) is ax
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), orbit.period * 1e3)
    plt.close("all")


def test_response_branch_tables_and_plot() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    branch = sk.equivalent_linear_response(joint(), 20000.0, 2 * math.pi * 100.0, 0.01)[0]
    data = branch.to_xarray()
    assert float(data["displacement_amplitude"]) == branch.displacement_amplitude
    assert float(data["stiffness"]) == branch.stiffness
    assert data["stiffness"].attrs["units"] == "N/m"
    assert data["natural_frequency"].attrs["units"] == "rad/s"
    row = branch.to_pandas()
    assert row.loc[0, "penetration_m"] == branch.penetration
    assert repr(branch).startswith("ResponseBranch(X = ")
    _, ax = plt.subplots()
    assert branch.plot(ax) is ax
    assert ax.get_lines()[-1].get_ydata()[0] == pytest.approx(branch.displacement_amplitude * 1e6)
    plt.close("all")
