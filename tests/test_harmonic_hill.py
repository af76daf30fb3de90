"""Hill's method with centroid sorting (MODEL.md 5.3) against independent routes.

The references: the closed-form exponents of a linear system (an orbit inside every
gap), the exact monodromy of the same HB orbit (products of matrix exponentials
between its gap-edge crossings, harmonic/monodromy.py), and for one joint the
Floquet multipliers of the exact orbit by shooting (clearjoint.periodic).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from scipy.optimize import linear_sum_assignment

from clearjoint import ClearanceJoint, Losses, ParameterError
from clearjoint.harmonic import HarmonicError, aft, frequency_response, hill, monodromy
from clearjoint.harmonic.system import build
from clearjoint.periodic import periodic_orbit
from clearjoint.results import ResponseEvent
from clearjoint.structure import Structure, chain, mast
from helpers import with_losses
from test_harmonic_aft import PYHARM, PYHARM_ZETA

FORCE = np.array([0.0, 0.0, 40.0])


def _set_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance between two sets of multipliers, paired to minimise it."""
    cost = np.abs(a[:, None] - b[None, :])
    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].max())


def test_centroid_of_single_harmonics_by_hand() -> None:
    """c_(+-h) = (a_h -+ i b_h) / 2: a_2 = 1, b_2 = i is e^(2 i w t) alone (centroid 2);
    a real cosine weighs k = +-2 equally (0); the mean alone is 0; b_1 = i gives -1."""
    basis = aft.Basis.make(3, 64)
    v = np.zeros((7, 4), dtype=np.complex128)
    v[3, 0], v[4, 0] = 1.0, 1j  # a_2, b_2
    v[3, 1] = 1.0
    v[0, 2] = 1.0
    v[2, 3] = 1j  # b_1 = i: (0 - i i) / 2 = 1/2 at k = +1, (0 + i i) / 2 = -1/2 at k = -1
    v[1, 3] = 1.0  # a_1 = 1: c_+1 = (1 + 1) / 2 = 1, c_-1 = 0
    np.testing.assert_allclose(hill.centroids(basis, v, 1), [2.0, 0.0, 0.0, 1.0], atol=1e-15)


def _stiff_mast() -> Structure:
    """A 2-bay mast whose joints (0.1 mm) close onto 1e8 N/m: contact modes far above H w."""
    return mast(2, joints=ClearanceJoint(1e-4, 1e8, gap_stiffness=1e6), rayleigh=(0.0, 2e-6))


def _tip_x(s: Structure, newtons: float) -> np.ndarray:
    """A force of ``newtons`` N on the x DOF of the mast's tip node (the second-last DOF)."""
    force = np.zeros(s.n_dof)
    force[-2] = newtons
    return force


def test_linear_orbit_gives_the_closed_form_exponents() -> None:
    """A 2-bay mast forced gently stays inside every gap: the perturbation equation has
    constant coefficients, its exponents are the eigenvalues of [[0, I], [-M^-1 K, -M^-1 C]]
    (closed form), several of them far above H w. The centroid picks the natural member of
    each family; the smallest-abs(Im) sorting cannot (those families have no member in its
    strip) and gets other multipliers."""
    s = _stiff_mast()
    model = build(s, None)
    force = _tip_x(s, 1.0)
    w = 2.0 * math.pi * 45.0
    fr = frequency_response(s, force, w, 1.0001 * w, harmonics=7, max_points=2, check_points=0)
    assert fr.coefficients is not None
    rel = fr.coefficients[0] @ model.directions.T
    assert np.max(np.abs(rel)) < 0.9 * float(np.min(model.g_c))  # inside every gap
    n = s.n_dof
    inv_m = 1.0 / np.diag(model.mass)
    a = np.block(
        [
            [np.zeros((n, n)), np.eye(n)],
            [-inv_m[:, None] * model.open_stiffness(), -inv_m[:, None] * model.damping],
        ]
    )
    lam = scipy.linalg.eigvals(a)
    assert np.max(np.abs(lam.imag)) > 10.0 * w  # modes far above H w / 2
    exact = np.exp(lam * 2.0 * math.pi / w)
    found = hill.orbit_spectrum(model, fr.coefficients[0], w)
    assert _set_distance(np.sort_complex(found.exponents), np.sort_complex(lam)) < 1e-6 * w
    assert _set_distance(found.multipliers, exact) < 1e-9
    assert np.max(np.abs(found.centroid)) < 1e-6
    assert found.defect < 1e-6
    strip = hill.orbit_spectrum(model, fr.coefficients[0], w, sorting="imaginary")
    assert _set_distance(strip.multipliers, exact) > 0.1


