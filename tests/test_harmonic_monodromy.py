"""Floquet multipliers of HB orbits of structures (harmonic/monodromy.py), by independent routes."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from clearjoint import ClearanceJoint
from clearjoint.errors import ParameterError
from clearjoint.harmonic import aft, frequency_response, monodromy
from clearjoint.harmonic.system import build
from clearjoint.structure import Structure, chain, time_response

FORCE = np.array([0.0, 0.0, 40.0])


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
    model = build(three_links, None)
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
    model = build(three_links, None)
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


# --- the eigen-decomposition product (monodromy.py, "Speed") against its references ---


def _chain_orbit(three_links: Structure, omega: float) -> tuple[object, aft.Basis, np.ndarray]:
    fr = frequency_response(three_links, FORCE, omega, 1.001 * omega, harmonics=7, max_points=2)
    assert fr.coefficients is not None
    basis = aft.Basis.make(7, fr.settings["samples"])
    return build(three_links, None), basis, fr.coefficients[0]


def _no_expm(*args: object, **kwargs: object) -> np.ndarray:
    raise AssertionError("scipy.linalg.expm called on a well-conditioned pattern")


@pytest.mark.parametrize("omega", [200.0, 300.0, 600.0])
def test_eigen_product_equals_the_expm_product(
    three_links: Structure, omega: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The default route (cached eigen-decompositions, no expm at all: expm is made to fail)
    gives the plain product of scipy.linalg.expm to 1e-10 relative, twice (the second call
    from the cache), and the same multipliers."""
    model, basis, coef = _chain_orbit(three_links, omega)
    reference = monodromy.monodromy(model, basis, coef, omega, method="expm")
    assert monodromy.crossings(model, basis, coef).size >= 2
    monodromy._FLOWS.clear()
    monkeypatch.setattr(scipy.linalg, "expm", _no_expm)
    for _ in range(2):
        phi = monodromy.monodromy(model, basis, coef, omega)
        error = np.linalg.norm(phi - reference) / np.linalg.norm(reference)
        assert error < 1e-10
    mu = np.linalg.eigvals(phi)
    mu_ref = np.linalg.eigvals(reference)
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(mu_ref)), rtol=1e-10)


def test_monodromy_against_solve_ivp_restarted_at_its_own_gap_edge_events(
    three_links: Structure,
) -> None:
    """Phi and the multipliers against an independent integration of the variational
    equation: DOP853 on M y'' + C y' + K_T(t) y = 0, with K_T read off the orbit's
    relative displacements and the integration stopped at each gap-edge crossing by
    solve_ivp's own events (no use of monodromy.crossings), to 1e-8 relative."""
    from scipy.integrate import solve_ivp

    omega = 600.0
    model, basis, coef = _chain_orbit(three_links, omega)
    phi = monodromy.monodromy(model, basis, coef, omega)
    b = model.directions
    rel = coef @ b.T
    inv_m = 1.0 / np.diag(model.mass)
    period = 2.0 * math.pi / omega

    def delta(t: float) -> np.ndarray:
        return basis.evaluate(rel, np.array([omega * t]))[0]

    def edge_event(j: int, level: float, direction: float) -> object:
        def event(t: float, y: np.ndarray) -> float:
            return float(delta(t)[j] - level)

        event.terminal = True  # type: ignore[attr-defined]
        event.direction = direction  # type: ignore[attr-defined]
        return event

    t, y = 0.0, np.eye(6).ravel()
    segments = 0
    while t < period:
        # this segment's tangent, read just after its start (constant until the next event),
        # and each edge's next crossing: downward where delta is above it now, else upward
        d = delta(t + 1e-9 * period)
        k = model.k0 + model.k_c * (d > model.g_c) + model.k_t * (d < -model.g_t)
        kt = model.stiffness + (b.T * k) @ b
        events = [
            edge_event(j, g, -1.0 if d[j] > g else 1.0)
            for j in range(3)
            for g in (model.g_c[j], -model.g_t[j])
        ]

        def rhs(_: float, z: np.ndarray, kt: np.ndarray = kt) -> np.ndarray:
            z = z.reshape(6, 6)
            return np.concatenate(
                (z[3:], -inv_m[:, None] * (kt @ z[:3] + model.damping @ z[3:]))
            ).ravel()

        sol = solve_ivp(rhs, (t, period), y, method="DOP853", rtol=1e-12, atol=1e-14, events=events)
        assert sol.success
        t, y = float(sol.t[-1]), sol.y[:, -1]
        segments += 1
    exact = y.reshape(6, 6)
    assert segments == monodromy.crossings(model, basis, coef).size + 1
    assert np.linalg.norm(phi - exact) / np.linalg.norm(exact) < 1e-8
    mu, mu_exact = np.linalg.eigvals(phi), np.linalg.eigvals(exact)
    np.testing.assert_allclose(np.sort(np.abs(mu)), np.sort(np.abs(mu_exact)), rtol=1e-8)
    assert float(np.max(np.abs(mu))) > 1.0  # 600 rad/s is the unstable point


def _free_end_chain() -> tuple[object, aft.Basis, np.ndarray]:
    """Two 1 kg masses, the outer held only by a joint with no gap stiffness and no damper:
    while that joint is open the outer mass is free, A has a Jordan block at 0 (defective)."""
    loose = ClearanceJoint(clearance=1e-4, compression_stiffness=1e6)
    s = chain([1.0, 1.0], [1e6, math.inf], [None, loose], dampers=[10.0, 0.0])
    model = build(s, None)
    basis = aft.Basis.make(3, 64)
    coef = np.zeros((7, 2))
    coef[1] = [0.0, 3e-4]  # the outer mass swings 0.3 mm: the joint opens and closes
    return model, basis, coef


