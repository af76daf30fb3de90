"""Harmonic balance with AFT (MODEL.md 5.3): basis, exact Jacobian, bad input, convergence."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import Friction, Joint, Losses
from clearjoint.harmonic import HarmonicError, aft, solve, system
from clearjoint.periodic import periodic_orbit

#: pyHarm's SDOF clearance case (issue 10): m = 1, c_v = 0.05, k0 = 1, edges +-0.1745, +3.
PYHARM = Joint(mass=1.0, clearance=2 * 0.1745, compression_stiffness=3.0, gap_stiffness=1.0)
PYHARM_ZETA = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 2 zeta sqrt(m k_c) = 0.05


def _finite_difference(fun, q: np.ndarray, step: float) -> np.ndarray:  # type: ignore[no-untyped-def]
    cols = []
    for i in range(q.size):
        dq = np.zeros_like(q)
        dq[i] = step
        cols.append((fun(q + dq) - fun(q - dq)) / (2.0 * step))
    return np.array(cols).T


def test_basis_round_trip_and_derivative() -> None:
    basis = aft.Basis.make(5, 64)
    np.testing.assert_allclose(basis.to_coefficients @ basis.to_time, np.eye(11), atol=1e-14)
    rng = np.random.default_rng(1)
    coef = rng.normal(size=11)
    tau = np.linspace(0.0, 2.0 * math.pi, 7)
    # d/dtau by the operator against a central difference of the series
    h = 1e-6
    numeric = (basis.evaluate(coef, tau + h) - basis.evaluate(coef, tau - h)) / (2 * h)
    np.testing.assert_allclose(basis.evaluate(basis.derivative @ coef, tau), numeric, atol=1e-7)
    # extremes against a dense grid
    grid = basis.evaluate(coef, np.linspace(0.0, 2.0 * math.pi, 200_001))
    top, bottom = basis.extremes(coef[:, None])
    assert top[0] == pytest.approx(grid.max(), abs=1e-9)
    assert bottom[0] == pytest.approx(grid.min(), abs=1e-9)


@pytest.mark.parametrize(("offset", "friction"), [(0.0, None), (0.03, Friction(0.02, 1.0))])
def test_jacobian_matches_finite_differences(offset: float, friction: Friction | None) -> None:
    joint = Joint(
        mass=1.5,
        clearance=0.2,
        compression_stiffness=3.0,
        tension_stiffness=2.0,
        gap_stiffness=0.5,
        gap_offset=offset,
    )
    model = system.from_joint(joint, Losses(damping_ratio=0.02, friction=friction), 0.05)
    basis = aft.Basis.make(6, 128)
    rng = np.random.default_rng(7)
    q = 0.1 * rng.normal(size=13)
    q[1] = 0.3  # well into both contacts
    omega, force = 1.1, np.array([0.05])
    ev = aft.evaluate(model, basis, q, omega, force)
    numeric = _finite_difference(
        lambda x: aft.evaluate(model, basis, x, omega, force).residual, q, 1e-7
    )
    np.testing.assert_allclose(ev.jacobian, numeric, atol=1e-7)
    d_omega = (
        aft.evaluate(model, basis, q, omega + 1e-7, force).residual
        - aft.evaluate(model, basis, q, omega - 1e-7, force).residual
    ) / 2e-7
    np.testing.assert_allclose(ev.d_omega, d_omega, atol=1e-7)


def test_bad_harmonics_and_samples() -> None:
    with pytest.raises(HarmonicError, match="harmonics must be an integer >= 1"):
        aft.check_harmonics(0, None)
    with pytest.raises(HarmonicError, match=r"samples must be an integer >= 2 \(2H \+ 1\) = 30"):
        aft.check_harmonics(7, 29)
    assert aft.check_harmonics(7, None) == (7, 512)


def test_restitution_and_friction_are_refused_with_a_pointer() -> None:
    with pytest.raises(HarmonicError, match=r"clearjoint\.periodic"):
        system.build(PYHARM, Losses(restitution=0.8))
    with pytest.raises(HarmonicError, match=r"clearjoint\.periodic"):
        system.build(PYHARM, Losses(friction=Friction(0.1, 1.0, "free-play")), 1e-3)


def _hb_orbit(harmonics: int, omega: float, guess: np.ndarray) -> tuple[np.ndarray, aft.Basis]:
    model = system.from_joint(PYHARM, Losses(damping_ratio=PYHARM_ZETA))
    h, n_t = aft.check_harmonics(harmonics, None)
    basis = aft.Basis.make(h, n_t)
    q0 = np.zeros(2 * h + 1)
    q0[: min(guess.size, q0.size)] = guess[: q0.size]

    def function(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ev = aft.evaluate(model, basis, q, omega, np.array([0.03]))
        return ev.residual, ev.jacobian

    found = solve.newton(function, q0, 0.1)
    assert found is not None
    return found[0], basis


def test_harmonic_balance_converges_to_the_exact_orbit() -> None:
    """HB x_max tends to the exact shooting orbit's as H grows (upper branch, omega = 1.3)."""
    omega = 1.3
    guess = np.array([0.0, -0.3, 0.1])
    errors = []
    exact = None
    for h in (3, 7, 15, 31):
        q, basis = _hb_orbit(h, omega, guess)
        guess = q
        if exact is None:
            x0 = q[0] + q[1::2].sum()
            v0 = omega * float(np.arange(1, h + 1) @ q[2::2])
            exact = periodic_orbit(
                PYHARM, 0.03, omega, losses=Losses(damping_ratio=PYHARM_ZETA), initial=(x0, v0)
            )
            assert exact.x_max > PYHARM.compression_gap  # a contacting orbit
        top, _ = basis.extremes(q[:, None])
        errors.append(abs(top[0] - exact.x_max) / exact.amplitude)
    assert errors[0] > 1e-4  # truncation is visible at H = 3 ...
    assert errors[2] < 5e-5  # ... and small at 15
    assert errors[3] < errors[1] / 10.0