@pytest.mark.parametrize(("harmonics", "tolerance"), [(7, 0.05), (15, 0.012)])
def test_chain_agrees_with_the_exact_monodromy_of_the_same_orbit(
    three_links: Structure, harmonics: int, tolerance: float
) -> None:
    """The 3-link chain at five frequencies, each orbit beyond a gap edge: Hill's 2N
    multipliers (centroid sorting) against the exact monodromy of the same HB orbit, all
    six paired, within a tolerance that shrinks with H (measured: worst 0.041 at H = 7,
    9.3e-3 at H = 15; `benchmarks/bench_hill.py --agreement`), and the same verdict. At H = 7,
    400 rad/s the centroid alone kept a spurious family (largest 0.159 against 0.792)."""
    model = build(three_links, None)
    for w in (200.0, 300.0, 400.0, 600.0, 800.0):
        fr = frequency_response(
            three_links, FORCE, w, 1.001 * w, harmonics=harmonics, max_points=2, check_points=0
        )
        assert fr.coefficients is not None
        q = fr.coefficients[0]
        basis = aft.Basis.make(harmonics, int(fr.settings["samples"]))
        exact = monodromy.multipliers(model, basis, q, w)
        found = hill.orbit_spectrum(model, q, w)
        assert _set_distance(found.multipliers, exact) < tolerance, w
        assert (np.max(np.abs(found.multipliers)) < 1.0) == (np.max(np.abs(exact)) < 1.0), w
        if harmonics == 7 and w == 400.0:
            assert np.max(np.abs(found.multipliers)) == pytest.approx(0.7923, abs=1e-3)


def test_stiff_contact_needs_many_more_harmonics_in_the_perturbation() -> None:
    """A 2-bay mast whose joints close onto 1e8 N/m (contact modes far above H w): at the
    orbit's own H = 7 Hill's multipliers miss the exact monodromy's by order 1 (the
    reason structures keep the monodromy by default); carrying the perturbation with
    H' = 31 on the same orbit brings them within 0.15 (docs/harmonic.md, "Stability")."""
    s = _stiff_mast()
    model = build(s, None)
    force = _tip_x(s, 5.0)
    w = 2.0 * math.pi * 51.92
    fr = frequency_response(s, force, w, 1.0001 * w, harmonics=7, max_points=2, check_points=0)
    assert fr.coefficients is not None
    q = fr.coefficients[0]
    rel = q @ model.directions.T
    basis = aft.Basis.make(7, int(fr.settings["samples"]))
    assert np.max(basis.extremes(rel)[0]) > float(np.min(model.g_c))  # in contact
    exact = monodromy.multipliers(model, basis, q, w)
    errors = [
        _set_distance(hill.orbit_spectrum(model, q, w, harmonics=h).multipliers, exact)
        for h in (7, 31)
    ]
    assert errors[0] > 0.3
    assert errors[1] < 0.15


