"""Coulomb friction in a structure's joints under harmonic balance (MODEL.md 5.2-5.3).

Checked by independent routes: the one-DOF Joint's HB (a separate setup of the same
equation), scipy's solve_ivp on the same regularised ODE (steady state and a
finite-difference monodromy), the exact piecewise monodromy without friction, and
the exact stick-slip orbits of :func:`clearjoint.periodic.periodic_orbit`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from clearjoint import ClearanceJoint, Friction, Joint, Losses, ParameterError
from clearjoint.harmonic import HarmonicError, frequency_response, nonlinear_modes
from clearjoint.harmonic.aft import Basis
from clearjoint.harmonic.check import check_orbits
from clearjoint.harmonic.monodromy import integrated_monodromy, monodromy
from clearjoint.harmonic.system import LinearSystem, build
from clearjoint.periodic import periodic_orbit
from clearjoint.stiffness import viscous_coefficient
from clearjoint.structure import Structure, chain

GAP, K_C, K_0 = 1e-4, 1e6, 1e5
LIGHT = Friction(coefficient=0.2, lateral_load=20.0)  # 4 N: slips all the time
FORCE = np.array([0.0, 100.0])


def _law(friction: Friction | None) -> ClearanceJoint:
    return ClearanceJoint(
        clearance=GAP, compression_stiffness=K_C, gap_stiffness=K_0, friction=friction
    )


@pytest.fixture(scope="module")
def two_links() -> Structure:
    """Two 1 kg masses on rigid links, each through a 0.1 mm joint with 4 N of friction."""
    return chain([1.0, 1.0], [math.inf] * 2, [_law(LIGHT)] * 2, dampers=[50.0, 50.0])


def _regularised_rhs(model: LinearSystem, force: np.ndarray, omega: float):  # type: ignore[no-untyped-def]
    """M u'' + C u' + K u + sum_j b_j (f_j(b_j u) + mu_s P tanh(b_j u' / v_eps)) = F sin(w t)."""
    n = model.n_dof
    b = model.directions
    inv_m = 1.0 / np.diag(model.mass)
    assert model.friction_force is not None

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        u, v = y[:n], y[n:]
        d = b @ u
        law = model.k0 * d + model.k_c * np.maximum(d - model.g_c, 0.0)
        law += model.k_t * np.minimum(d + model.g_t, 0.0)
        rub = model.friction_force * np.tanh((b @ v) / model.friction_speed)
        load = force * math.sin(omega * t) - model.damping @ v - model.stiffness @ u
        return np.concatenate((v, inv_m * (load - b.T @ (law + rub))))

    return rhs


def test_one_joint_chain_is_the_joints_harmonic_balance() -> None:
    """A one-link rigid chain with a rubbing joint gives the Joint's HB curve (item 3a)."""
    joint = Joint(mass=1.0, clearance=GAP, compression_stiffness=K_C, gap_stiffness=K_0)
    zeta = 0.02
    s = chain([1.0], [math.inf], [_law(LIGHT)], dampers=[viscous_coefficient(joint, zeta)])
    kw = {"harmonics": 7, "max_points": 12}
    a = frequency_response(
        joint, 100.0, 600.0, 900.0, losses=Losses(damping_ratio=zeta, friction=LIGHT), **kw
    )
    b = frequency_response(s, np.array([100.0]), 600.0, 900.0, **kw)
    assert a.omega.size == b.omega.size == 12
    assert b.coefficients is not None
    assert a.coefficients is not None
    np.testing.assert_allclose(b.omega, a.omega, rtol=1e-8)
    scale = float(np.max(np.abs(a.coefficients)))
    assert np.max(np.abs(b.coefficients[:, :, 0] - a.coefficients)) < 1e-8 * scale
    assert np.max(a.amplitude) > 2.0 * GAP  # the joint reaches contact on this stretch
    assert "orbit_check" not in b.settings  # no exact structure motion with friction
    assert not [e for e in b.events if e.kind == "untrusted"]  # it slides, never sticks


@pytest.mark.parametrize("omega", [500.0, 1100.0, 1300.0])
def test_steady_states_agree_with_solve_ivp_of_the_regularised_ode(
    two_links: Structure, omega: float
) -> None:
    """HB (H = 9) against 30 periods of solve_ivp on the same regularised ODE (item 3b).

    Started from the HB state, the integration stays on it (these orbits are stable),
    so the last period's extremes measure the HB truncation error: below 0.5 % of the
    amplitude here (observed 0.004-0.03 %). Both joints go beyond a gap edge.
    """
    fr = frequency_response(two_links, FORCE, omega, 1.001 * omega, harmonics=9, max_points=2)
    assert fr.stable[0]
    model = build(two_links, None, 1e-3 * omega * GAP)  # the default v_eps
    period = 2.0 * math.pi / omega
    times = np.linspace(29.0 * period, 30.0 * period, 1025)
    sol = solve_ivp(
        _regularised_rhs(model, FORCE, omega),
        (0.0, 30.0 * period),
        fr.initial_state[0],
        method="DOP853",
        rtol=1e-9,
        atol=1e-13,
        t_eval=times,
    )
    assert sol.success
    u = sol.y[:2]
    scale = float(np.max(np.abs(u)))
    assert np.max(np.abs(u.max(axis=1) - fr.x_max[0])) < 5e-3 * scale
    assert np.max(np.abs(u.min(axis=1) - fr.x_min[0])) < 5e-3 * scale
    assert np.all(np.max(np.abs(model.directions @ u), axis=1) > 0.5 * GAP)


