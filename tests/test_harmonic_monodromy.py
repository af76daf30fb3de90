"""Floquet multipliers of HB orbits of structures (harmonic/monodromy.py), by independent routes."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from clearjoint import ClearanceJoint
from clearjoint.harmonic import aft, frequency_response, monodromy
from clearjoint.harmonic.system import build
from clearjoint.structure import Structure, chain, time_response

FORCE = np.array([0.0, 0.0, 40.0])


@pytest.fixture(scope="module")
def three_links() -> Structure:
    """Three 1 kg masses on 1 MN/m links, each with a 0.1 mm joint, dashpots across."""
    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    return chain([1.0, 1.0, 1.0], [1e6] * 3, [j] * 3, dampers=[150.0] * 3)


def _state_at_period(structure: Structure, omega: float, start: np.ndarray) -> np.ndarray:
    """(u(T), u'(T)) of the exact event-driven motion from ``start`` = (u(0), u'(0))."""
    n = structure.n_dof
    period = 2.0 * math.pi / omega
    motion = time_response(
        structure, FORCE, omega, 2.0 * period, initial=(start[:n], start[n:]), samples_per_period=8
    )
    assert motion.t[8] == pytest.approx(period, rel=1e-12)
    return np.concatenate((motion.u[8], motion.v[8]))


def test_open_orbit_has_the_linear_systems_multipliers(three_links: Structure) -> None:
    """An orbit inside every gap: Phi = expm(A T), multipliers exp(lambda T) of the open system."""
    small = FORCE * 1e-3
    omega = 150.0
    fr = frequency_response(three_links, small, omega, 1.001 * omega, harmonics=5, max_points=2)
    model = build(three_links, 0.0, None, 1.0)
    n = model.n_dof
    k_open = model.open_stiffness()
    inv_m = np.linalg.inv(model.mass)
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-inv_m @ k_open, -inv_m @ model.damping]])
    expected = np.exp(np.linalg.eigvals(a) * 2.0 * math.pi / omega)
    np.testing.assert_allclose(
        np.sort(np.abs(fr.multipliers[0])), np.sort(np.abs(expected)), rtol=1e-9, atol=1e-15
    )
    assert monodromy.crossings(model, aft.Basis.make(5, 64), fr.coefficients[0]).size == 0


@pytest.mark.parametrize("omega", [200.0, 300.0, 600.0])
def test_multipliers_match_the_exact_flows_finite_difference_monodromy(
    three_links: Structure, omega: float
) -> None:
    """Phi of the HB orbit (H = 15) against the monodromy of the exact event-driven motion,
    by central differences of structure.time_response over one period from the HB state.
    The largest multipliers agree to the HB truncation (1.0e-3, 0 and 2.7e-4 measured at
    200, 300, 600 rad/s); 600 rad/s is unstable."""
    fr = frequency_response(three_links, FORCE, omega, 1.001 * omega, harmonics=15, max_points=2)
    x0 = fr.initial_state[0]
    scale = np.concatenate((np.full(3, 1e-4), np.full(3, 1e-4 * omega)))
    columns = []
    for i in range(6):
        e = np.zeros(6)
        e[i] = 1e-4 * scale[i]
        columns.append(
            (
                _state_at_period(three_links, omega, x0 + e)
                - _state_at_period(three_links, omega, x0 - e)
            )
            / (2.0 * e[i])
        )
    exact = np.linalg.eigvals(np.array(columns).T)
    largest_exact = float(np.max(np.abs(exact)))
    largest_hb = float(np.max(np.abs(fr.multipliers[0])))
    assert largest_hb == pytest.approx(largest_exact, rel=2e-3)
    assert (largest_hb > 1.0) == (largest_exact > 1.0) == (omega == 600.0)
    assert bool(fr.stable[0]) != (omega == 600.0)


def test_a_perturbed_stable_orbit_returns(three_links: Structure) -> None:
    """At 300 rad/s (stable by the monodromy) a kick of 30 % of the velocity amplitude dies out."""
    omega = 300.0
    fr = frequency_response(three_links, FORCE, omega, 1.001 * omega, harmonics=7, max_points=2)
    assert fr.stable[0]
    x0 = fr.initial_state[0].copy()
    x0[3:] *= 1.3
    motion = time_response(
        three_links,
        FORCE,
        omega,
        30 * 2 * math.pi / omega,
        initial=(x0[:3], x0[3:]),
        samples_per_period=64,
    )
    first = np.max(np.abs(motion.u[:64].max(axis=0) - fr.x_max[0]))
    last = np.max(np.abs(motion.u[-64:].max(axis=0) - fr.x_max[0]))
    assert last < 0.05 * first


def test_monodromy_equals_a_product_over_the_contact_patterns(three_links: Structure) -> None:
    """Phi against solve_ivp of the variational equation with the tangent read off the orbit."""
    from scipy.integrate import solve_ivp

    omega = 600.0
    fr = frequency_response(three_links, FORCE, omega, 1.001 * omega, harmonics=7, max_points=2)
    model = build(three_links, 0.0, None, 1.0)
    basis = aft.Basis.make(7, fr.settings["samples"])
    coef = fr.coefficients[0]
    phi = monodromy.monodromy(model, basis, coef, omega)
    b = model.directions
    inv_m = 1.0 / np.diag(model.mass)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        delta = basis.evaluate(coef @ b.T, np.array([omega * t]))[0]
        k = model.k0 + model.k_c * (delta > model.g_c) + model.k_t * (delta < -model.g_t)
        kt = model.stiffness + (b.T * k) @ b
        y = y.reshape(6, 6)
        return np.concatenate(
            (y[3:], -inv_m[:, None] * (kt @ y[:3] + model.damping @ y[3:]))
        ).ravel()

    cuts = monodromy.crossings(model, basis, coef) / omega
    assert cuts.size >= 2
    sol = solve_ivp(
        rhs,
        (0.0, 2 * math.pi / omega),
        np.eye(6).ravel(),
        rtol=1e-10,
        atol=1e-12,
        method="DOP853",
        t_eval=None,
        first_step=1e-7,
    )
    np.testing.assert_allclose(phi, sol.y[:, -1].reshape(6, 6), atol=1e-5 * np.max(np.abs(phi)))
    assert scipy.linalg.norm(phi) > 0.0
