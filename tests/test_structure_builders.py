"""Builders: the chain's sign convention and the truss's member forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import ClearanceJoint, Joint
from clearjoint.structure import Member, StructureError, chain, truss


def test_chain_links_are_compressed_by_the_difference_of_neighbours() -> None:
    joint = ClearanceJoint(1e-4, 1e7)
    s = chain([1.0, 2.0, 3.0], [1e6, math.inf, 2e6], [None, joint, None], dampers=[1.0, 2.0, 3.0])
    # link i is compressed by u_i - u_(i-1), displacements positive toward the ground
    np.testing.assert_array_equal(
        s.member_directions, [[1.0, 0.0, 0.0], [-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]]
    )
    np.testing.assert_array_equal(s.joint_directions, [[-1.0, 1.0, 0.0]])
    c = s.damping_matrix()
    np.testing.assert_array_equal(c, [[3.0, -2.0, 0.0], [-2.0, 5.0, -3.0], [0.0, -3.0, 3.0]])


def test_one_rigid_link_chain_is_exactly_the_joint() -> None:
    joint = Joint(2.0, 1e-4, 8e7, tension_stiffness=3e7, gap_stiffness=1e6, gap_offset=2e-5)
    s = chain([2.0], [math.inf], [joint.element])
    x = np.linspace(-3e-4, 3e-4, 25)
    (law,) = s.joint_laws
    np.testing.assert_array_equal(law.force(x), joint.restoring_force(x))
    assert s.mass_diagonal().tolist() == [2.0]


def test_truss_accepts_members_as_objects_mappings_or_pairs() -> None:
    nodes = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]
    t = truss(
        nodes,
        [Member(0, 2, stiffness=1e6), {"start": 1, "end": 3, "stiffness": 2e6}, (1, 2), (2, 3)],
        supports=[0, 1],
        masses=1.0,
        stiffness=3e6,
    )
    assert t.n_dof == 4
    assert t.dof_names == ["n2x", "n2y", "n3x", "n3y"]


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: chain([1.0, 1.0], [1e6]), "stiffnesses must have one entry per link (2)"),
        (lambda: chain([1.0], [1e6], [None, None]), "joints must have one entry per link (1)"),
        (lambda: chain([0.0], [1e6]), "masses[0] must be > 0 kg"),
        (
            lambda: truss([[0.0, 0.0], [1.0, 0.0]], [(0, 1)], supports=[0]),
            "member 0 is a pair of nodes but no default stiffness was given",
        ),
    ],
)
def test_builder_input_errors_name_the_item(call, message) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(StructureError) as info:
        call()
    assert message in str(info.value)


def test_mast_has_two_hinged_longerons_per_bay_and_bends_first() -> None:
    from clearjoint.structure import mast

    hinge = ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5)
    tower = mast(10, joints=hinge)
    assert len(tower.joint_members) == 20
    assert tower.n_dof == 40
    closed, opened = tower.modes("closed"), tower.modes("open")
    assert opened.omega[0] < closed.omega[0]  # open joints soften the mast
    tip = tower.node_displacements(closed.shapes[:, 0])[-1]
    assert abs(tip[0]) > 5.0 * abs(tip[1])  # the first mode sways sideways
    with pytest.raises(StructureError, match="one per longeron"):
        mast(2, joints=[hinge] * 3)


def test_mast_takes_its_own_joint_per_longeron_in_order() -> None:
    from clearjoint.structure import mast

    own = [ClearanceJoint(c, 5e7, gap_stiffness=1e5) for c in (10e-6, 20e-6, 30e-6, 40e-6)]
    tower = mast(2, joints=own)
    # bay 1 left, bay 1 right, bay 2 left, bay 2 right: members 0, 1, 4, 5
    assert tower.joint_members == (0, 1, 4, 5)
    given = [tower.members[i].joint for i in tower.joint_members]
    assert given == own
    # in series with the longeron (k_m = EA / h = 4e7 N/m), the gap grows by 1 + k0 / k_m
    clearances = [law.clearance for law in tower.joint_laws]
    np.testing.assert_allclose(clearances, np.array([1, 2, 3, 4]) * 1e-5 * (1 + 1e5 / 4e7))
    same = mast(2, joints=[own[0]] * 4)
    np.testing.assert_array_equal(
        same.modes("closed").omega, mast(2, joints=own[0]).modes("closed").omega
    )
