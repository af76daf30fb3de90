"""simulate._shooting: the exact map's monodromy, and steady_state's period-n label."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import Friction, Joint, Losses
from clearjoint.exact import shooting as sh
from clearjoint.exact import single
from clearjoint.exact.shooting import shoot
from clearjoint.simulate import steady_state, time_response
from clearjoint.simulate.reference import reference_time_response
from helpers import with_losses

#: pyHarm's SDOF clearance case: m = 1, c_v = 0.05, k0 = 1, edges at +-0.1745, contact adds 3.
PYHARM = Joint(
    mass=1.0,
    clearance=2 * 0.1745,
    gap_stiffness=1.0,
    compression_stiffness=3.0,
    tension_stiffness=3.0,
)
PYHARM_ZETA = 0.05 / (2.0 * math.sqrt(3.0))  # c_v = 2 zeta sqrt(m k_c) = 0.05

#: The issue's case that steady_state used to call period 2.
ALTERNATING = Joint(
    mass=1.0,
    clearance=1.0,
    compression_stiffness=1.0,
    tension_stiffness=0.88766521723705,
    gap_stiffness=0.054102906400873854,
)
ALTERNATING_FRICTION = Friction(0.3, 0.31677059106795386)


def _finite_difference(p: np.ndarray, z: np.ndarray) -> np.ndarray:
    jac = np.zeros((2, 2))
    for k in range(2):
        dz = np.zeros(2)
        dz[k] = 1e-7 * max(abs(z[k]), 1e-2)
        jac[:, k] = (shoot(p, z + dz, 1).end - shoot(p, z - dz, 1).end) / (2 * dz[k])
    return jac


@pytest.mark.parametrize(
    ("force", "omega", "losses"),
    [
        (0.03, 1.5, {"damping_ratio": PYHARM_ZETA}),  # contact, continuous force
        (0.03, 1.2, {"damping_ratio": PYHARM_ZETA, "restitution": 0.7}),  # impacts
        (0.03, 1.0, {"damping_ratio": PYHARM_ZETA, "friction": Friction(0.3, 0.01)}),
        (0.06, 0.4, {"damping_ratio": PYHARM_ZETA, "friction": Friction(0.5, 0.02)}),  # sticks
    ],
)
def test_monodromy_by_saltation_matches_a_finite_difference_of_the_map(
    force: float, omega: float, losses: dict[str, object]
) -> None:
    p = single.parameters(
        PYHARM,
        force,
        omega,
        losses.get("damping_ratio", 0.0),  # type: ignore[arg-type]
        losses.get("friction"),  # type: ignore[arg-type]
        losses.get("restitution", 1.0),  # type: ignore[arg-type]
    )
    for z in (np.array([0.15, 0.05]), np.array([-0.3, 0.2]), np.array([0.05, -0.1])):
        exact = shoot(p, z, 1).monodromy
        fd = _finite_difference(p, z)
        assert np.max(np.abs(exact - fd)) <= 1e-5 * np.max(np.abs(fd))


def _end_and_sensitivity(
    p: np.ndarray, z: np.ndarray, parameter: int, lam: float
) -> tuple[np.ndarray, np.ndarray, float, int]:
    """P_1(z; lam), the sensitivity dP/dlam shoot_map carries, its exactness flag, events."""
    q = p.copy()
    sh.set_parameter(q, parameter, lam)
    state = np.zeros(4)
    sh.start_state(q, float(z[0]), float(z[1]), state)
    out = np.zeros(sh.N_OUT)
    assert sh.shoot_map(q, state, 1, out, parameter) == 0
    sens = out[sh.O_DL0 : sh.O_DL1 + 1].copy()
    return state[:2].copy(), sens, float(out[sh.O_DL_EXACT]), int(out[sh.O_EVENTS])


@pytest.mark.parametrize(
    ("case", "force", "omega", "losses", "z"),
    [
        ("free play", 0.03, 0.7, {"damping_ratio": PYHARM_ZETA}, (0.05, 0.01)),
        ("contact", 0.03, 1.5, {"damping_ratio": PYHARM_ZETA}, (0.3, 0.0)),
        ("impacts", 0.03, 1.2, {"damping_ratio": PYHARM_ZETA, "restitution": 0.7}, (0.3, 0.1)),
        (
            "slip",
            0.3,
            1.0,
            {"damping_ratio": PYHARM_ZETA, "friction": Friction(0.3, 0.2)},
            (0.1, 0),
        ),
        (
            "sticks",
            0.3,
            0.4,
            {"damping_ratio": PYHARM_ZETA, "friction": Friction(0.3, 0.5)},
            (0, 0),
        ),
        (
            "sticks, impacts, undamped",
            0.3,
            0.4,
            {"friction": Friction(0.3, 0.5), "restitution": 0.9},
            (0.2, 0.3),
        ),
    ],
)
def test_parameter_sensitivity_matches_a_central_difference_of_the_map(
    case: str, force: float, omega: float, losses: dict[str, object], z: tuple[float, float]
) -> None:
    # dP/domega and dP/dF0 carried through the segments and events (saltation) against a
    # central difference of the exact map (an independent route: two more evaluations)
    p = single.parameters(
        PYHARM,
        force,
        omega,
        losses.get("damping_ratio", 0.0),  # type: ignore[arg-type]
        losses.get("friction"),  # type: ignore[arg-type]
        losses.get("restitution", 1.0),  # type: ignore[arg-type]
    )
    z0 = np.array(z, dtype=float)
    motion = time_response(
        PYHARM, force, omega, 2 * math.pi / omega, initial=z, **with_losses(losses)
    )  # type: ignore[arg-type]
    if case.startswith("sticks"):
        assert motion.stick_time > 0.0
    if case == "free play":
        assert motion.impact_times.size == 0
        assert max(abs(motion.x_max), abs(motion.x_min)) < PYHARM.compression_gap
    if case.startswith(("contact", "impacts")):
        assert motion.x_max > PYHARM.compression_gap
    for parameter, lam in ((0, omega), (1, force)):
        _, sens, exact, events = _end_and_sensitivity(p, z0, parameter, lam)
        assert exact == 1.0
        h = 1e-6 * lam
        up, _, _, events_up = _end_and_sensitivity(p, z0, parameter, lam + h)
        down, _, _, events_down = _end_and_sensitivity(p, z0, parameter, lam - h)
        assert events_up == events == events_down  # the same sequence of segments
        central = (up - down) / (2 * h)
        assert np.max(np.abs(sens - central)) <= 1e-6 * np.max(np.abs(central))


def test_parameter_sensitivity_falls_back_to_a_difference_at_exact_undamped_resonance() -> None:
    # undamped free play at omega = sqrt(k0 / m) exactly: the secular particular solution is
    # not carried, so shoot_map says so and map_residual differences the map instead
    p = single.parameters(PYHARM, 0.001, 1.0, 0.0, None, 1.0)
    z = np.array([0.01, 0.0])
    _, _, exact, _ = _end_and_sensitivity(p, z, 0, 1.0)
    assert exact == 0.0
    out = np.zeros(sh.N_RES)
    assert sh.map_residual(p, 0, 0.01, 0.0, 1.0, out, True) == 0
    assert out[sh.R_EVALS] == 2.0
    # the forward difference with step 1e-7 lam, as written by hand, and near the central one
    base, _, _, _ = _end_and_sensitivity(p, z, 0, 1.0)
    shifted, _, _, _ = _end_and_sensitivity(p, z, 0, 1.0 + 1e-7)
    forward = (shifted - base) / 1e-7
    assert np.allclose(out[sh.R_DLAM : sh.R_DLAM + 2], forward, rtol=1e-12, atol=0.0)
    up, _, _, _ = _end_and_sensitivity(p, z, 0, 1.0 + 1e-6)
    down, _, _, _ = _end_and_sensitivity(p, z, 0, 1.0 - 1e-6)
    central = (up - down) / 2e-6
    assert np.max(np.abs(forward - central)) <= 1e-3 * np.max(np.abs(central))
    # off resonance the same call evaluates the map once
    out = np.zeros(sh.N_RES)
    assert sh.map_residual(p, 0, 0.01, 0.0, 1.1, out, True) == 0
    assert out[sh.R_EVALS] == 1.0


def _closes_after(
    joint: Joint, force: float, omega: float, ss_state: tuple[float, ...], **kw: object
) -> float:
    """|x(T) - x(0)| + |v(T) - v(0)| / omega after one period, by solve_ivp (independent route)."""
    ref = reference_time_response(joint, force, omega, 1, initial=ss_state[:2], **with_losses(kw))  # type: ignore[arg-type]
    return float(abs(ref.strobe[0, 0] - ss_state[0]) + abs(ref.strobe[0, 1] - ss_state[1]) / omega)


def test_alternating_convergence_is_labelled_period_1() -> None:
    force, omega = 0.6074259728855343, 0.5913488835368865
    ss = steady_state(ALTERNATING, force, omega, losses=Losses(friction=ALTERNATING_FRICTION))
    assert ss.period_multiple == 1
    assert (
        _closes_after(ALTERNATING, force, omega, ss.initial_state, friction=ALTERNATING_FRICTION)
        < 1e-7
    )
    assert ss.energy.balance_error < 1e-9


def test_linear_orbit_inside_the_gap_is_labelled_period_1() -> None:
    force, omega = 0.03, 1.5
    ss = steady_state(
        PYHARM, force, omega, losses=Losses(damping_ratio=PYHARM_ZETA), initial=(0.4, 0.0)
    )
    assert ss.period_multiple == 1
    # closed form x = a sin(w t) + b cos(w t) of m x'' + c x' + k0 x = F0 sin(w t)
    k, c = 1.0 - omega**2, 0.05
    det = k * k + (c * omega) ** 2
    a, b = force * k / det, -force * c * omega / det
    assert ss.initial_state[0] == pytest.approx(b, abs=1e-10)
    assert ss.initial_state[1] == pytest.approx(a * omega, abs=1e-10)
