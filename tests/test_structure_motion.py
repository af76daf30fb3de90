"""Exact structure motion against the one-joint kernel, solve_ivp and its own energy balance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import ClearanceJoint, Friction, Joint, Losses
from clearjoint.simulate import time_response as joint_time_response
from clearjoint.structure import Structure, StructureError, chain, free_decay, time_response
from clearjoint.structure.reference import reference_response

JOINT_ARGS = dict(
    clearance=1e-4,
    compression_stiffness=8e7,
    tension_stiffness=3e7,
    gap_stiffness=1e6,
    gap_offset=2e-5,
)


def test_one_joint_chain_agrees_with_the_one_joint_simulator() -> None:
    joint = Joint(2.0, **JOINT_ARGS)  # type: ignore[arg-type]
    element = ClearanceJoint(**JOINT_ARGS, restitution=0.8)  # type: ignore[arg-type]
    c_v = 2.0 * 0.02 * math.sqrt(2.0 * 8e7)  # the simulator's c_v = 2 zeta sqrt(m k_c)
    one = chain([2.0], [math.inf], [element], dampers=[c_v])
    omega = 0.8 * math.sqrt(8e7 / 2.0)
    duration = 12 * 2.0 * math.pi / omega
    mine = time_response(one, [3000.0], omega, duration, samples_per_period=64)
    theirs = joint_time_response(
        joint,
        3000.0,
        omega,
        duration,
        losses=Losses(damping_ratio=0.02, restitution=0.8),
        samples_per_period=64,
    )
    np.testing.assert_array_equal(mine.t, theirs.time)
    scale = np.max(np.abs(theirs.displacement))
    assert np.max(np.abs(mine.u[:, 0] - theirs.displacement)) <= 1e-9 * scale
    v_scale = np.max(np.abs(theirs.velocity))
    assert np.max(np.abs(mine.v[:, 0] - theirs.velocity)) <= 1e-9 * v_scale
    assert mine.events > 20
    for key in ("input", "viscous", "impact"):
        assert getattr(mine.energy, key) == pytest.approx(getattr(theirs.energy, key), rel=1e-9)


def _three_links():  # type: ignore[no-untyped-def]
    hit = ClearanceJoint(
        1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5, restitution=0.7
    )
    series = ClearanceJoint(1.5e-4, 5e7, tension_stiffness=9e7, gap_stiffness=2e6, gap_offset=-4e-5)
    return chain(
        [2.0, 1.5, 1.0], [math.inf, 6e7, 4e7], [hit, series, None], dampers=[50.0, 30.0, 20.0]
    )


def test_three_link_chain_with_two_joints_matches_solve_ivp_with_edge_events() -> None:
    s = _three_links()
    force = [500.0, -300.0, 800.0]
    omega = 0.9 * float(s.modes("closed").omega[0])
    duration = 8 * 2.0 * math.pi / omega
    mine = time_response(s, force, omega, duration, samples_per_period=32)
    u, v, events = reference_response(s, force, omega, mine.t)
    assert mine.events == events > 30
    assert set(np.unique(mine.pattern[:, 0])) == {-1, 0, 1}
    assert np.max(np.abs(mine.u - u)) <= 1e-8 * np.max(np.abs(u))
    assert np.max(np.abs(mine.v - v)) <= 1e-8 * np.max(np.abs(v))
    assert mine.energy.impact > 0.0
    assert mine.balance_error < 1e-9


def test_free_decay_ledger_closes_and_energy_only_falls() -> None:
    s = _three_links()
    u0 = np.array([3e-4, 5e-4, 6e-4])
    decay = free_decay(s, (u0, np.zeros(3)), 0.02, samples_per_period=32)
    ledger = decay.energy
    assert ledger.input == 0.0
    assert ledger.viscous > 0.0
    assert ledger.impact > 0.0
    # independent: the stored energy at the start, from the joint laws and springs by hand
    laws = s.joint_laws
    stored = float(laws[0].potential_energy(u0[0])) + float(laws[1].potential_energy(u0[1] - u0[0]))
    stored += 0.5 * 4e7 * (u0[2] - u0[1]) ** 2
    final_u, final_v = decay.final_state
    end = (
        float(laws[0].potential_energy(final_u[0]))
        + float(laws[1].potential_energy(final_u[1] - final_u[0]))
        + 0.5 * 4e7 * (final_u[2] - final_u[1]) ** 2
        + 0.5 * float(np.sum(np.array([2.0, 1.5, 1.0]) * final_v**2))
    )
    losses = ledger.viscous + ledger.impact
    assert abs(stored - end - losses) <= 1e-9 * stored


@pytest.mark.parametrize(("reach", "expected"), [(1.0 - 1e-7, 0), (1.0 + 1e-7, 2)])
def test_grazing_contacts_are_neither_missed_nor_invented(reach: float, expected: int) -> None:
    # free oscillation in the gap on k0: delta = X0 cos(w0 t) touches the compression edge
    # once a period only if X0 > g_c; a penetration of 1e-7 g_c lasts ~1e-3.5 of a period
    joint = ClearanceJoint(2e-4, 5e7, gap_stiffness=1e5, gap_offset=-5e-5)  # g_t = 3 g_c
    one = chain([1.0], [math.inf], [joint])
    w0 = math.sqrt(1e5)
    x0 = reach * joint.compression_gap
    decay = free_decay(one, ([0.0], [x0 * w0]), 2.0 * math.pi / w0, samples_per_period=16)
    assert decay.events == expected
    if expected:  # entered where the free-play sine X0 sin(w0 t) reaches g_c
        entry = math.asin(joint.compression_gap / x0) / w0
        np.testing.assert_allclose(decay.event_times[0], entry, rtol=1e-9)


def test_bad_motion_input_is_refused_with_one_line() -> None:
    s = _three_links()
    with pytest.raises(StructureError, match="force has 2 entries but the structure has 3 DOF"):
        time_response(s, [1.0, 2.0], 100.0, 0.01)
    with pytest.raises(StructureError, match="initial must be"):
        free_decay(s, np.zeros(5), 0.01)
    one = chain([1.0], [1e6])
    # a scalar is not "1 entry" of a 1-DOF structure: the message names the shape it got
    with pytest.raises(
        StructureError,
        match=r"force must be a 1-D array of 1 value per DOF \(n1x\), got shape \(\)",
    ):
        time_response(one, 1.0, 100.0, 0.01)
    with pytest.raises(StructureError, match=r"initial u0 must be a 1-D array .* got shape \(\)"):
        free_decay(one, [1e-3, 0.0], 0.01)
    rub = ClearanceJoint(1e-4, 8e7, friction=Friction(0.1, 100.0))
    with pytest.raises(StructureError, match="Coulomb friction in a joint of a structure"):
        free_decay(chain([1.0], [math.inf], [rub]), ([1e-4], [0.0]), 0.01)


def _power_coefficients(roots: list[float], lead: float) -> np.ndarray:
    """Coefficients c_0..c_d (rising powers) of lead * prod (s - r)."""
    return np.asarray(np.polynomial.polynomial.polyfromroots(roots) * lead, dtype=np.float64)


@pytest.mark.parametrize(
    ("roots", "first", "tol"),
    [
        # a brief dip: two roots 2e-7 apart, each known to ~1e-16 / |Q'| = 5e-10
        ([0.3 - 1e-7, 0.3 + 1e-7, 0.9, 1.7], 0.3 - 1e-7, 2e-9),
        ([0.25, 0.5, 0.75, 2.5, -1.0], 0.25, 1e-14),
        ([1.2, 1.5], None, 0.0),  # roots beyond the step
        ([0.999999, 3.0], 0.999999, 1e-14),
    ],
)
def test_first_root_of_the_edge_polynomial_is_the_first_one(
    roots: list[float], first: float | None, tol: float
) -> None:
    from clearjoint.exact.march import MAX_DEPTH, MAX_TERMS, first_root

    c = _power_coefficients(roots, 1.0)
    if c[0] < 0.0:
        c = -c
    stack = np.zeros((MAX_DEPTH + 2, MAX_TERMS + 2))
    bounds = np.zeros((MAX_DEPTH + 2, 2))
    s = first_root(np.concatenate((c, [0.0])), c.size - 1, stack, bounds)
    if first is None:
        assert s > 1.0
    else:  # the roots are placed by hand; the answer is approached from Q > 0
        assert abs(s - first) <= tol
        assert np.polynomial.polynomial.polyval(s, c) > 0.0


def test_a_dip_that_stays_above_the_edge_is_not_an_event() -> None:
    from clearjoint.exact.march import MAX_DEPTH, MAX_TERMS, first_root

    # (s - 0.3)^2 + 1e-14 > 0 everywhere: no root, though its minimum is 1e-14
    c = np.array([0.09 + 1e-14, -0.6, 1.0, 0.0])
    stack = np.zeros((MAX_DEPTH + 2, MAX_TERMS + 2))
    bounds = np.zeros((MAX_DEPTH + 2, 2))
    assert first_root(c, 2, stack, bounds) > 1.0
    # at the edge and moving in (c_0 = 0, c_1 < 0) is an event now; moving away is not
    assert first_root(np.array([0.0, -1.0, 0.0]), 2, stack, bounds) == 0.0
    assert first_root(np.array([-1e-20, 1.0, 0.5]), 2, stack, bounds) > 1.0


def test_a_small_mast_with_rayleigh_damping_matches_solve_ivp_event_for_event() -> None:
    # 2-D: each joint's shortening involves four DOF; damping alpha M + beta K_closed
    from clearjoint.structure import mast

    hinge = ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)
    s = mast(3, joints=hinge, rayleigh=(0.5, 2e-6))
    force = np.zeros(s.n_dof)
    force[-2] = 20.0
    omega = 0.9 * float(s.modes("closed").omega[0])
    mine = time_response(s, force, omega, 2 * 2.0 * math.pi / omega, samples_per_period=32)
    u, v, events = reference_response(s, force, omega, mine.t)
    assert mine.events == events > 40
    assert len(set(map(tuple, mine.pattern))) > 5
    assert np.max(np.abs(mine.u - u)) <= 1e-9 * np.max(np.abs(u))
    assert np.max(np.abs(mine.v - v)) <= 1e-9 * np.max(np.abs(v))
    assert mine.balance_error < 1e-9


def test_a_3d_node_with_a_joint_matches_solve_ivp_event_for_event() -> None:
    """3-D: a mass on three skew members, a joint (k0 = 0, off-centre) in one, forced off-axis."""
    from clearjoint.structure import Member, Structure

    q, _ = np.linalg.qr(np.array([[1.0, 2.0, 0.5], [-0.3, 1.0, 2.0], [0.7, -1.0, 1.5]]))
    hinge = ClearanceJoint(1e-4, 5e7, gap_offset=3e-5)
    members = (
        Member(1, 0, stiffness=1e6, damping=5.0),
        Member(2, 0, stiffness=4e6),
        Member(3, 0, stiffness=9e6, joint=hinge),
    )
    s = Structure(np.vstack(([0.0, 0.0, 0.0], -q.T)), [2.5, 0, 0, 0], members, supports=(1, 2, 3))
    force = 300.0 * np.array([0.2, -0.5, 1.0])
    omega = 0.8 * float(s.modes("closed").omega[2])
    mine = time_response(s, force, omega, 4 * 2.0 * math.pi / omega, samples_per_period=32)
    u, v, events = reference_response(s, force, omega, mine.t)
    assert mine.events == events > 4
    assert np.max(np.abs(mine.u - u)) <= 1e-9 * np.max(np.abs(u))
    assert np.max(np.abs(mine.v - v)) <= 1e-9 * np.max(np.abs(v))
    assert mine.balance_error < 1e-9


def test_too_many_events_is_an_error_not_a_truncated_motion(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The event cap ends the run with SimulationError naming the joint, never a short result."""
    from clearjoint.errors import ClearjointError
    from clearjoint.simulate import SimulationError
    from clearjoint.structure import motion

    s = _three_links()
    omega = 0.9 * float(s.modes("closed").omega[0])
    args = (s, [500.0, -300.0, 800.0], omega, 2 * 2.0 * math.pi / omega)
    assert time_response(*args).events > 3  # the same run, uncapped, has events
    monkeypatch.setattr(motion, "MAX_EVENTS_PER_STEP", 0)  # cap: no event at all
    with pytest.raises(
        SimulationError, match=r"more than 0 gap-edge events .* at joint \d"
    ) as info:
        time_response(*args)
    assert isinstance(info.value, ClearjointError)
    assert "\n" not in str(info.value)


def test_structure_motion_to_pandas_is_one_row_per_sample(three_links: Structure) -> None:
    motion = time_response(three_links, [0.0, 0.0, 40.0], 400.0, 0.02, samples_per_period=32)
    table = motion.to_pandas()
    assert table.index.name == "time_s"
    np.testing.assert_array_equal(table.index.to_numpy(), motion.t)
    for k, name in enumerate(three_links.dof_names):
        np.testing.assert_array_equal(table[f"u_m[{name}]"].to_numpy(), motion.u[:, k])
        np.testing.assert_array_equal(table[f"v_m_per_s[{name}]"].to_numpy(), motion.v[:, k])
    assert motion.to_xarray()["u"].attrs["units"] == "m"
