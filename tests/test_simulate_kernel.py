"""exact.kernel: march limits, the closed-form segment energies, stiff contact."""

from __future__ import annotations

import itertools
import math
import os
import subprocess
import sys
import textwrap
from fractions import Fraction

import numpy as np
import pytest

from clearjoint import Friction, Joint, Losses
from clearjoint.exact import kernel as kn
from clearjoint.exact import single
from clearjoint.simulate import time_response

#: k_contact / k0 = 1e8: free flights of seconds between contacts of a fraction of a ms.
STIFF = Joint(
    mass=1.0,
    clearance=0.2,
    gap_stiffness=1.0,
    compression_stiffness=1e8,
    tension_stiffness=1e8,
)


def test_a_march_that_runs_out_of_steps_raises_instead_of_jumping() -> None:
    # with the JIT off the step limit is read at run time, so one step is enough to hit it
    script = textwrap.dedent(
        """
        from clearjoint import Friction, Joint, Losses
        from clearjoint.exact import kernel as kn
        from clearjoint.simulate import time_response, SimulationError
        kn.MAX_MARCH_STEPS = 1
        joint = Joint(mass=1.0, clearance=0.2, gap_stiffness=1.0, compression_stiffness=4.0)
        for losses in (None, Losses(friction=Friction(0.5, 1.0))):  # moving, sticking state
            try:
                time_response(joint, 1.0, 1.0, 6.0, losses=losses)
            except SimulationError as error:
                assert "certified steps" in str(error), error
                print("raised")
            else:
                print("returned")
        """
    )
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["raised", "raised"]


def _quadrature_energy(p: np.ndarray, q: np.ndarray, duration: float) -> tuple[float, float]:
    """64-point Gauss-Legendre on 40 pieces of the state's velocity, one point at a time."""
    nodes, weights = np.polynomial.legendre.leggauss(64)
    edges = np.linspace(0.0, duration, 41)
    work = viscous = 0.0
    for a, b in itertools.pairwise(edges):
        for node, weight in zip(nodes, weights, strict=True):
            tau = 0.5 * (a + b) + 0.5 * (b - a) * node
            v = kn.evaluate(q, 1, tau)[1]
            force = p[kn.P_F0] * math.sin(q[kn.Q_PHI] + p[kn.P_W] * tau)
            work += 0.5 * (b - a) * weight * force * v
            viscous += 0.5 * (b - a) * weight * p[kn.P_DAMP] * v * v
    return work, viscous


@pytest.mark.parametrize("damping", [0.0, 0.05, 2.0, 3.0])  # light, over-damped free-play
@pytest.mark.parametrize("region", [kn.FREE, kn.COMPRESSION, kn.TENSION])
def test_closed_form_segment_energy_matches_adaptive_quadrature(
    damping: float, region: int
) -> None:
    joint = Joint(mass=1.0, clearance=0.2, gap_stiffness=1.0, compression_stiffness=30.0)
    p = single.parameters(joint, 0.7, 1.3, 0.0, None, 1.0)
    p[kn.P_DAMP] = damping
    rng = np.random.default_rng(region + 7)
    scratch = np.zeros((3, 6), dtype=np.complex128)
    for _ in range(5):
        x0, v0, phi = rng.normal() * 0.2, rng.normal(), rng.uniform(0.0, 2 * math.pi)
        q = kn.phase_coefficients(p, region, 1, x0, v0, phi)
        duration = rng.uniform(0.1, 4.0)
        work, viscous = kn._segment_energy(p, q, 1, duration, scratch)
        ref_work, ref_viscous = _quadrature_energy(p, q, duration)
        scale = abs(ref_work) + ref_viscous
        assert work == pytest.approx(ref_work, abs=1e-11 * scale)
        assert viscous == pytest.approx(ref_viscous, abs=1e-11 * scale)


def test_stiff_contact_runs_and_closes_its_ledger() -> None:
    # 100 periods with k_contact / k0 = 1e8 and e = 0.8: before the closed-form energies the
    # free flights were cut into pieces of the contact period / 8 (seconds per call), and a
    # velocity zero below the resolution of the time stalled the march
    omega = 1.0
    motion = time_response(
        STIFF, 1.0, omega, 100 * 2 * math.pi / omega, losses=Losses(restitution=0.8)
    )
    assert motion.impact_times.size > 100
    assert motion.energy.balance_error < 1e-9


@pytest.mark.parametrize(
    ("alpha", "kq", "tau"),
    [
        (-3.0, 4e4, 2e-3),  # under-damped
        (-300.0, 4e4, 2e-3),  # over-damped, root tau >= 1/2
        (-200.5, 4e4, 1e-3),  # over-damped, small root tau (the expm1 branch)
        (-200.0, 4e4, 2e-3),  # critical
    ],
)
def test_homogeneous_parts_are_the_matrix_exponential(alpha: float, kq: float, tau: float) -> None:
    """x'' = 2 alpha x' - kq x: e - alpha g and g are the first row of expm(A tau)."""
    from scipy.linalg import expm

    d2 = alpha * alpha - kq
    e_part, g_part = kn.homogeneous_parts(alpha, d2, math.sqrt(abs(d2)), tau)
    flow = expm(np.array([[0.0, 1.0], [-kq, 2.0 * alpha]]) * tau)
    assert e_part - alpha * g_part == pytest.approx(flow[0, 0], rel=1e-9, abs=1e-12)
    assert g_part == pytest.approx(flow[0, 1], rel=1e-9, abs=1e-15)