def test_a_defective_pattern_falls_back_to_expm(monkeypatch: pytest.MonkeyPatch) -> None:
    """The open pattern of the free-end chain is refused by the decomposition (its V is
    singular); its segments take scipy.linalg.expm (counted), the closed ones do not; the
    product equals the plain expm product."""
    model, basis, coef = _free_end_chain()
    n = model.n_dof
    widths, states = monodromy._segments(model, basis, coef)
    is_open = np.all(states == 0, axis=1)
    assert is_open.any()
    assert (~is_open).any()
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, n:] = -model.damping / np.diag(model.mass)[:, None]
    a[n:, :n] = -monodromy._pattern_stiffness(model, states[np.argmax(is_open)])
    assert monodromy._decompose(a) is None
    a[n:, :n] = -monodromy._pattern_stiffness(model, states[np.argmin(is_open)])
    assert monodromy._decompose(a) is not None
    reference = monodromy.monodromy(model, basis, coef, 100.0, method="expm")
    calls = []
    expm = scipy.linalg.expm

    def counted(m: np.ndarray) -> np.ndarray:
        calls.append(1)
        return np.asarray(expm(m))

    monkeypatch.setattr(scipy.linalg, "expm", counted)
    phi = monodromy.monodromy(model, basis, coef, 100.0)
    assert len(calls) == int(np.sum(is_open & (widths > 0)))
    np.testing.assert_allclose(phi, reference, rtol=0, atol=1e-10 * np.linalg.norm(reference))


def test_an_orbit_too_big_for_the_cache_keeps_expm(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Decompositions that would evict each other within one orbit are not made."""
    model, basis, coef = _chain_orbit(three_links, 600.0)
    monkeypatch.setattr(monodromy._FLOWS, "limit", 1000)
    calls = []

    def refuse(a: np.ndarray) -> None:
        calls.append(1)

    monkeypatch.setattr(monodromy, "_decompose", refuse)
    phi = monodromy.monodromy(model, basis, coef, 600.0)
    assert not calls
    np.testing.assert_array_equal(
        phi, monodromy.monodromy(model, basis, coef, 600.0, method="expm")
    )


def test_the_cache_tells_systems_apart(three_links: Structure) -> None:
    """Two structures that differ only in the contact stiffness share no decomposition:
    each gets its own expm product."""
    model, basis, coef = _chain_orbit(three_links, 600.0)
    stiffer = build(
        chain(
            [1.0, 1.0, 1.0],
            [1e6] * 3,
            [ClearanceJoint(clearance=1e-4, compression_stiffness=2e7, gap_stiffness=1e5)] * 3,
            dampers=[150.0] * 3,
        ),
        None,
    )
    for system in (model, stiffer, model):
        phi = monodromy.monodromy(system, basis, coef, 600.0)
        reference = monodromy.monodromy(system, basis, coef, 600.0, method="expm")
        assert np.linalg.norm(phi - reference) < 1e-10 * np.linalg.norm(reference)


def test_an_unknown_method_is_refused(three_links: Structure) -> None:
    model, basis, coef = _chain_orbit(three_links, 300.0)
    with pytest.raises(ParameterError, match="method must be 'eigen' or 'expm'"):
        monodromy.monodromy(model, basis, coef, 300.0, method="pade")  # type: ignore[arg-type]


def test_leading_multipliers_give_the_exact_verdict_on_every_point_of_a_mast_curve(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Issue 25's verdict that scales: the monodromy applied to a block of columns (subspace
    iteration, the product never formed), on every point of the 10-bay mast's curve into
    its first resonance (the issue's case, 60 points), against the eigenvalues of the whole
    monodromy matrix of the same orbit: the same verdict everywhere, the largest modulus
    to 1e-9 and the next three to 1e-8 of it (the leading route forced on, as it is by
    itself from 49 DOF up; the 20-bay curve is checked by ``bench_scale.py --exact``)."""
    from clearjoint.structure import mast

    structure = mast(10, joints=ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5), rayleigh=(0, 2e-6))
    force = np.zeros(structure.n_dof)
    force[list(structure.dof_names).index("n21x")] = 0.1
    w_open = float(structure.modes("open").omega[0])
    monkeypatch.setattr(monodromy, "LEADING_ABOVE", 0)
    fr = frequency_response(
        structure,
        force,
        0.8 * w_open,
        2.0 * w_open,
        max_points=60,
        max_step=0.05,
        check_points=0,
    )
    model = build(structure, None, 1.0)  # no friction: the speed is unused
    basis = aft.Basis.make(fr.settings["harmonics"], fr.settings["samples"])
    assert fr.coefficients is not None
    flips = 0
    for i in range(fr.omega.size):
        exact = monodromy.multipliers(model, basis, fr.coefficients[i], float(fr.omega[i]))
        top = np.abs(exact[:4])
        mine = np.abs(fr.multipliers[i, :4])
        assert mine[0] == pytest.approx(top[0], rel=1e-9)  # the verdict's multiplier
        # the next ones to 1e-8 of it (the two routes of the whole monodromy, eigen and
        # expm, differ by up to 6e-8 at 20 bays: docs/harmonic.md, Speed)
        assert mine == pytest.approx(top, rel=0.0, abs=1e-8 * top[0])
        assert bool(fr.stable[i]) == bool(top[0] < 1.0)
        assert np.count_nonzero(fr.multipliers[i]) == 16  # the block's; outside it 0
        flips += int(i > 0 and fr.stable[i] != fr.stable[i - 1])
    assert flips >= 2  # the curve crosses the verdict's boundary
