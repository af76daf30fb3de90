"""dissipation.py: closed forms against numerical quadrature, limits, and the exact cycle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import Friction, Losses, ParameterError, Pin
from clearjoint import dissipation as ds
from clearjoint.contact import hertz_coefficient
from clearjoint.stiffness import free_orbit, natural_frequency
from helpers import C1, CASES, joint, reference_cycle, with_losses

PIN = Pin.for_clearance(radius=5e-3, clearance=C1, length=10e-3)


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("amplitude", [1e-7, 5e-6, 4e-5])
def test_closed_forms_match_quadrature_along_the_integrated_free_cycle(
    name: str, amplitude: float
) -> None:
    j = CASES[name]
    period, (v2, v2_gap, travel, contact) = reference_cycle(j, amplitude)
    orbit = free_orbit(j, amplitude)
    assert float(orbit.contact_action + orbit.free_play_action) == pytest.approx(v2, rel=1e-8)
    assert float(orbit.free_play_action) == pytest.approx(v2_gap, rel=1e-8)
    friction = Friction(0.3, 200.0)
    assert float(ds.sliding_friction(j, amplitude, friction)) == pytest.approx(
        60.0 * travel, rel=1e-8
    )
    factor = 4 * 0.2 * hertz_coefficient(PIN) / (3 * math.pi * PIN.radius)
    assert float(ds.contact_friction(j, amplitude, PIN, 0.2)) == pytest.approx(
        factor * contact, rel=1e-7
    )
    # the paper's form: c_P = 4 mu P / (pi w_n X) times the integral of v^2
    omega_n = 2 * math.pi / period
    x_amp = float(orbit.displacement_amplitude)
    assert float(ds.sliding_friction(j, amplitude, friction, form="paper")) == pytest.approx(
        4 * 60.0 / (math.pi * omega_n * x_amp) * v2, rel=1e-8
    )


@pytest.mark.parametrize("name", list(CASES))
def test_impact_speeds_come_from_the_energy_at_the_edges(name: str) -> None:
    j = CASES[name]
    a = 2e-5
    e = 0.6
    energy = float(j.potential_energy(j.compression_gap + a))
    speeds2 = [
        max(2 * (energy - float(j.potential_energy(edge))) / j.mass, 0.0)
        for edge in (j.compression_gap, -j.tension_gap)
    ]
    expected = 0.5 * (1 - e**2) * j.mass * sum(speeds2)
    assert float(ds.impact(j, a, e)) == pytest.approx(expected, rel=1e-12)


def test_paper_impact_for_the_symmetric_joint_is_beta_m_a_squared_w_squared() -> None:
    a, e = 3e-5, 0.5
    w1 = math.sqrt(8e7 / 2.0)
    assert float(ds.impact(joint(), a, e)) == pytest.approx(
        2 * 0.5 * (1 - e**2) * 2.0 * (a * w1) ** 2, rel=1e-12
    )


def test_friction_over_the_free_play_stroke_only_is_2_mu_p_c() -> None:
    friction = Friction(0.2, 100.0, region="free-play")
    a = np.array([1e-6, 1e-5, 1e-4])
    np.testing.assert_allclose(ds.sliding_friction(joint(), a, friction), 2 * 20.0 * C1)
    whole = ds.sliding_friction(joint(), a, Friction(0.2, 100.0))
    np.testing.assert_allclose(whole, 4 * 20.0 * (a + C1 / 2), rtol=1e-12)  # 4 mu P X


def test_without_clearance_the_paper_form_is_exact_and_viscous_is_pi_c_w_x2() -> None:
    linear = joint(clearance=0.0)
    a = np.array([1e-6, 3e-5])
    friction = Friction(0.2, 100.0)
    exact = ds.sliding_friction(linear, a, friction)
    paper = ds.sliding_friction(linear, a, friction, form="paper")
    np.testing.assert_allclose(paper, exact, rtol=1e-12)
    zeta = 0.03
    c_v = 2 * zeta * math.sqrt(2.0 * 8e7)
    w = math.sqrt(8e7 / 2.0)
    np.testing.assert_allclose(ds.viscous(linear, a, zeta), math.pi * c_v * w * a**2, rtol=1e-12)


def test_limits_no_friction_elastic_impact() -> None:
    values = ds.energies(joint(), 1e-5)
    for key in (
        "sliding_friction_j",
        "sliding_friction_paper_j",
        "contact_friction_j",
        "impact_j",
        "viscous_j",
        "total_j",
        "loss_factor",
        "hertz_half_width_m",
    ):
        assert float(values[key]) == 0.0


def test_energies_add_up_and_give_the_loss_factor() -> None:
    j = joint(tension_stiffness=5e7)
    a = np.array([5e-6, 2e-5])
    values = ds.energies(
        j,
        a,
        losses=Losses(
            friction=Friction(0.2, 300.0),
            pin=PIN,
            contact_friction_coefficient=0.15,
            restitution=0.8,
            damping_ratio=0.01,
        ),
    )
    assert set(values) == set(ds.ENERGY_KEYS)
    parts = (
        values["sliding_friction_j"]
        + values["contact_friction_j"]
        + values["impact_j"]
        + values["viscous_j"]
    )
    np.testing.assert_allclose(values["total_j"], parts, rtol=1e-14)
    u_max = j.potential_energy(free_orbit(j, a).x_max)
    np.testing.assert_allclose(values["loss_factor"], values["total_j"] / (2 * math.pi * u_max))
    np.testing.assert_allclose(values["equivalent_damping_ratio"], values["loss_factor"] / 2)
    peak = 8e7 * a  # compression carries the larger force here
    b = hertz_coefficient(PIN) * np.sqrt(peak)  # b = beta_H sqrt(F_n)
    np.testing.assert_allclose(values["hertz_half_width_m"], b, rtol=1e-12)


def test_compare_closes_the_balance_and_reports_the_gap() -> None:
    j = joint(tension_stiffness=5e7)
    long_pin = Pin.for_clearance(radius=5e-3, clearance=C1, length=25e-3)
    result = ds.compare(
        j,
        1000.0,
        2 * math.pi * 400.0,
        losses=Losses(
            friction=Friction(0.2, 300.0),
            pin=long_pin,
            contact_friction_coefficient=0.15,
            restitution=0.8,
            damping_ratio=0.01,
        ),
    )
    ledger = result.cycle.energy
    carried = result.exact["total_j"] - result.exact["contact_friction_j"]
    assert carried == pytest.approx(ledger.input, rel=1e-9)
    for key, gap in result.gap.items():
        assert gap == pytest.approx(result.closed[key] / result.exact[key] - 1.0)
    assert result.penetration == pytest.approx(result.cycle.x_max - j.compression_gap)


def test_closed_form_is_close_to_the_exact_cycle_on_the_resonant_branch() -> None:
    # forced at the free orbit's own frequency w_n(A), with F0 a little above the
    # losses' balance pi F0 X = E(A), the steady cycle sits near the free cycle
    j = joint(tension_stiffness=5e7)
    a = 4e-5
    losses = {"restitution": 0.95, "damping_ratio": 0.003, "friction": Friction(0.1, 20.0)}
    orbit = free_orbit(j, a)
    x_amp = float(orbit.displacement_amplitude)
    f0 = 1.5 * float(ds.total(j, a, **with_losses(losses))) / (math.pi * x_amp)  # type: ignore[arg-type]
    result = ds.compare(
        j,
        f0,
        float(natural_frequency(j, a)),
        initial=(float(orbit.x_min), 0.0),
        **with_losses(losses),
    )  # type: ignore[arg-type]
    assert result.penetration == pytest.approx(a, rel=0.05)
    for key in ("sliding_friction_j", "impact_j", "viscous_j"):
        assert abs(result.gap[key]) < 0.06, key
    assert abs(result.gap["total_j"]) < 0.04


def test_closed_form_is_far_from_a_quasi_static_cycle() -> None:
    # well below resonance the mass is pushed slowly through the gap: the free
    # cycle's edge speed A w_c overstates the impacts many times over
    result = ds.compare(
        joint(), 20000.0, 2 * math.pi * 100.0, losses=Losses(restitution=0.9, damping_ratio=0.01)
    )
    assert result.gap["impact_j"] > 5.0


def test_excitation_work_of_the_sampled_cycle_matches_the_ledger() -> None:
    from clearjoint.simulate import steady_state

    omega = 2 * math.pi * 400.0
    cycle = steady_state(
        joint(tension_stiffness=5e7),
        1000.0,
        omega,
        losses=Losses(damping_ratio=0.05),
        samples_per_period=4096,
    )
    work = ds.excitation_work(cycle.time, cycle.velocity, 1000.0, omega)
    assert work == pytest.approx(cycle.energy.input, rel=1e-4)


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: ds.impact(joint(), 1e-5, 1.2), "restitution must satisfy"),
        (lambda: ds.sliding_friction(joint(), 1e-5, 0.3), "friction must be"),  # type: ignore[arg-type]
        (
            lambda: ds.sliding_friction(joint(), 1e-5, Friction(0.1, 1.0), form="viscous"),
            "form must be",
        ),  # type: ignore[arg-type]
        (lambda: ds.energies(joint(), -1e-6), "amplitude must be >= 0"),
        (
            lambda: ds.excitation_work([0, 1, 3, 4, 5, 6, 7, 8], np.ones(8), 1.0, 1.0),
            "uniformly sampled",
        ),
    ],
)
def test_bad_input(call: object, words: str) -> None:
    with pytest.raises(ParameterError, match=words):
        call()  # type: ignore[operator]


# ---- Energies: what energies() returns, as a result ----------------------------------------

LOSSES = {
    "friction": Friction(0.2, 300.0),
    "pin": PIN,
    "contact_friction_coefficient": 0.15,
    "restitution": 0.8,
    "damping_ratio": 0.01,
}


def test_energies_result_is_still_the_mapping_it_was() -> None:
    values = ds.energies(joint(), np.array([5e-6, 2e-5]), **with_losses(LOSSES))  # type: ignore[arg-type]
    assert list(values) == list(ds.ENERGY_KEYS)
    assert dict(values).keys() == set(ds.ENERGY_KEYS)
    assert values["impact_j"] is values.impact_j
    with pytest.raises(KeyError):
        values["amplitude"]


def test_energies_repr_stays_short_for_many_amplitudes() -> None:
    a = np.geomspace(1e-6, 2e-5, 10_000)
    values = ds.energies(joint(), a, **with_losses(LOSSES))  # type: ignore[arg-type]
    text = repr(values)
    assert len(text) < 200
    assert "10000 amplitudes" in text
    # the impact energy alone bounds the total from below; the total's top end is printed
    top = float(np.max(values["total_j"])) * 1e3
    assert f"{top:.4g} mJ" in text


def test_energies_to_xarray_and_pandas_round_trip_with_units() -> None:
    a = np.array([1e-6, 5e-6, 2e-5])
    values = ds.energies(joint(), a, **with_losses(LOSSES))  # type: ignore[arg-type]
    data = values.to_xarray()
    np.testing.assert_array_equal(data["amplitude"].values, a)
    assert data["amplitude"].attrs["units"] == "m"
    for key in ds.ENERGY_KEYS:
        np.testing.assert_array_equal(data[key].values, values[key])
    assert data["total_j"].attrs["units"] == "J"
    assert data["loss_factor"].attrs["units"] == "1"
    assert data["hertz_half_width_m"].attrs["units"] == "m"
    table = values.to_pandas()
    assert list(table.columns) == list(ds.ENERGY_KEYS)
    np.testing.assert_array_equal(table.index.to_numpy(), a)
    # a scalar amplitude is a one-row table
    assert ds.energies(joint(), 1e-5).to_pandas().shape == (1, len(ds.ENERGY_KEYS))


def test_energies_plot_draws_the_total_in_mj_against_a_in_um() -> None:
    from matplotlib.figure import Figure

    a = np.geomspace(1e-6, 2e-5, 40)
    values = ds.energies(joint(), a, **with_losses(LOSSES))  # type: ignore[arg-type]
    ax = Figure().add_subplot()
    assert values.plot(ax) is ax
    lines = {line.get_label(): line for line in ax.lines}
    total = lines["total E_Z"]
    np.testing.assert_allclose(total.get_xdata(), a * 1e6)
    # the total is the sum of the mechanisms, added here independently of the library's total
    parts = sum(values[k] for k in ("sliding_friction_j", "contact_friction_j", "impact_j"))
    np.testing.assert_allclose(total.get_ydata(), (parts + values["viscous_j"]) * 1e3, rtol=1e-14)
    impact = lines["impact E_I"]
    np.testing.assert_allclose(impact.get_ydata(), values["impact_j"] * 1e3)
    assert ax.get_xscale() == "log"


def test_energies_accept_a_losses_value_for_the_five_keywords() -> None:
    from clearjoint import Joint

    joint = Joint(2.0, 1.06e-4, 8e7)
    pin = Pin.for_clearance(5e-3, 1.06e-4, 1e-2)
    keywords = dict(
        friction=Friction(0.1, 50.0),
        pin=pin,
        contact_friction_coefficient=0.2,
        restitution=0.7,
        damping_ratio=0.01,
    )
    amplitude = np.array([1e-6, 3e-6])
    by_keywords = ds.energies(joint, amplitude, **with_losses(keywords))  # type: ignore[arg-type]
    by_value = ds.energies(joint, amplitude, **with_losses(keywords))  # type: ignore[arg-type]
    for key, value in by_keywords.items():
        np.testing.assert_array_equal(by_value[key], value)
    np.testing.assert_array_equal(
        ds.total(joint, amplitude, **with_losses(keywords)),  # type: ignore[arg-type]
        ds.total(joint, amplitude, **with_losses(keywords)),  # type: ignore[arg-type]
    )


def test_comparison_tables_and_plot_carry_both_routes() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    result = ds.compare(
        joint(), 20000.0, 2 * math.pi * 100.0, losses=Losses(restitution=0.9, damping_ratio=0.01)
    )
    data = result.to_xarray()
    for key in result.exact:
        assert float(data["exact"].sel(energy=key)) == result.exact[key]
        assert float(data["closed"].sel(energy=key)) == result.closed[key]
        assert float(data["gap"].sel(energy=key)) == result.gap[key]
    assert data["exact"].attrs["units"] == "J"
    assert data["penetration"].attrs["units"] == "m"
    table = result.to_pandas()
    assert table.loc["impact_j", "exact_j"] == result.exact["impact_j"]
    text = repr(result)
    assert text.startswith("Comparison(A = ")
    assert "{" not in text
    assert len(text) < 200
    _, ax = plt.subplots()
    assert result.plot(ax) is ax
    assert len(ax.patches) == 2 * len(result.exact)
    plt.close("all")


def test_agreement_map_tables_and_plot() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    omega = 2 * math.pi * np.array([100.0, 200.0])
    force = np.array([1.0, 2.0, 3.0])
    gap = np.array([[0.1, -0.2, np.nan], [0.05, 0.0, 0.3]])
    amap = ds.AgreementMap(omega, force, np.full((2, 3), 1e-6), {"total_j": gap})
    data = amap.to_xarray()
    np.testing.assert_array_equal(data["gap_total_j"].values, gap)
    np.testing.assert_array_equal(data["force"].values, force)
    assert data["penetration"].attrs["units"] == "m"
    assert data["omega"].attrs["units"] == "rad/s"
    table = amap.to_pandas()
    assert table.loc[(omega[1], 3.0), "gap_total_j"] == 0.3
    assert "2 x 3 grid" in repr(amap)
    assert "array" not in repr(amap)
    _, ax = plt.subplots()
    assert amap.plot(ax) is ax
    np.testing.assert_array_equal(np.ma.filled(ax.collections[0].get_array(), np.nan), gap.T)
    plt.close("all")