def _first_root(g0: float, g1: float, g2: float, bound: float, h_max: float) -> float:
    """First h in (0, h_max] where g0 + g1 h + g2 h^2/2 - bound h^3/6 falls to 0, by numpy.roots."""
    roots = np.roots([-bound / 6.0, 0.5 * g2, g1, g0])
    real = [r.real for r in roots if abs(r.imag) <= 1e-12 * abs(r) and r.real > 0.0]
    return min([h_max, *real])


def _exact_cubic(g0: float, g1: float, g2: float, bound: float, h: float) -> Fraction:
    g0_, g1_, g2_, b_, h_ = (Fraction(v) for v in (g0, g1, g2, bound, h))
    return g0_ + h_ * (g1_ + h_ * (g2_ / 2 - b_ * h_ / 6))


def test_certified_step_is_certified_and_tight_on_random_cubics() -> None:
    # long brackets (a critical point far left of h_max) and both convex and concave pieces
    rng = np.random.default_rng(3)
    for _ in range(2000):
        g0 = abs(rng.normal()) * 10.0 ** rng.uniform(-6, 1) * (rng.uniform() > 0.2)
        g1 = rng.normal() * 10.0 ** rng.uniform(-3, 4)
        g2 = rng.normal() * 10.0 ** rng.uniform(-3, 8)
        bound = 10.0 ** rng.uniform(0, 12)
        h_max = 10.0 ** rng.uniform(-5, 1)
        h = kn.certified_step(g0, g1, g2, bound, h_max)
        root = _first_root(g0, g1, g2, bound, h_max)
        if g0 == 0.0 and g1 < 0.0:
            assert h == 0.0
            continue
        # positive up to h (exactly at h, in rational arithmetic), so no root was passed
        grid = np.linspace(0.0, h, 201)[1:]
        assert np.all(kn._cubic(g0, g1, g2, bound, grid) > 0.0) or h == 0.0, (g0, g1, g2, h)
        size = abs(g0) + abs(g1) * h + abs(g2) * h * h / 2 + bound * h**3 / 6
        assert _exact_cubic(g0, g1, g2, bound, h) >= -1e-15 * size  # the round-off of the bound
        assert h <= root * (1.0 + 1e-10)  # numpy.roots itself is good to about 1e-13
        assert h >= root * (1.0 - 2e-9) - 1e-300, (g0, g1, g2, bound, h_max, h, root)


@pytest.mark.parametrize("x0", [1e-12, -1e-12, 3e-13, 1e-9])
def test_a_start_at_rest_just_off_zero_follows_the_closed_form(x0: float) -> None:
    # at rest at x0 > 0, phase 0: the net force -k0 x0 is tiny and negative while its rate
    # F0 w is positive, so the mass moves down for 2 x0 / (F0 w) s, then turns. The kernel
    # took the tiny acceleration for round-off, zeroed it, and so met the velocity zero at
    # once, again and again ("more than 100000 events ... (chattering)")
    omega = 1.0
    motion = time_response(
        STIFF, 1.0, omega, 3 * 2 * math.pi, losses=Losses(restitution=0.8), initial=(x0, 0)
    )
    # free play with k0 = m w^2 (resonant): x = x0 cos t + (sin t - t cos t) / 2 until x = 0.1
    t = motion.time
    free = t < 0.9 * motion.impact_times[0]
    exact = x0 * np.cos(t[free]) + 0.5 * (np.sin(t[free]) - t[free] * np.cos(t[free]))
    np.testing.assert_allclose(motion.displacement[free], exact, rtol=0, atol=1e-14)
    assert motion.events < 200
    assert motion.energy.balance_error < 1e-9


@pytest.mark.parametrize("ulps", [1, 2, 4])
def test_a_start_just_past_the_friction_limit_sticks_instead_of_looping(ulps: int) -> None:
    # at rest at x0 = F_f / k0 + a few ulps, phase 0: the net force -k0 x0 is just past the
    # friction limit, its rate F0 w pulls it back inside. The mass slides down for an
    # instant, then sticks while |F0 sin t - k0 x0| <= F_f, i.e. until t = pi; before the
    # fix this looped at t = 0 ("more than 100000 events ... (chattering)")
    joint = Joint(mass=1.0, clearance=2.0, gap_stiffness=1.0, compression_stiffness=3.0)
    x0 = 0.5 + ulps * float(np.spacing(0.5))
    motion = time_response(
        joint,
        1.0,
        1.0,
        2 * 2 * math.pi,
        losses=Losses(friction=Friction(0.5, 1.0)),
        initial=(x0, 0.0),
    )
    stuck = motion.time < math.pi - 1e-6
    np.testing.assert_allclose(motion.displacement[stuck], x0, rtol=0, atol=1e-12)
    assert motion.displacement[motion.time > math.pi + 0.5].min() < x0 - 0.01  # then slides
    assert motion.energy.balance_error < 1e-9
