"""system.py: the one vibration system, from a Joint, from a Structure, validated."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse

from clearjoint import ClearanceJoint, Friction, Joint, Losses
from clearjoint.errors import ClearjointError, ParameterTypeError
from clearjoint.structure import chain, mast
from clearjoint.system import VibrationSystem, as_system, pattern_states


def test_a_joint_is_the_one_dof_case() -> None:
    joint = Joint(mass=2.0, clearance=0.1e-3, compression_stiffness=8e7, tension_stiffness=5e7)
    losses = Losses(damping_ratio=0.02, friction=Friction(0.2, 300.0), restitution=0.8)
    s = as_system(joint, losses)
    assert s.n_dof == 1
    assert s.n_joints == 1
    assert s.is_joint
    # MODEL.md eq 7: c_v = 2 zeta sqrt(m k_c), written out here
    assert s.damping[0, 0] == pytest.approx(2 * 0.02 * math.sqrt(2.0 * 8e7), rel=1e-15)
    assert s.mass[0, 0] == 2.0
    assert s.stiffness[0, 0] == 0.0
    assert s.directions[0, 0] == 1.0
    assert s.laws == (joint.element,)
    # the joint's own losses travel with it, the damping ratio is in C
    assert s.losses[0].friction == Friction(0.2, 300.0)
    assert s.losses[0].restitution == 0.8
    assert s.losses[0].damping_ratio == 0.0
    np.testing.assert_array_equal(s.friction_force(), [60.0])
    np.testing.assert_array_equal(s.restitution(), [0.8])
    assert s.dof_names == ("x",)


def _spring_chain_by_hand(k: list[float], m: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """K and M of masses in a line, spring i between mass i-1 (ground for i = 0) and mass i."""
    n = len(m)
    kk = np.zeros((n, n))
    for i, ki in enumerate(k):
        kk[i, i] += ki
        if i > 0:
            kk[i - 1, i - 1] += ki
            kk[i - 1, i] -= ki
            kk[i, i - 1] -= ki
    return kk, np.diag(m)


def test_a_chain_gives_the_matrices_written_by_hand() -> None:
    law = ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4)
    s = chain([0.5, 0.7, 0.9], [1e5, 2e5, 3e5], joints=[None, law, None]).to_system()
    # members without a joint in K; the jointed link's spring is in series with its law
    k_plain, m = _spring_chain_by_hand([1e5, 0.0, 3e5], [0.5, 0.7, 0.9])
    np.testing.assert_allclose(s.mass, m, rtol=1e-15)
    np.testing.assert_allclose(s.stiffness, k_plain, rtol=1e-15, atol=1e-9)
    assert s.n_joints == 1
    b = s.directions[0]
    assert abs(b[0] - b[1]) == 2.0
    assert b[0] == -b[1]
    assert b[2] == 0.0
    series = law.in_series(2e5)
    assert s.laws[0] == series
    # closed pattern: the series law's contact tangent k0 + k_c on the link
    k_closed = _spring_chain_by_hand(
        [1e5, series.gap_stiffness + series.compression_stiffness, 3e5], [1, 1, 1]
    )[0]
    np.testing.assert_allclose(s.closed_stiffness(), k_closed, rtol=1e-12)
    k_open = _spring_chain_by_hand([1e5, series.gap_stiffness, 3e5], [1, 1, 1])[0]
    np.testing.assert_allclose(s.open_stiffness(), k_open, rtol=1e-12)


@pytest.mark.parametrize("bays", [2, 5])
def test_a_mast_system_agrees_with_the_structure(bays: int) -> None:
    law = ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)
    structure = mast(bays, joints=law, rayleigh=(0.0, 2e-6), member_damping=3.0)
    s = structure.to_system()
    rng = np.random.default_rng(bays)
    for _ in range(5):
        states = rng.integers(-1, 2, size=s.n_joints)
        k_s, r_s = s.pattern_stiffness(states)
        k_ref, r_ref = structure.pattern_stiffness(states)
        np.testing.assert_allclose(k_s, k_ref, rtol=1e-12, atol=1e-12 * np.abs(k_ref).max())
        np.testing.assert_allclose(r_s, r_ref, rtol=1e-12, atol=1e-12 * np.abs(r_ref).max())
    np.testing.assert_allclose(s.damping, structure.damping_matrix(), rtol=1e-15)
    np.testing.assert_array_equal(s.mass_diagonal(), structure.mass_diagonal())
    # the closed modes from the system's matrices against the structure's own
    w2 = scipy.linalg.eigh(s.closed_stiffness(), s.mass, eigvals_only=True)
    np.testing.assert_allclose(np.sqrt(w2), structure.modes("closed").omega, rtol=1e-9)
    assert s.dof_names == tuple(structure.dof_names)


def test_a_large_structure_gives_sparse_matrices_equal_to_dense() -> None:
    structure = mast(60, joints=ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5))
    s = structure.to_system()
    assert s.is_sparse
    assert s.n_dof > 200
    states = np.random.default_rng(0).integers(-1, 2, size=s.n_joints)
    k_s, r_s = s.pattern_stiffness(states)
    assert scipy.sparse.issparse(k_s)
    k_ref, r_ref = structure.pattern_stiffness(states)
    np.testing.assert_allclose(k_s.toarray(), k_ref, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(r_s, r_ref, rtol=1e-12, atol=1e-12)


def test_joint_forces_are_each_law() -> None:
    laws = (ClearanceJoint(1e-3, 1e6), ClearanceJoint(2e-3, 3e6, 1e6, 1e3, 2e-4))
    s = VibrationSystem(np.eye(2), np.zeros((2, 2)), np.zeros((2, 2)), np.eye(2), laws)
    delta = np.linspace(-3e-3, 3e-3, 41)[:, None] * np.ones(2)
    f, k = s.joint_forces(delta)
    # the piecewise law of MODEL.md section 0, written out
    d1 = delta[:, 1]
    g_c, g_t = 1e-3 + 2e-4, 1e-3 - 2e-4
    f1 = 1e3 * d1 + 3e6 * np.maximum(d1 - g_c, 0) + 1e6 * np.minimum(d1 + g_t, 0)
    np.testing.assert_allclose(f[:, 1], f1, rtol=1e-14, atol=1e-12)
    np.testing.assert_allclose(k[:, 0], np.where(np.abs(delta[:, 0]) > 0.5e-3, 1e6, 0.0))


def test_friction_and_restitution_in_a_law_move_to_its_losses() -> None:
    law = ClearanceJoint(1e-3, 1e6, friction=Friction(0.1, 50.0), restitution=0.7)
    s = VibrationSystem(np.eye(1), np.zeros((1, 1)), np.zeros((1, 1)), np.eye(1), (law,))
    assert s.laws[0].friction is None
    assert s.laws[0].restitution == 1.0
    assert s.losses[0].friction == Friction(0.1, 50.0)
    assert s.losses[0].restitution == 0.7


def _system(**change: object) -> VibrationSystem:
    given: dict[str, object] = {
        "mass": np.eye(2),
        "damping": np.zeros((2, 2)),
        "stiffness": np.eye(2),
        "directions": [[1.0, -1.0]],
        "laws": (ClearanceJoint(1e-3, 1e6),),
    }
    given.update(change)
    return VibrationSystem(**given)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"mass": np.ones((2, 3))}, "square"),
        ({"stiffness": np.eye(3)}, "stiffness is 3 x 3"),
        ({"damping": np.full((2, 2), np.nan)}, "NaN"),
        ({"directions": [[1.0, 0.0, 0.0]]}, "directions must be"),
        ({"laws": (1.0,)}, "ClearanceJoint"),
        ({"losses": (Losses(), Losses())}, "2 losses given for 1 joints"),
        ({"losses": (Losses(damping_ratio=0.1),)}, "damping matrix C"),
        ({"dof_names": ("a", "a")}, "2 distinct names"),
        ({"mass": "heavy"}, "matrix of numbers"),
    ],
)
def test_bad_input_is_one_clear_error(change: dict[str, object], words: str) -> None:
    with pytest.raises(ClearjointError, match=words):
        _system(**change)


def test_consistent_mass_is_refused_where_a_lumped_one_is_needed() -> None:
    s = _system(mass=np.array([[2.0, 0.5], [0.5, 2.0]]))
    with pytest.raises(ClearjointError, match="lumped"):
        s.mass_diagonal()
    np.testing.assert_array_equal(_system().mass_diagonal(), [1.0, 1.0])


def test_as_system_takes_each_kind_once() -> None:
    structure = chain([1.0, 1.0], [1e4, 1e4], joints=[ClearanceJoint(1e-3, 1e6), None])
    s = structure.to_system()
    assert as_system(s) is s
    assert as_system(structure).n_dof == 2
    with pytest.raises(ClearjointError, match="losses apply to a single Joint"):
        as_system(structure, Losses(damping_ratio=0.1))
    with pytest.raises(ParameterTypeError, match=r"must be a clearjoint\.Joint"):
        as_system(3.0)


def test_force_vector_and_patterns() -> None:
    s = _system()
    np.testing.assert_array_equal(s.force_vector([1.0, 2.0]), [1.0, 2.0])
    with pytest.raises(ClearjointError, match="one amplitude per DOF"):
        s.force_vector([1.0])
    np.testing.assert_array_equal(pattern_states(s, "closed"), [1])
    with pytest.raises(ClearjointError, match="0 \\(open\\)"):
        pattern_states(s, [2])
    assert repr(s) == "VibrationSystem(2 DOF, 1 joints, dense)"