def test_integrated_monodromy_is_the_exact_one_without_friction() -> None:
    """No friction: the integrated monodromy equals the exact product of exponentials."""
    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5)
    s = chain([1.0, 1.0, 1.0], [1e6] * 3, [j] * 3, dampers=[150.0] * 3)
    force = np.array([0.0, 0.0, 40.0])
    fr = frequency_response(s, force, 400.0, 400.4, harmonics=7, max_points=2, check_points=0)
    model = build(s, None)
    basis = Basis.make(7, int(fr.settings["samples"]))
    assert fr.coefficients is not None
    coef = fr.coefficients[0]
    exact = monodromy(model, basis, coef, 400.0)
    found = integrated_monodromy(model, basis, coef, 400.0)
    scale = np.concatenate((np.ones(3), np.full(3, 400.0)))
    assert np.max(np.abs((found - exact) * scale[None, :] / scale[:, None])) < 1e-7
    assert np.max(np.abs(coef @ model.directions.T)) > j.compression_gap  # contact


def test_multipliers_with_friction_match_a_finite_difference_monodromy(
    two_links: Structure,
) -> None:
    """With friction: the HB curve's multipliers against d(flow)/d(state) of solve_ivp.

    A smooth regularisation (v_eps = 0.05 w c) and H = 9 make the HB orbit close to a
    true orbit of the regularised ODE (it closes to 1e-3 of its state), so the two
    monodromies linearise about nearly the same orbit.
    """
    omega = 1000.0
    v_eps = 0.05 * omega * GAP
    fr = frequency_response(
        two_links,
        FORCE,
        omega,
        1.001 * omega,
        harmonics=9,
        samples=128,
        max_points=2,
        friction_regularization=v_eps,
    )
    model = build(two_links, None, v_eps)
    rhs = _regularised_rhs(model, FORCE, omega)
    period = 2.0 * math.pi / omega

    def flow(x: np.ndarray) -> np.ndarray:
        sol = solve_ivp(rhs, (0.0, period), x, method="DOP853", rtol=1e-12, atol=1e-16)
        return np.asarray(sol.y[:, -1])

    x0 = fr.initial_state[0]
    scale = np.concatenate((np.full(2, GAP), np.full(2, GAP * omega)))
    assert np.max(np.abs(flow(x0) - x0) / scale) < 1e-2
    phi = np.empty((4, 4))
    for k in range(4):
        e = np.zeros(4)
        e[k] = 1e-4 * scale[k]
        phi[:, k] = (flow(x0 + e) - flow(x0 - e)) / (2.0 * e[k])
    mu = np.linalg.eigvals(phi)
    hb = fr.multipliers[0]
    assert np.max(np.abs(np.sort_complex(mu) - np.sort_complex(hb))) < 5e-3
    # an unstable orbit (abs(mu) = 1.11): both verdicts agree
    assert np.max(np.abs(hb)) > 1.05
    assert np.max(np.abs(mu)) > 1.05


@pytest.mark.parametrize(
    ("lateral_load", "omega", "bound"),
    [(20.0, 600.0, 2e-3), (20.0, 1200.0, 2e-3), (350.0, 900.0, 0.15), (350.0, 1200.0, 0.15)],
)
def test_regularisation_error_against_the_exact_stick_slip_orbit(
    lateral_load: float, omega: float, bound: float
) -> None:
    """One rubbing joint: HB (H = 9, default v_eps) amplitude vs the exact orbit (item 3c).

    4 N of friction (always slipping): within 0.2 % (observed 0.02-0.12 %); 70 N (the
    exact orbit sticks, 1.1-1.5 ms per period): within 15 % (observed 11.5-11.6 %), and
    the HB points are flagged "untrusted" (the joint sticks); the numbers quoted in
    docs/harmonic.md.
    """
    rub = Friction(coefficient=0.2, lateral_load=lateral_load)
    joint = Joint(mass=1.0, clearance=GAP, compression_stiffness=K_C, gap_stiffness=K_0)
    zeta = 0.02
    s = chain([1.0], [math.inf], [_law(rub)], dampers=[viscous_coefficient(joint, zeta)])
    fr = frequency_response(
        s, np.array([100.0]), omega, 1.001 * omega, harmonics=9, samples=128, max_points=2
    )
    exact = periodic_orbit(joint, 100.0, omega, losses=Losses(damping_ratio=zeta, friction=rub))
    a_exact = 0.5 * (exact.cycle.x_max - exact.cycle.x_min)
    error = abs(fr.amplitude[0, 0] / a_exact - 1.0)
    assert error < bound
    assert fr.stable[0]
    assert exact.stable
    untrusted = [e for e in fr.events if e.kind == "untrusted"]
    if lateral_load > 100.0:
        assert exact.cycle.stick_time > 0.0  # the stick-slip case
        assert error > 0.01  # the regularisation's error is visible there
        assert untrusted  # and HB flags the sticking
        assert "it sticks" in untrusted[0].note
    else:
        assert exact.cycle.stick_time == 0.0
        assert not untrusted


def test_what_is_still_refused(two_links: Structure) -> None:
    """Friction over the free-play stroke and the exact orbit check."""
    stroke = _law(Friction(coefficient=0.2, lateral_load=20.0, region="free-play"))
    s = chain([1.0], [math.inf], [stroke])
    with pytest.raises(HarmonicError, match=r"free-play stroke only.*member 0"):
        frequency_response(s, np.array([100.0]), 600.0, 610.0)
    with pytest.raises(HarmonicError, match=r"free-play stroke only.*member 0"):
        nonlinear_modes(s, 1, [1e-4])
    fr = frequency_response(two_links, FORCE, 1000.0, 1001.0, max_points=2)
    with pytest.raises(HarmonicError, match=r"check_orbits cannot check.*friction"):
        check_orbits(fr)
    with pytest.raises(ParameterError, match="friction_regularization"):
        frequency_response(two_links, FORCE, 1000.0, 1001.0, friction_regularization=0.0)