def test_one_joint_agrees_with_the_exact_orbits_floquet_multipliers() -> None:
    """pyHarm's joint (H = 12), the curve's contact points (both stable branches and the
    unstable one): the eigenproblem with centroid sorting against the multipliers of the
    exact orbit by shooting (clearjoint.periodic) started from the HB orbit, away from
    bifurcations (abs(mu) - 1 > 0.03), and against Hill's infinite determinant of the same
    HB orbit (the same truncation by another route). Measured (20 points): paired
    multipliers within 7.0e-3 (median), 4.8e-2 (worst, 1.53 rad/s beside the fold, where
    the HB orbit's own error matters most); 3.2e-4 from the determinant. Both shrink with
    H (`benchmarks/bench_hill.py --agreement`)."""
    model = build(PYHARM, Losses(damping_ratio=PYHARM_ZETA))
    curve = frequency_response(
        PYHARM, 0.03, 1.0, 1.7, harmonics=12, losses=Losses(damping_ratio=PYHARM_ZETA), max_step=0.1
    )
    assert curve.coefficients is not None
    compared = unstable = 0
    for i in range(0, curve.omega.size, 3):
        if curve.amplitude[i] < 1.1 * 0.1745:  # contact only (free play is linear)
            continue
        w = float(curve.omega[i])
        exact = periodic_orbit(
            PYHARM,
            0.03,
            w,
            losses=Losses(damping_ratio=PYHARM_ZETA),
            initial=curve.initial_state[i],
        )
        ref = np.asarray(exact.multipliers)
        if abs(float(np.max(np.abs(ref))) - 1.0) < 0.03:
            continue
        found = hill.orbit_spectrum(model, curve.coefficients[i][:, None], w)
        assert _set_distance(found.multipliers, ref) < 0.06
        top = float(np.max(np.abs(found.multipliers)))
        assert top == pytest.approx(float(np.max(np.abs(ref))), rel=0.05)
        assert (top < 1.0) == exact.stable
        assert _set_distance(found.multipliers, curve.multipliers[i]) < 1e-3
        compared += 1
        unstable += not exact.stable
    assert compared >= 12
    assert unstable >= 4


def test_frequency_response_stability_option(three_links: Structure) -> None:
    """stability="hill" on a structure against the default exact monodromy, and
    stability="monodromy" on a joint against the default Hill determinant."""
    curve = dict(harmonics=7, max_points=6, check_points=0)
    by_hill = frequency_response(three_links, FORCE, 300.0, 320.0, stability="hill", **curve)
    by_mono = frequency_response(three_links, FORCE, 300.0, 320.0, **curve)
    assert by_hill.settings["stability"] == "hill"
    assert by_mono.settings["stability"] == "monodromy"
    assert by_hill.settings["hill_defect"].shape == by_hill.omega.shape
    np.testing.assert_array_equal(by_hill.omega, by_mono.omega)
    np.testing.assert_array_equal(by_hill.stable, by_mono.stable)
    for a, b in zip(by_hill.multipliers, by_mono.multipliers, strict=True):
        assert _set_distance(a, b) < 0.05
    assert not [e for e in by_hill.events if e.kind == "untrusted"]
    joint = dict(harmonics=12, damping_ratio=PYHARM_ZETA, max_points=5)
    det = frequency_response(PYHARM, 0.03, 1.2, 1.25, **with_losses(joint))
    mono = frequency_response(PYHARM, 0.03, 1.2, 1.25, stability="monodromy", **with_losses(joint))
    assert det.settings["stability"] == "hill"
    np.testing.assert_allclose(np.abs(det.multipliers), np.abs(mono.multipliers), atol=2e-3)
    with pytest.raises(ParameterError, match="stability must be 'hill' or 'monodromy'"):
        frequency_response(PYHARM, 0.03, 1.2, 1.25, stability="floquet")  # type: ignore[arg-type]