@pytest.mark.parametrize(("harmonics", "samples"), [(1, 6), (4, 18), (12, 512), (32, 130)])
def test_fft_products_equal_the_dense_dft_product(harmonics: int, samples: int) -> None:
    """P diag(v) E from 2 (2H + 1) moments equals the dense triple product (H = 32 gathers)."""
    basis = aft.Basis.make(harmonics, samples)
    values = np.random.default_rng(harmonics).normal(size=(samples, 3))
    blocks = basis.products(values)
    for j in range(3):
        dense = (basis.to_coefficients * values[:, j]) @ basis.to_time
        np.testing.assert_allclose(blocks[j], dense, atol=1e-13)


def _sdof(stiffness: float, mass: float, damping: float) -> system.LinearSystem:
    one = np.ones((1, 1))
    return system.LinearSystem(
        mass=mass * one,
        damping=damping * one,
        stiffness=stiffness * one,
        directions=one.copy(),
        k0=np.zeros(1),
        k_c=np.zeros(1),
        k_t=np.zeros(1),
        g_c=np.ones(1),
        g_t=np.ones(1),
        dof_names=["x"],
        is_joint=True,
        source=None,
    )


@pytest.mark.parametrize("omega", [0.05, 0.7, 1.0, 1.9, 2.0, 3.3])
def test_hill_determinant_is_exact_for_constant_stiffness(omega: float) -> None:
    """k(t) = k: multipliers exp(lambda T), lambda = -c/2m +- i sqrt(k/m - (c/2m)^2), any w
    (w = 1 and 2 put a = sqrt(k/m)/w on an integer, where the normalised determinant has poles)."""
    m, c, k = 2.0, 0.3, 2.0
    model = _sdof(k, m, c)
    basis = aft.Basis.make(12, 64)
    jac = aft.linear_jacobian(model, basis, omega, model.damping)
    mu = aft.hill_determinant_multipliers(model, basis, jac[None], np.array([omega]))[0]
    lam = -c / (2 * m) + 1j * math.sqrt(k / m - (c / (2 * m)) ** 2)
    t = 2 * math.pi / omega
    exact = np.exp(np.array([lam, lam.conjugate()]) * t)
    np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(exact), atol=1e-9)


