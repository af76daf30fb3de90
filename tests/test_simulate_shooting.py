"""simulate._shooting: the exact map's monodromy, and steady_state's period-n label."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import Friction, Joint
from clearjoint.simulate import core, steady_state
from clearjoint.simulate._shooting import shoot
from clearjoint.simulate.reference import reference_time_response

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
    p = core._parameters(
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


def _closes_after(
    joint: Joint, force: float, omega: float, ss_state: tuple[float, ...], **kw: object
) -> float:
    """|x(T) - x(0)| + |v(T) - v(0)| / omega after one period, by solve_ivp (independent route)."""
    ref = reference_time_response(joint, force, omega, 1, initial=ss_state[:2], **kw)  # type: ignore[arg-type]
    return float(abs(ref.strobe[0, 0] - ss_state[0]) + abs(ref.strobe[0, 1] - ss_state[1]) / omega)


def test_alternating_convergence_is_labelled_period_1() -> None:
    force, omega = 0.6074259728855343, 0.5913488835368865
    ss = steady_state(ALTERNATING, force, omega, friction=ALTERNATING_FRICTION)
    assert ss.period_multiple == 1
    assert (
        _closes_after(ALTERNATING, force, omega, ss.initial_state, friction=ALTERNATING_FRICTION)
        < 1e-7
    )
    assert ss.energy.balance_error < 1e-9


def test_linear_orbit_inside_the_gap_is_labelled_period_1() -> None:
    force, omega = 0.03, 1.5
    ss = steady_state(PYHARM, force, omega, damping_ratio=PYHARM_ZETA, initial=(0.4, 0.0))
    assert ss.period_multiple == 1
    # closed form x = a sin(w t) + b cos(w t) of m x'' + c x' + k0 x = F0 sin(w t)
    k, c = 1.0 - omega**2, 0.05
    det = k * k + (c * omega) ** 2
    a, b = force * k / det, -force * c * omega / det
    assert ss.initial_state[0] == pytest.approx(b, abs=1e-10)
    assert ss.initial_state[1] == pytest.approx(a * omega, abs=1e-10)