def test_unresolved_points_are_flagged_not_guessed(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Where Hill's eigenproblem resolves fewer than 2N exponents the point gets NaN
    multipliers and an "untrusted" event, never a verdict."""
    with pytest.raises(HarmonicError, match="fewer than the 2N = 4"):
        hill.select(np.array([-1.0 + 0j, -2.0, -3.0]), np.array([0.0, 0.1, 2.0]), 1.0, 4)

    def refuse(*args: object, **kwargs: object) -> hill.HillSpectrum:
        raise HarmonicError("no")

    monkeypatch.setattr(hill, "spectrum", refuse)
    fr = frequency_response(
        three_links,
        FORCE,
        300.0,
        301.0,
        harmonics=3,
        max_points=2,
        check_points=0,
        stability="hill",
    )
    assert np.isnan(fr.multipliers).all()
    assert not fr.stable.any()
    assert [e.kind for e in fr.events].count("untrusted") == fr.omega.size
    assert "stability='monodromy'" in fr.events[-1].note


def test_negative_real_multiplier_members_count_once() -> None:
    """The two members -+ i w / 2 of a negative real multiplier's family (centroids +-1/2)
    are one family: with 2N = 2 the other family is kept beside one of them."""
    w = 10.0
    lam = np.array([-1.0 + 5.0j, -1.0 - 5.0j, -1.0 + 15.0j, -1.0 - 15.0j, -3.0 + 0j, -3.0 + 10j])
    kbar = np.array([-0.5, 0.5, -1.5, 1.5, 0.0, -1.0])
    kept, _ = hill.select(lam, kbar, w, 2)
    assert sorted(kept.tolist())[-1] == 4
    assert len({round(abs(lam[i].imag)) for i in kept}) == 2
    assert repr(hill.HillSpectrum(lam[:2], lam[:2], kbar[:2], 0.0)).startswith("HillSpectrum(2")


@pytest.mark.parametrize("omega", [0.8, 1.0, 1.3, 2.2])
def test_damped_mathieu_against_the_integrated_monodromy(omega: float) -> None:
    """k(t) = k (1 + 0.6 cos w t + 0.3 sin 2 w t), m = 1, c = 0.1 (tests/test_harmonic_aft.py):
    both multipliers of the eigen route with centroid sorting (H = 12) against the monodromy
    integrated by scipy's solve_ivp. w = 1 and 1.3 lie in tongues (real multipliers, one
    below -1): at 1.3 the imaginary-part sorting keeps one exponent twice and misses -0.51;
    the centroid's family check keeps both."""
    from test_harmonic_aft import mathieu

    model, basis, jac, exact = mathieu(omega)
    found = hill.spectrum(model, basis, jac, omega)
    assert _set_distance(found.multipliers, exact) < 5e-5
    if omega == 1.3:
        strip = hill.spectrum(model, basis, jac, omega, sorting="imaginary")
        assert _set_distance(strip.multipliers, exact) > 0.5


def test_hill_on_stiff_contact_flags_the_points_the_monodromy_contradicts() -> None:
    """stability="hill" on the 2-bay mast in contact at H = 7 (largest multiplier 0.80 by
    Hill, 1.43 by the exact monodromy of the same orbit): the point is flagged, naming
    both numbers; the default (the monodromy) calls it unstable."""
    s = _stiff_mast()
    force = _tip_x(s, 5.0)
    w = 2.0 * math.pi * 51.92
    curve = dict(harmonics=7, max_points=2, check_points=0)
    by_hill = frequency_response(s, force, w, 1.0001 * w, stability="hill", **curve)
    by_mono = frequency_response(s, force, w, 1.0001 * w, **curve)
    assert not by_mono.stable.any()
    assert by_hill.stable.all()
    flagged = [e for e in by_hill.events if e.kind == "untrusted"]
    assert len(flagged) == 2
    assert "exact monodromy" in flagged[0].note
    assert not [e for e in by_mono.events if e.kind == "untrusted"]


def _events_on_a_chain(mu: np.ndarray) -> list[ResponseEvent]:
    """curve_events of multipliers ``mu`` (4 points) at w = 1, 2, 3, 4 on a 2-mass chain,
    its joints never beyond a gap edge (no grazing)."""
    from clearjoint.harmonic.response import curve_events

    model = build(chain([1.0, 1.0], [1e6, 1e6], [ClearanceJoint(1e-4, 1e7)] * 2), None)
    omega = np.array([1.0, 2.0, 3.0, 4.0])
    d = np.zeros((4, 2))
    return curve_events(model, omega, mu, d, d, omega, np.ones(4), np.full(4, 1e-6))