def mathieu(omega: float) -> tuple[system.LinearSystem, aft.Basis, np.ndarray, np.ndarray]:
    """The damped Mathieu-like case k(t) = k (1 + 0.6 cos w t + 0.3 sin 2 w t), m = 1,
    c = 0.1, k = 0.5: its one-DOF model, an H = 12 basis (128 samples), the HB Jacobian of
    the time-varying stiffness, and the exact multipliers from the monodromy matrix
    integrated by scipy's solve_ivp (no clearjoint code in that route)."""
    from scipy.integrate import solve_ivp

    m, c, k = 1.0, 0.1, 0.5
    model = _sdof(0.0, m, c)
    basis = aft.Basis.make(12, 128)
    tau = 2 * math.pi * np.arange(128) / 128

    def stiffness(t: float | np.ndarray) -> float | np.ndarray:
        return k * (1 + 0.6 * np.cos(omega * t) + 0.3 * np.sin(2 * omega * t))

    jac = aft.linear_jacobian(model, basis, omega, model.damping)
    aft.add_joint_blocks(jac, basis.products(stiffness(tau / omega)[:, None]), np.ones((1, 1)))
    period = 2 * math.pi / omega
    columns = []
    for start in ([1.0, 0.0], [0.0, 1.0]):
        sol = solve_ivp(
            lambda t, y: [y[1], -(c * y[1] + stiffness(t) * y[0]) / m],
            (0.0, period),
            start,
            rtol=1e-11,
            atol=1e-12,
        )
        columns.append(sol.y[:, -1])
    return model, basis, jac, np.linalg.eigvals(np.array(columns).T)


@pytest.mark.parametrize("omega", [0.8, 1.0, 1.3, 2.2])
def test_hill_determinant_matches_the_integrated_monodromy(omega: float) -> None:
    """Damped Mathieu-like k(t) = k (1 + 0.6 cos w t + 0.3 sin 2 w t): Hill's determinant
    (H = 12) against the monodromy matrix integrated by scipy's solve_ivp; w = 1 and 1.3 lie
    in instability tongues (real multipliers < -1). The truncated determinant converges as
    H^-3 here (2e-5 at H = 12, 3e-7 at 48); at w = 1.3 the eigenvalue route's imaginary-part
    criterion keeps one Floquet exponent twice (two tie at Im = w / 2) and misses -0.51."""
    model, basis, jac, exact = mathieu(omega)
    mu = aft.hill_determinant_multipliers(model, basis, jac[None], np.array([omega]))[0]
    np.testing.assert_allclose(np.sort_complex(mu), np.sort_complex(exact), atol=5e-5)
    assert (np.max(np.abs(mu)) > 1.0) == (np.max(np.abs(exact)) > 1.0)


def test_hill_determinant_agrees_with_hills_eigenproblem() -> None:
    """On orbits in and out of contact the two Hill routes (same truncation) agree."""
    model = system.from_joint(PYHARM, Losses(damping_ratio=PYHARM_ZETA))
    basis = aft.Basis.make(12, 512)
    for omega, guess in ((1.3, [0.0, -0.3, 0.1]), (0.6, [0.0, 0.05, 0.0])):
        q, _ = _hb_orbit(12, omega, np.array(guess))
        ev = aft.evaluate(model, basis, q, omega, np.array([0.03]))
        by_det = aft.hill_determinant_multipliers(
            model, basis, ev.jacobian[None], np.array([omega])
        )
        by_eig = aft.hill_multipliers(aft.hill_exponents(model, basis, ev.jacobian, omega), omega)
        np.testing.assert_allclose(np.abs(by_det[0]), np.abs(by_eig), rtol=1e-3)


def test_compiled_one_dof_path_equals_the_general_one() -> None:
    """evaluate's compiled one-DOF path (H <= 31) and the general numpy path agree."""
    import dataclasses

    joint = Joint(
        mass=1.5,
        clearance=0.2,
        compression_stiffness=3.0,
        tension_stiffness=2.0,
        gap_stiffness=0.5,
        gap_offset=0.03,
    )
    model = system.from_joint(joint, Losses(damping_ratio=0.02))
    basis = aft.Basis.make(6, 128)
    general = dataclasses.replace(basis, assemble=None)  # forces the numpy path
    q = 0.1 * np.random.default_rng(3).normal(size=13)
    q[1] = 0.3
    fast = aft.evaluate(model, basis, q, 1.1, np.array([0.05]), negative_damping=0.01)
    slow = aft.evaluate(model, general, q, 1.1, np.array([0.05]), negative_damping=0.01)
    for a, b in zip(
        (fast.residual, fast.jacobian, fast.d_omega, fast.tangent),
        (slow.residual, slow.jacobian, slow.d_omega, slow.tangent),
        strict=True,
    ):
        np.testing.assert_allclose(a, b, atol=1e-13)
