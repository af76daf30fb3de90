"""Structure: matrices and linear modes against closed forms; bad input (MODEL.md 5.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse

from clearjoint import ClearanceJoint, ParameterError
from clearjoint.structure import Member, Structure, StructureError, chain, truss


def test_two_mass_chain_modes_match_the_closed_form() -> None:
    m1, m2, k1, k2 = 2.0, 0.5, 3e6, 1e6
    modes = chain([m1, m2], [k1, k2]).modes()
    # det(K - w^2 M) = 0 for K = [[k1 + k2, -k2], [-k2, k2]], M = diag(m1, m2)
    a = (k1 + k2) / m1 + k2 / m2
    root = math.sqrt(a * a - 4.0 * k1 * k2 / (m1 * m2))
    expected = np.sqrt([(a - root) / 2.0, (a + root) / 2.0])
    np.testing.assert_allclose(modes.omega, expected, rtol=1e-12)
    shapes = modes.shapes
    np.testing.assert_allclose(shapes.T @ np.diag([m1, m2]) @ shapes, np.eye(2), atol=1e-12)


def test_closed_and_open_patterns_use_the_joint_in_series() -> None:
    joint = ClearanceJoint(1e-4, 8e7, gap_stiffness=1e6)
    k_m = 4e7
    one = chain([2.0], [k_m], [joint])
    series = lambda k: k * k_m / (k + k_m)  # noqa: E731
    assert one.modes("closed").omega[0] == pytest.approx(math.sqrt(series(8.1e7) / 2.0), rel=1e-12)
    assert one.modes("open").omega[0] == pytest.approx(math.sqrt(series(1e6) / 2.0), rel=1e-12)
    rigid = chain([2.0], [math.inf], [ClearanceJoint(1e-4, 8e7)])
    assert rigid.modes("open").omega[0] == 0.0  # k0 = 0: a free mass in the gap


@pytest.mark.parametrize("n", [10, 40, 160])
def test_fixed_free_bar_modes_converge_to_the_analytic_ones(n: int) -> None:
    length, e, rho, area = 2.0, 7e10, 2700.0, 1e-4
    h = length / n
    nodes = np.linspace(0.0, length, n + 1)
    masses = np.full(n + 1, rho * area * h)
    masses[-1] *= 0.5
    members = [Member(i, i + 1, youngs_modulus=e, area=area) for i in range(n)]
    bar = Structure(nodes, masses, tuple(members), supports=(0,))
    omega = bar.modes(count=3).omega
    k = np.arange(1, 4)
    exact = (2 * k - 1) * math.pi / (2.0 * length) * math.sqrt(e / rho)
    error = np.abs(omega / exact - 1.0)
    # lumped masses: the error falls as 1/n^2, ~ ((2k - 1) pi / (2 n))^2 / 24
    bound = ((2 * k - 1) * math.pi / (2.0 * n)) ** 2 / 12.0
    assert np.all(error < bound)
    assert error[0] > bound[0] / 10.0  # the error is really of that order, not zero


def test_large_structures_return_sparse_matrices_and_eigsh_agrees_with_dense() -> None:
    n = 240
    bar = chain(np.full(n, 0.1), np.full(n, 1e6))
    assert scipy.sparse.issparse(bar.stiffness_matrix("closed"))
    assert scipy.sparse.issparse(bar.mass_matrix())
    low = bar.modes(count=4).omega
    dense = np.sqrt(np.sort(np.linalg.eigvalsh(bar.stiffness_matrix().toarray() / 0.1))[:4])
    np.testing.assert_allclose(low, dense, rtol=1e-9)


def test_sparse_modes_of_an_open_mechanism_give_its_zero_frequency() -> None:
    """k0 = 0 and every joint open: K is singular, so no shift-invert about 0 (it raised)."""
    n = 240
    free = chain(np.full(n, 0.1), np.full(n, 1e6), [ClearanceJoint(1e-4, 1e7)] + [None] * (n - 1))
    low = free.modes("open", count=3).omega
    k_open = free.stiffness_matrix("open").toarray()
    dense = np.sqrt(np.clip(np.sort(np.linalg.eigvalsh(k_open / 0.1))[:3], 0.0, None))
    assert low[0] <= 1e-6 * low[1]  # the free chain's rigid-body mode
    np.testing.assert_allclose(low[1:], dense[1:], rtol=1e-9)


def test_member_directions_in_2d_give_the_textbook_stiffness() -> None:
    # a node held by two perpendicular members at +-45 deg: K = k I, so w = sqrt(k/m) twice
    nodes = [[0.0, 0.0], [-1.0, -1.0], [1.0, -1.0]]
    frame = truss(nodes, [(1, 0), (2, 0)], supports=[1, 2], masses=[3.0, 0.0, 0.0], stiffness=1.2e6)
    np.testing.assert_allclose(frame.stiffness_matrix(), 1.2e6 * np.eye(2), rtol=1e-12, atol=1e-6)
    np.testing.assert_allclose(frame.modes().omega, math.sqrt(1.2e6 / 3.0), rtol=1e-12)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (
            lambda: Structure([0.0, 0.0, 1.0], [0, 1, 1], (Member(0, 1, stiffness=1e6),), (0,)),
            "member 0 (nodes 0-1) has zero length; move its nodes apart",
        ),
        (
            lambda: Structure([0.0, 1.0], [0, 1], (Member(0, 5, stiffness=1e6),), (0,)),
            "member 0 end names node 5, which does not exist",
        ),
        (
            lambda: Structure(
                [0.0, 1.0, 2.0],
                [0, 0, 1],
                (
                    Member(0, 1, stiffness=1e6, joint=ClearanceJoint(1e-4, 1e7)),
                    Member(1, 2, stiffness=1e6),
                ),
                (0, 1),
            ),
            "member 0 joins two supports",
        ),
        (
            lambda: Structure([0.0, 1.0, 2.0], [1, 1, 1], (Member(0, 1, stiffness=1e6),), ()),
            "the structure is singular",
        ),
        (
            lambda: chain([1.0], [1e7], [ClearanceJoint(1e-4, 1e7, restitution=0.5)]),
            "restitution 0.5 on a joint in series with a member",
        ),
        (lambda: chain([1.0], [math.inf]), "member 0 (nodes 0-1) is rigid and has no joint"),
        (
            lambda: Structure([0.0, 1.0], [0, 1], (Member(0, 1, stiffness=1e6),), (0, 0)),
            "support 0 is listed twice; list each support once",
        ),
    ],
)
def test_bad_structures_are_refused_with_one_line_naming_the_item(build, message) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(StructureError) as info:
        build()
    text = str(info.value)
    assert message in text
    assert "\n" not in text


def test_rayleigh_takes_alpha_as_a_rate_and_beta_as_a_time_with_units() -> None:
    """alpha multiplies M (1/s: "20rad/s" is 20 /s), beta multiplies K (s); Hz is refused."""
    nodes = [[0.0], [-1.0]]
    member = [Member(0, 1, stiffness=4e7)]
    given = Structure(nodes, [0.0, 2.0], member, supports=(0,), rayleigh=("20rad/s", "2e-6s"))
    assert given.rayleigh == (20.0, 2e-6)
    # C = alpha M + beta K on the one DOF: 20 * 2 + 2e-6 * 4e7
    assert given.damping_matrix().tolist() == [[20.0 * 2.0 + 2e-6 * 4e7]]
    with pytest.raises(ParameterError, match="ambiguous for a rate in 1/s"):
        Structure(nodes, [0.0, 2.0], member, supports=(0,), rayleigh=("20Hz", 0.0))
    with pytest.raises(StructureError, match=r"rayleigh must be \(alpha, beta\)"):
        Structure(nodes, [0.0, 2.0], member, supports=(0,), rayleigh=0.5)  # type: ignore[arg-type]


def test_a_3d_node_on_three_skew_orthogonal_members_has_their_three_frequencies() -> None:
    """3-D: K = sum k_i e_i e_i^T for orthonormal e_i, so omega_i = sqrt(k_i / m) exactly."""
    q, _ = np.linalg.qr(np.array([[1.0, 2.0, 0.5], [-0.3, 1.0, 2.0], [0.7, -1.0, 1.5]]))
    k, m = np.array([1e6, 4e6, 9e6]), 2.5
    nodes = np.vstack(([0.0, 0.0, 0.0], -q.T))  # node 0 free, supports at -e_i
    members = tuple(Member(i + 1, 0, stiffness=float(k[i])) for i in range(3))
    node = Structure(nodes, [m, 0.0, 0.0, 0.0], members, supports=(1, 2, 3))
    assert node.dim == 3
    assert node.dof_names == ["n0x", "n0y", "n0z"]
    np.testing.assert_allclose(node.modes().omega, np.sqrt(k / m), rtol=1e-12)
    # each shape lies along its member (up to sign), normalised to phi^T M phi = 1
    shapes = node.modes().shapes * math.sqrt(m)
    np.testing.assert_allclose(np.abs(np.sum(shapes * q, axis=0)), 1.0, rtol=1e-12)
    # open, a joint (k0 = 0) in series with member 3 takes that member out: omega_3 = 0
    joint = ClearanceJoint(1e-4, 1e12)
    jointed = Structure(
        nodes,
        [m, 0.0, 0.0, 0.0],
        (*members[:2], Member(3, 0, stiffness=float(k[2]), joint=joint)),
        supports=(1, 2, 3),
    )
    open_omega = jointed.modes("open").omega
    np.testing.assert_allclose(open_omega, [0.0, *np.sqrt(k[:2] / m)], atol=1e-6)


def test_structures_compare_by_value_and_are_not_hashable() -> None:
    joint = ClearanceJoint(1e-4, 8e7)
    a = chain([2.0, 1.0], [3e6, 1e6], [joint, None])
    assert a == chain([2.0, 1.0], [3e6, 1e6], [joint, None])  # it used to raise on the arrays
    assert a != chain([2.0, 1.5], [3e6, 1e6], [joint, None])
    assert a != chain([2.0, 1.0], [3e6, 1e6], [None, None])
    assert a != "a structure"
    with pytest.raises(TypeError):
        hash(a)


def test_modes_to_pandas_is_one_row_per_mode(three_links: Structure) -> None:
    modes = three_links.modes()
    table = modes.to_pandas()
    np.testing.assert_array_equal(table.index.to_numpy(), np.arange(1, modes.omega.size + 1))
    np.testing.assert_array_equal(table["omega_rad_per_s"].to_numpy(), modes.omega)
    np.testing.assert_array_equal(table["frequency_hz"].to_numpy(), modes.frequency_hz)
    for k, name in enumerate(three_links.dof_names):
        np.testing.assert_array_equal(table[f"shape[{name}]"].to_numpy(), modes.shapes[k])
    assert modes.to_xarray()["frequency"].attrs["units"] == "Hz"