def _kinds(mu: np.ndarray) -> list[str]:
    return [e.kind for e in _events_on_a_chain(mu)]


#: A complex pair at angle +-1 rad.
_TURN = np.exp(1j * np.array([1.0, -1.0]))


def test_neimark_sacker_crossings_are_events_and_collisions_are_not() -> None:
    """A complex pair 0.9 -> 1.1 at angle +-1 rad between w = 2 and 3 (a real pair beside
    it): one "neimark_sacker" event at w = 2.5 by linear interpolation. A real multiplier
    through +1 and a complex pair that meets the real axis outside the circle (the largest
    complex modulus drops from 1.2 to the inside pair's 0.5) give none."""
    mu = np.array(
        [np.concatenate((r * _TURN, [0.3, 0.2])) for r in (0.8, 0.9, 1.1, 1.2)],
        dtype=np.complex128,
    )
    found = _events_on_a_chain(mu)
    assert [e.kind for e in found] == ["neimark_sacker"]
    assert found[0].omega == pytest.approx(2.5)
    real = mu.copy()
    real[:, :2] = np.array([[0.8, 0.1], [0.9, 0.1], [1.1, 0.1], [1.2, 0.1]])
    assert _kinds(real) == []
    collide = np.array(
        [
            [1.2 * np.exp(0.2j), 1.2 * np.exp(-0.2j), 0.5j, -0.5j],
            [1.3, 1.1, 0.5j, -0.5j],
            [1.4, 1.0 + 1e-9, 0.5j, -0.5j],
            [1.5, 0.9, 0.5j, -0.5j],
        ]
    )
    assert _kinds(collide) == []


def test_a_neimark_sacker_crossing_is_found_whatever_the_tiny_multipliers_do() -> None:
    """The crossing above (a pair 0.9 -> 1.1 between w = 2 and 3), where the point at w = 3
    also returns a complex pair of modulus 1e-7 that the others return as 0 (the leading
    block's route returns 0 outside its block, whose size changes from point to point):
    still one "neimark_sacker" event at w = 2.5. Counting every complex multiplier,
    however small, skipped it as a pair meeting the real axis."""
    mu = np.array(
        [np.concatenate((r * _TURN, [0.3, 0.2, 0.0, 0.0])) for r in (0.8, 0.9, 1.1, 1.2)],
        dtype=np.complex128,
    )
    mu[2, 4:] = 1e-7 * np.exp(1j * np.array([2.0, -2.0]))
    found = _events_on_a_chain(mu)
    assert [e.kind for e in found] == ["neimark_sacker"]
    assert found[0].omega == pytest.approx(2.5)


def test_a_second_pair_moving_beside_the_crossing_one_neither_hides_nor_fakes_it() -> None:
    """Two coincidences the review of issue 25's fifth round built, which any count of
    complex multipliers above a threshold gets wrong (here 0.5): (1) the pair 0.9 -> 1.1
    crosses while a second pair goes 0.45 -> 0.55: still one event at w = 2.5; (2) the
    largest pair meets the real axis outside the circle (1.2 -> reals 1.3 and 0.9) while
    the second pair goes 0.45 -> 0.55: no event (the largest complex modulus falls from
    1.2 to 0.55, but no pair crossed the circle)."""
    other = np.exp(1j * np.array([2.0, -2.0]))
    mu = np.array(
        [
            np.concatenate((r * _TURN, s * other, [0.0, 0.0]))
            for r, s in ((0.8, 0.4), (0.9, 0.45), (1.1, 0.55), (1.2, 0.6))
        ],
        dtype=np.complex128,
    )
    found = _events_on_a_chain(mu)
    assert [e.kind for e in found] == ["neimark_sacker"]
    assert found[0].omega == pytest.approx(2.5)
    collide = mu.copy()
    collide[:2, :2] = np.array([1.2, 1.1])[:, None] * _TURN
    collide[2:, :2] = np.array([[1.3, 0.9], [1.4, 0.8]])
    assert _kinds(collide) == []
