"""The structure solvers on a VibrationSystem (issue 23): a Structure and its system agree,
and a system given only as matrices runs every structure solver (MODEL.md 5.2-5.3)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from clearjoint import ClearanceJoint, Friction, Joint, Losses, dissipation, periodic
from clearjoint import simulate as sim
from clearjoint.errors import ParameterError, ParameterTypeError
from clearjoint.harmonic import frequency_response, nonlinear_modes
from clearjoint.joint import LOSS_KEYWORDS
from clearjoint.simulate.reference import reference_time_response
from clearjoint.structure import Structure, chain, decay_backbone, free_decay, time_response
from clearjoint.structure.model import system_modes
from clearjoint.system import VibrationSystem, VibrationSystemError

LAW = ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4)


@pytest.fixture
def links() -> Structure:
    """Three masses, a joint in the first and the last link, dashpots on each."""
    return chain([1.0, 1.5, 2.0], [3e5, 2e5, 1e5], [LAW, None, LAW], [4.0, 3.0, 2.0])


def _hand_chain(mass: np.ndarray | None = None) -> VibrationSystem:
    """A 3-mass chain written out as matrices: springs ground-1, 1-2, 2-3, two joints."""
    k1, k2, k3 = 3e5, 2e5, 1e5
    stiffness = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    m = np.diag([1.0, 1.5, 2.0]) if mass is None else mass
    return VibrationSystem(
        mass=m,
        damping=1e-4 * stiffness + 0.5 * np.eye(3),
        stiffness=stiffness,
        directions=np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 1.0]]),
        laws=(LAW, ClearanceJoint(0.1e-3, 6e5, gap_stiffness=5e4)),
        dof_names=("a", "b", "c"),
    )


def test_time_response_of_a_structure_and_of_its_system_are_equal(links: Structure) -> None:
    force = np.array([0.0, 0.0, 30.0])
    one = time_response(links, force, 400.0, 0.05)
    two = time_response(links.to_system(), force, 400.0, 0.05)
    np.testing.assert_array_equal(one.u, two.u)
    np.testing.assert_array_equal(one.v, two.v)
    np.testing.assert_array_equal(one.event_times, two.event_times)
    assert one.dof_names == two.dof_names == tuple(links.dof_names)
    assert two.structure is links


def test_free_decay_and_backbone_of_a_structure_and_of_its_system_are_equal(
    links: Structure,
) -> None:
    initial = (np.array([1e-3, 2e-3, 3e-3]), np.zeros(3))
    one = free_decay(links, initial, 0.1)
    two = free_decay(links.to_system(), initial, 0.1)
    np.testing.assert_array_equal(one.t, two.t)
    np.testing.assert_array_equal(one.u, two.u)
    b1, b2 = decay_backbone(one, 2, mode=1), decay_backbone(two, 2, mode=1)
    np.testing.assert_array_equal(b1.amplitude, b2.amplitude)


def test_modes_of_a_structure_and_of_its_system_agree(links: Structure) -> None:
    for pattern in ("closed", "open"):
        mine = links.modes(pattern)
        one, two = system_modes(links, pattern), system_modes(links.to_system(), pattern)
        np.testing.assert_array_equal(one.omega, two.omega)
        np.testing.assert_array_equal(one.shapes, two.shapes)
        # the system assembles K in another order: equal to round-off, not bitwise
        np.testing.assert_allclose(mine.omega, one.omega, rtol=1e-12)
        assert one.structure is links
        assert one.dof_names == tuple(links.dof_names)


def test_harmonic_response_of_a_structure_and_of_its_system_are_equal(links: Structure) -> None:
    force = np.array([0.0, 0.0, 30.0])
    kwargs = {"harmonics": 5, "max_points": 4, "check_points": 0}
    one = frequency_response(links, force, 300.0, 320.0, **kwargs)
    two = frequency_response(links.to_system(), force, 300.0, 320.0, **kwargs)
    np.testing.assert_array_equal(one.omega, two.omega)
    np.testing.assert_array_equal(one.x_max, two.x_max)


def test_a_system_of_matrices_runs_time_response_free_decay_and_modes() -> None:
    system = _hand_chain()
    motion = time_response(system, [0.0, 0.0, 20.0], 300.0, 0.03)
    assert motion.structure is None
    assert motion.dof_names == ("a", "b", "c")
    assert motion.balance_error < 1e-8
    assert next(iter(motion.to_pandas().columns)) == "u_m[a]"
    decay = free_decay(system, (np.array([1e-3, 0.0, -1e-3]), np.zeros(3)), 0.05)
    assert decay.energy.input == 0.0
    assert decay.balance_error < 1e-8
    modes = system_modes(system, "closed")
    assert modes.structure is None
    assert modes.omega.size == 3
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    assert modes.plot() is not None  # against DOF index: no structure to draw
    assert motion.plot() is not None


def test_the_linear_limit_of_harmonic_balance_on_a_system_is_the_closed_form_frf() -> None:
    """Inside the gaps the joints stay open: x = (K_open - w^2 M + i w C)^-1 F."""
    system = _hand_chain()
    force = np.array([0.0, 0.0, 1e-3])
    omega = np.array([150.0, 250.0])
    fr = frequency_response(system, force, omega[0], omega[-1], harmonics=3, check_points=0)
    assert fr.coefficients is not None
    b = system.directions
    k_open = system.stiffness + (b.T * system.law_arrays().k0) @ b
    for w, coef in zip(fr.omega, fr.coefficients, strict=True):
        dynamic = k_open - w**2 * system.mass + 1j * w * system.damping
        x = np.linalg.solve(dynamic, force)
        np.testing.assert_allclose(np.hypot(coef[1], coef[2]), np.abs(x), rtol=1e-6)
        assert np.max(np.abs(b @ x)) < 0.1e-3  # inside every gap


def test_a_consistent_mass_is_refused_by_the_solvers_that_need_a_lumped_one() -> None:
    consistent = np.array([[1.0, 0.2, 0.0], [0.2, 1.5, 0.2], [0.0, 0.2, 2.0]])
    system = _hand_chain(consistent)
    with pytest.raises(VibrationSystemError, match="lumped"):
        time_response(system, [0.0, 0.0, 1.0], 300.0, 0.01)
    with pytest.raises(VibrationSystemError, match="lumped"):
        free_decay(system, (np.zeros(3), np.ones(3)), 0.01)
    with pytest.raises(VibrationSystemError, match="lumped"):
        system_modes(system)
    assert math.isfinite(float(system.mass[0, 1]))


# ---- a Joint is the one-DOF case: the single-joint solvers take its system -------------------


def _joint_and_losses() -> tuple[Joint, Losses]:
    joint = Joint(2.0, 1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5)
    return joint, Losses(damping_ratio=0.02, friction=Friction(0.1, 50.0), restitution=0.8)


def test_a_joint_and_its_one_dof_system_round_trip() -> None:
    joint, losses = _joint_and_losses()
    back, back_losses = VibrationSystem.from_joint(joint, losses).to_joint()
    assert back == joint
    assert back_losses.friction == losses.friction
    assert back_losses.restitution == losses.restitution
    assert back_losses.damping_ratio == pytest.approx(losses.damping_ratio, rel=1e-15)


def test_a_system_spring_in_parallel_is_the_joints_gap_stiffness() -> None:
    # the same law written two ways: k0 in the joint, or K beside a k0 = 0 joint
    law = ClearanceJoint(1e-4, 8e7, tension_stiffness=3e7)
    one = np.ones((1, 1))
    system = VibrationSystem(2.0 * one, 0.0 * one, 1e6 * one, one, (law,))
    joint, losses = system.to_joint()
    assert joint == Joint(2.0, 1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6)
    assert losses == Losses()


def test_the_single_joint_solvers_give_the_same_numbers_for_the_joint_and_its_system() -> None:
    joint, losses = _joint_and_losses()
    system = VibrationSystem.from_joint(joint, losses)
    w = 2.0 * math.pi * 600.0
    by_joint = sim.time_response(joint, 300.0, w, 0.01, losses=losses)
    by_system = sim.time_response(system, 300.0, w, 0.01)
    np.testing.assert_allclose(by_system.displacement, by_joint.displacement, rtol=1e-9, atol=1e-15)
    orbit_j = periodic.periodic_orbit(joint, 300.0, w, losses=losses)
    orbit_s = periodic.periodic_orbit(system, 300.0, w)
    np.testing.assert_allclose(orbit_s.initial_state, orbit_j.initial_state, rtol=1e-9)
    e_j = dissipation.total(joint, [5e-6, 2e-5], losses=losses)
    e_s = dissipation.total(system, [5e-6, 2e-5])
    np.testing.assert_allclose(e_s, e_j, rtol=1e-12)


def test_a_system_that_is_not_one_joint_is_refused_by_the_single_joint_solvers(
    links: Structure,
) -> None:
    with pytest.raises(VibrationSystemError, match="one DOF and one joint, got 3 DOFs"):
        sim.time_response(links.to_system(), 1.0, 100.0, 0.01)
    joint, losses = _joint_and_losses()
    with pytest.raises(ParameterError, match="carries its own"):
        sim.steady_state(VibrationSystem.from_joint(joint), 1.0, 100.0, losses=losses)
    flipped = VibrationSystem.from_joint(joint)
    flipped = VibrationSystem(
        flipped.mass, flipped.damping, flipped.stiffness, -flipped.directions, flipped.laws
    )
    with pytest.raises(VibrationSystemError, match="direction b = \\+1"):
        periodic.periodic_orbit(flipped, 1.0, 100.0)


@pytest.mark.parametrize(
    ("solver", "arguments"),
    [
        (sim.time_response, (1.0, 100.0, 0.01)),
        (sim.steady_state, (1.0, 100.0)),
        (sim.frequency_sweep, (1.0, [100.0, 200.0])),
        (reference_time_response, (1.0, 100.0, 2)),
        (periodic.periodic_orbit, (1.0, 100.0)),
        (periodic.frequency_response, (1.0, 100.0, 200.0)),
        (periodic.orbit_cycle, (1.0, 100.0, (0.0, 0.0))),
        (periodic.orbit_monodromy, (1.0, 100.0, (0.0, 0.0))),
        (dissipation.total, ([1e-5],)),
        (dissipation.energies, ([1e-5],)),
        (dissipation.compare, (1.0, 100.0)),
        (dissipation.agreement_map, ([100.0], [1.0])),
        (frequency_response, (1.0, 100.0, 200.0)),
        (nonlinear_modes, ()),
    ],
    ids=lambda v: getattr(v, "__qualname__", ""),
)
@pytest.mark.parametrize("keyword", LOSS_KEYWORDS)
def test_every_solver_refuses_a_loose_loss_keyword_with_the_fix(
    solver: Any, arguments: tuple[Any, ...], keyword: str
) -> None:
    joint, _ = _joint_and_losses()
    with pytest.raises(ParameterTypeError, match=rf"losses=Losses\({keyword}=0\.5\) instead"):
        solver(joint, *arguments, **{keyword: 0.5})


def test_the_single_joint_kernel_is_a_fast_path_equal_to_the_structure_solver() -> None:
    # one system object, two solvers: the single-joint kernel and the structure's march
    joint, _ = _joint_and_losses()
    system = VibrationSystem.from_joint(joint, Losses(damping_ratio=0.02, restitution=0.8))
    w = 0.8 * math.sqrt(8e7 / 2.0)
    duration = 12 * 2.0 * math.pi / w
    general = time_response(system, [3000.0], w, duration, samples_per_period=64)
    fast = sim.time_response(system, 3000.0, w, duration, samples_per_period=64)
    assert general.events > 20
    scale = float(np.max(np.abs(fast.displacement)))
    assert float(np.max(np.abs(general.u[:, 0] - fast.displacement))) <= 1e-9 * scale
    assert general.energy.impact == pytest.approx(fast.energy.impact, rel=1e-9)


def test_the_orbit_check_of_harmonic_balance_runs_on_a_system_as_on_its_structure(
    links: Structure,
) -> None:
    force = np.array([0.0, 0.0, 30.0])
    kwargs = {"harmonics": 5, "max_points": 6, "check_points": 3}
    one = frequency_response(links, force, 300.0, 320.0, **kwargs)
    two = frequency_response(links.to_system(), force, 300.0, 320.0, **kwargs)
    np.testing.assert_array_equal(
        one.settings["orbit_check"].residual, two.settings["orbit_check"].residual
    )
    assert np.all(np.isfinite(two.settings["orbit_check"].residual))


def test_a_one_dof_system_takes_a_number_as_its_force_in_every_solver() -> None:
    joint, _ = _joint_and_losses()
    system = VibrationSystem.from_joint(joint, Losses(damping_ratio=0.05))
    by_number = frequency_response(system, 300.0, 5000.0, 5200.0, harmonics=3, max_points=3)
    by_array = frequency_response(system, [300.0], 5000.0, 5200.0, harmonics=3, max_points=3)
    np.testing.assert_array_equal(by_number.x_max, by_array.x_max)


def test_losses_refuse_a_contact_friction_coefficient_without_a_pin() -> None:
    with pytest.raises(ParameterError, match="these losses have no pin"):
        Losses(contact_friction_coefficient=0.3)


@pytest.mark.parametrize(
    ("direction", "stiffness", "words"),
    [
        (-1.0, 0.0, "swap k_c and k_t"),
        (0.5, 0.0, "own displacement"),
        (1.0, -2e6, "must be >= 0"),
    ],
)
def test_a_system_that_is_no_single_joint_says_why(
    direction: float, stiffness: float, words: str
) -> None:
    one = np.ones((1, 1))
    law = ClearanceJoint(1e-4, 8e7, gap_stiffness=1e6)
    system = VibrationSystem(one, 0.0 * one, stiffness * one, direction * one, (law,))
    with pytest.raises(VibrationSystemError, match=words):
        system.to_joint()
