"""fit.py: the laws recover known coefficients from noisy data, within their own errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import fit


def grid(seed: int = 3, n: int = 60) -> tuple[np.ndarray, np.ndarray, np.random.Generator]:
    rng = np.random.default_rng(seed)
    omega = 2 * math.pi * rng.choice([20.0, 40.0, 60.0, 80.0, 100.0], n)
    amplitude = rng.uniform(10e-6, 90e-6, n)
    return omega, amplitude, rng


def test_eq19_recovers_its_coefficients_within_their_confidence_intervals() -> None:
    omega, amplitude, rng = grid()
    truth = (1500.0, 1.1e10, 5.1e7)
    k = truth[0] * omega + truth[1] * amplitude + truth[2] + rng.normal(0, 5e4, omega.size)
    law = fit.stiffness_law(omega, amplitude, k)
    for value, error, true in zip(law.values, law.errors, truth, strict=True):
        assert abs(value - true) < 3 * error
    assert law.r_squared > 0.97
    assert law.residuals.shape == omega.shape
    # Fig. 9's normalisation, by hand
    f_part, a_part = fit.normalised_coefficients(law, omega, amplitude, k)
    assert f_part == pytest.approx(law.values[0] * omega.mean() / k.mean())
    assert a_part == pytest.approx(law.values[1] * amplitude.mean() / k.mean())


def test_standard_errors_match_the_scatter_over_many_noisy_samples() -> None:
    omega, amplitude, _ = grid(n=40)
    rng = np.random.default_rng(7)
    slopes, errors = [], []
    for _ in range(300):
        k = 2000.0 * omega + 1e10 * amplitude + 5e7 + rng.normal(0, 1e5, omega.size)
        law = fit.stiffness_law(omega, amplitude, k)
        slopes.append(law.values[0])
        errors.append(law.errors[0])
    assert np.std(slopes) == pytest.approx(np.mean(errors), rel=0.15)


def test_eq20_gives_back_the_joint_in_series_and_carries_the_uncertainty() -> None:
    omega, amplitude, rng = grid()
    k_dn = 200.0 * omega + 3e9 * amplitude + 7e7  # the beam
    k_joint = 2e8
    k_d = 1 / (1 / k_dn + 1 / k_joint)
    noise = 2e4
    jointed = fit.stiffness_law(omega, amplitude, k_d + rng.normal(0, noise, omega.size))
    beam = fit.stiffness_law(omega, amplitude, k_dn + rng.normal(0, noise, omega.size))
    result = fit.joint_stiffness(jointed, beam, omega, amplitude)
    # the series relation is not linear in (w, A), so eq 19 is an approximation: a few %
    np.testing.assert_allclose(result.value, k_joint, rtol=0.03)
    assert np.all(result.error > 0)
    # first-order propagation by hand at one point, from the two laws' covariances
    w, a = omega[0], amplitude[0]
    x = np.array([w, a, 1.0])
    kd, kn = x @ jointed.values, x @ beam.values
    d_kd = kn**2 / (kn - kd) ** 2
    d_kn = -(kd**2) / (kn - kd) ** 2
    var = d_kd**2 * x @ jointed.covariance @ x + d_kn**2 * x @ beam.covariance @ x
    assert result.error[0] == pytest.approx(math.sqrt(var), rel=1e-6)
    swapped = fit.joint_stiffness(beam, jointed, omega[:3], amplitude[:3])
    assert np.all(np.isnan(swapped.value))  # k_dn <= k_d: undefined


def test_eq21_and_eq22_recover_known_laws() -> None:
    omega, amplitude, rng = grid(n=80)
    clearance = rng.choice([0.106e-3, 0.196e-3], omega.size)
    d = (-4.5, 1.5e-3, 8e3)
    e = (3e4, -5.0, -4e7)
    ln_e = (
        d[0]
        + d[1] * omega
        + d[2] * clearance
        + (e[0] + e[1] * omega + e[2] * clearance) * amplitude
    )
    energy = np.exp(ln_e + rng.normal(0, 0.02, omega.size))
    law = fit.dissipation_law(omega, clearance, amplitude, energy)
    for value, error, true in zip(law.values, law.errors, (*d, *e), strict=True):
        assert abs(value - true) < 3.5 * error
    alternative = fit.power_law(omega, clearance, amplitude, energy)
    assert law.aic < alternative.aic  # the stated criterion picks the true form
    np.testing.assert_allclose(
        fit.evaluate_dissipation_law(law, omega, clearance, amplitude), energy, rtol=0.1
    )
    one = omega == omega[0]
    exp_law = fit.exponential_law(
        amplitude[one & (clearance == clearance[0])], energy[one & (clearance == clearance[0])]
    )
    assert exp_law.values[1] == pytest.approx(e[0] + e[1] * omega[0] + e[2] * clearance[0], rel=0.1)


def test_power_law_wins_when_the_data_follow_it() -> None:
    omega, amplitude, rng = grid(n=80)
    clearance = rng.choice([0.106e-3, 0.196e-3], omega.size)
    energy = np.exp(
        -1.0
        + 0.8 * np.log(omega)
        + 1.5 * np.log(amplitude)
        - 2e3 * clearance
        + rng.normal(0, 0.02, omega.size)
    )
    assert (
        fit.power_law(omega, clearance, amplitude, energy).aic
        < fit.dissipation_law(omega, clearance, amplitude, energy).aic
    )


def test_refuses_too_few_points_and_singular_designs() -> None:
    with pytest.raises(fit.FitError, match="3 points for 3 coefficients"):
        fit.stiffness_law([1.0, 2.0, 3.0], [1.0, 2.0, 4.0], [1.0, 2.0, 3.0])
    with pytest.raises(fit.FitError, match="singular design"):
        fit.stiffness_law([5.0] * 6, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0], [1.0] * 6)
    with pytest.raises(fit.FitError, match="NaN"):
        fit.stiffness_law([1.0, 2.0, 3.0, 4.0, math.nan], [1.0] * 5, [1.0] * 5)
    with pytest.raises(fit.FitError, match="energies must be > 0"):
        fit.exponential_law([1.0, 2.0, 3.0], [1.0, 0.0, 2.0])


def test_each_law_is_evaluated_through_its_own_design() -> None:
    omega, amplitude, rng = grid(n=40)
    clearance = rng.choice([0.106e-3, 0.196e-3], omega.size)
    energy = np.exp(-3.0 + 2e-3 * omega + 4e4 * amplitude + rng.normal(0, 0.01, omega.size))
    exp_law = fit.exponential_law(amplitude, energy)
    np.testing.assert_allclose(
        fit.evaluate_exponential_law(exp_law, amplitude),
        np.exp(exp_law.values[0]) * np.exp(exp_law.values[1] * amplitude),
    )
    power = fit.power_law(omega, clearance, amplitude, energy)
    g0, g1, g2, g3 = power.values
    np.testing.assert_allclose(
        fit.evaluate_power_law(power, omega, clearance, amplitude),
        np.exp(g0) * omega**g1 * amplitude**g2 * np.exp(g3 * clearance),
    )
    k = 2e3 * omega + 1e10 * amplitude + 5e7
    law = fit.stiffness_law(omega, amplitude, k)
    assert fit.evaluate_stiffness_law(law, 100.0, 20e-6) == pytest.approx(
        2e3 * 100.0 + 1e10 * 20e-6 + 5e7
    )


def test_slope_and_its_standard_error_by_hand() -> None:
    omega, amplitude, rng = grid(n=50)
    clearance = rng.choice([0.106e-3, 0.196e-3], omega.size)
    energy = np.exp(-4.0 + 1e-3 * omega - 3e3 * clearance + 2e4 * amplitude)
    energy *= np.exp(rng.normal(0, 0.03, omega.size))
    law = fit.dissipation_law(omega, clearance, amplitude, energy)
    a = 40e-6
    value, error = fit.slope(law, [0, 0, 1, 0, 0, a])  # d ln E / dc at A
    assert value == pytest.approx(law.values[2] + a * law.values[5])
    var = law.covariance[2, 2] + a * a * law.covariance[5, 5] + 2 * a * law.covariance[2, 5]
    assert error == pytest.approx(math.sqrt(var))
    with pytest.raises(fit.FitError, match="3 weights"):
        fit.slope(law, [1, 0, 0])


def test_quadratic_check_sees_saturation_and_a_first_fall() -> None:
    omega, amplitude, rng = grid(n=60)
    saturating = 1.0 - np.exp(-amplitude / 30e-6) + rng.normal(0, 1e-3, omega.size)
    law = fit.quadratic_law(amplitude, omega, saturating)
    assert law.values[2] < -3 * law.errors[2]  # the rate of increase falls
    falling_first = (omega - 400.0) ** 2 * 1e-3 + rng.normal(0, 1.0, omega.size)
    law = fit.quadratic_law(omega, amplitude, falling_first)
    first, error = fit.slope(law, [0, 1, 2 * omega.min(), 0])
    assert first < -3 * error
    np.testing.assert_allclose(
        fit.evaluate_quadratic_law(law, omega, amplitude), falling_first, atol=5.0
    )
