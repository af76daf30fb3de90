"""Finite-element models from matrices and their Craig-Bampton reduction (issue 26).

Every reference is assembled here by hand (beam elements written out below, closed
forms, scipy's eigh of K + k b b^T), never taken from the code under test."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse

from clearjoint import ClearanceJoint
from clearjoint.errors import ParameterTypeError
from clearjoint.harmonic import frequency_response, nonlinear_modes
from clearjoint.structure import free_decay, from_matrices, reduce, time_response
from clearjoint.structure.fe import FEModelError, MatrixModel, ReducedSystem
from clearjoint.structure.model import system_modes
from clearjoint.system import VibrationSystemError

LAW = ClearanceJoint(0.1e-3, 2e6, gap_stiffness=2e3)
EI, RHO_A, K_ROT = 2e3, 2.0, 1e4  # N m^2, kg/m, N m/rad


def hinged_beam(
    elements: int, *, lumped: bool, sparse: bool = True
) -> tuple[object, object, list[str], int, int]:
    """A cantilever of two 1 m segments meeting at a hinge (two coincident nodes).

    Euler-Bernoulli elements (w, theta per node), consistent or lumped mass; node 0
    clamped. The hinge nodes' rotations are tied by a spring K_ROT; their transverse
    DOFs meet only through the clearance joint. Returns M, K, DOF names, and the
    indices of the two hinge w DOFs.
    """
    h = 1.0 / elements
    ke = (EI / h**3) * np.array(
        [
            [12, 6 * h, -12, 6 * h],
            [6 * h, 4 * h * h, -6 * h, 2 * h * h],
            [-12, -6 * h, 12, -6 * h],
            [6 * h, 2 * h * h, -6 * h, 4 * h * h],
        ]
    )
    if lumped:
        me = RHO_A * h * np.diag([0.5, h * h / 24.0, 0.5, h * h / 24.0])
    else:
        me = (RHO_A * h / 420.0) * np.array(
            [
                [156, 22 * h, 54, -13 * h],
                [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                [54, 13 * h, 156, -22 * h],
                [-13 * h, -3 * h * h, -22 * h, 4 * h * h],
            ]
        )
    n_nodes = 2 * (elements + 1)
    k = np.zeros((2 * n_nodes, 2 * n_nodes)) if not sparse else None
    rows, cols, kv, mv = [], [], [], []
    for first in (0, elements + 1):
        for e in range(elements):
            dofs = np.arange(2 * (first + e), 2 * (first + e) + 4)
            rows.extend(np.repeat(dofs, 4))
            cols.extend(np.tile(dofs, 4))
            kv.extend(ke.ravel())
            mv.extend(me.ravel())
    ra, rb = 2 * elements + 1, 2 * elements + 3  # the hinge nodes' rotations
    for r, c, v in ((ra, ra, K_ROT), (rb, rb, K_ROT), (ra, rb, -K_ROT), (rb, ra, -K_ROT)):
        rows.append(r)
        cols.append(c)
        kv.append(v)
        mv.append(0.0)
    shape = (2 * n_nodes, 2 * n_nodes)
    k = scipy.sparse.coo_matrix((kv, (rows, cols)), shape=shape).tocsr()
    m = scipy.sparse.coo_matrix((mv, (rows, cols)), shape=shape).tocsr()
    free = np.arange(2, 2 * n_nodes)  # node 0 clamped
    k, m = k[free][:, free], m[free][:, free]
    names = [f"n{i // 2}{'w' if i % 2 == 0 else 't'}" for i in free]
    wa, wb = names.index(f"n{elements}w"), names.index(f"n{elements + 1}w")
    if not sparse:
        k, m = k.toarray(), m.toarray()
    return m, k, names, wa, wb


def closed_reference(m: object, k: object, wa: int, wb: int, k_joint: float) -> np.ndarray:
    """omega (rad/s), ascending, of K + k_joint (e_a - e_b)(e_a - e_b)^T against M."""
    kd = k.toarray() if scipy.sparse.issparse(k) else np.array(k)
    md = m.toarray() if scipy.sparse.issparse(m) else np.array(m)
    kd[wa, wa] += k_joint
    kd[wb, wb] += k_joint
    kd[wa, wb] -= k_joint
    kd[wb, wa] -= k_joint
    # the inverse pencil M x = (1/w^2) K x: a fine beam's K spans 1e16, and eigh(K, M)
    # loses ~1e-5 on its lowest mode; 1/mu is accurate at the low end (K positive definite)
    mu = scipy.linalg.eigvalsh(md, kd)[::-1]
    return 1.0 / np.sqrt(mu)


# ---- from_matrices --------------------------------------------------------------------------


def test_two_masses_joined_by_a_joint_have_the_closed_form_frequencies() -> None:
    """Each mass on its own spring k; the joint k_j between them: w^2 = k/m, (k + 2 k_j)/m."""
    m, k = 2.0, 5e4
    system = from_matrices(np.diag([m, m]), np.diag([k, k]), joints=[(0, 1, LAW)])
    for pattern, k_j in (("closed", 2e3 + 2e6), ("open", 2e3)):
        omega = system_modes(system, pattern).omega
        expected = np.sqrt([k / m, (k + 2.0 * k_j) / m])
        np.testing.assert_allclose(omega, expected, rtol=1e-12)
    assert isinstance(system.source, MatrixModel)
    assert system.source.joint_dofs == ((0, 1),)


@pytest.mark.parametrize("sparse", [False, True])
def test_modes_of_a_lumped_beam_match_eigh_of_the_same_assembly(sparse: bool) -> None:
    m, k, names, wa, wb = hinged_beam(12, lumped=True, sparse=sparse)
    system = from_matrices(m, k, joints=[(names[wa], names[wb], LAW)], dof_names=names)
    assert system.is_sparse == sparse
    for pattern, k_joint in (("closed", 2e3 + 2e6), ("open", 2e3)):
        mine = system_modes(system, pattern).omega
        np.testing.assert_allclose(mine, closed_reference(m, k, wa, wb, k_joint), rtol=1e-9)


def test_a_joint_between_two_nodes_along_a_direction() -> None:
    """delta = n . (u_a - u_b): K + k n_ab n_ab^T, the same assembly by hand."""
    masses = np.array([1.0, 1.2, 0.8, 1.5, 1.1, 0.9])
    k = np.diag([4e4, 5e4, 6e4, 3e4, 7e4, 2e4])
    n = np.array([0.6, 0.8, 0.0])
    names = ["ax", "ay", "az", "bx", "by", "bz"]
    system = from_matrices(
        np.diag(masses), k, joints=[(names[:3], names[3:], n, LAW)], dof_names=names
    )
    b = np.concatenate((n, -n))
    np.testing.assert_array_equal(system.directions[0], b)
    k_closed = k + (2e3 + 2e6) * np.outer(b, b)
    expected = np.sqrt(scipy.linalg.eigvalsh(k_closed, np.diag(masses)))
    np.testing.assert_allclose(system_modes(system).omega, expected, rtol=1e-9)
    ground = from_matrices(np.diag(masses), k, joints=[([0, 1, 2], None, n, LAW)])
    np.testing.assert_array_equal(ground.directions[0], np.concatenate((n, np.zeros(3))))


def test_rayleigh_damping_is_alpha_m_plus_beta_k_closed() -> None:
    m, k = np.diag([1.0, 2.0]), np.array([[3e4, -1e4], [-1e4, 1e4]])
    system = from_matrices(m, k, joints=[(1, None, LAW)], rayleigh=(0.5, "2e-5s"))
    k_closed = k + np.diag([0.0, 2e3 + 2e6])
    np.testing.assert_allclose(system.damping, 0.5 * m + 2e-5 * k_closed, rtol=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"stiffness": np.array([[1.0, 2.0], [0.0, 1.0]])}, "not symmetric"),
        ({"stiffness": np.eye(3)}, "stiffness is 3 x 3"),
        ({"stiffness": np.array([[1.0, 0.0], [0.0, -5e7]])}, "negative diagonal"),
        ({"stiffness": np.array([[1e7, 3e7], [3e7, 1e7]])}, "not positive semi-definite"),
        ({"mass": np.array([[1.0, 2.0], [2.0, 1.0]])}, "mass matrix is not positive"),
        ({"mass": np.ones(3)}, "square"),
        ({"joints": [(0, 2, LAW)]}, "DOF 2, which does not exist"),
        ({"joints": [("x", "nope", LAW)], "dof_names": ["x", "y"]}, "'nope', which does not"),
        ({"joints": [(0, 0, LAW)]}, "to itself"),
        ({"joints": [([0], [1], [2.0], LAW)]}, "unit vector"),
        ({"dof_names": ["a"]}, "2 distinct names"),
    ],
)
def test_bad_models_are_refused_in_one_line_naming_the_problem(
    kwargs: dict[str, object], match: str
) -> None:
    args: dict[str, object] = {
        "mass": np.eye(2),
        "stiffness": np.array([[2e4, -1e4], [-1e4, 2e4]]),
        "joints": [(0, 1, LAW)],
    }
    args.update(kwargs)
    with pytest.raises(VibrationSystemError, match=match) as info:
        from_matrices(args.pop("mass"), args.pop("stiffness"), **args)  # type: ignore[arg-type]
    assert "\n" not in str(info.value)


def test_a_law_that_is_no_clearance_joint_is_a_type_error() -> None:
    with pytest.raises(ParameterTypeError, match="ClearanceJoint"):
        from_matrices(np.eye(2), np.eye(2), joints=[(0, 1, 3.0)])


def test_every_solver_runs_on_a_system_from_matrices() -> None:
    """A 3-mass chain as matrices, joints by DOF name: each structure solver runs on it."""
    k1, k2, k3 = 3e5, 2e5, 1e5
    stiffness = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    law = ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4)
    system = from_matrices(
        np.diag([1.0, 1.5, 2.0]),
        stiffness,
        joints=[("a", None, law), ("c", "b", law)],
        rayleigh=(0.5, 1e-4),
        dof_names=["a", "b", "c"],
    )
    motion = time_response(system, [0.0, 0.0, 20.0], 300.0, 0.03)
    assert motion.balance_error < 1e-8
    decay = free_decay(system, (np.array([1e-3, 0.0, -1e-3]), np.zeros(3)), 0.03)
    assert decay.balance_error < 1e-8
    fr = frequency_response(system, [0.0, 0.0, 20.0], 300.0, 320.0, harmonics=3, max_points=3)
    assert fr.omega.size >= 2
    nm = nonlinear_modes(system, 1, [1e-3, 2e-3], harmonics=5)
    assert np.all(nm.converged)
    # the backbone starts above the open mode and stays below the closed one
    f_open, f_closed = system_modes(system, "open").omega[0], system_modes(system).omega[0]
    omega = nm.frequency  # rad/s
    assert np.all((omega > f_open) & (omega < f_closed))


# ---- Craig-Bampton --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def long_beam() -> tuple[object, list[str], object, object, int, int]:
    """A consistent-mass hinged beam of 602 DOFs, sparse."""
    m, k, names, wa, wb = hinged_beam(150, lumped=False)
    system = from_matrices(m, k, joints=[(wa, wb, LAW)], dof_names=names, rayleigh=(1.0, 1e-5))
    return system, names, m, k, wa, wb


def test_craig_bampton_with_40_modes_gives_the_first_five_closed_modes_to_1e_4(
    long_beam: tuple,
) -> None:
    system, _, m, k, wa, wb = long_beam
    reduced = reduce(system, modes=40)
    assert isinstance(reduced, ReducedSystem)
    assert reduced.boundary == (wa, wb)
    assert reduced.n_dof == 42
    full = closed_reference(m, k, wa, wb, 2e3 + 2e6)[:5]
    mine = system_modes(reduced).omega[:5]  # M = 1: every solver's lumped mass
    assert np.max(np.abs(mine - full) / full) < 1e-4
    open_full = closed_reference(m, k, wa, wb, 2e3)[:5]
    open_mine = system_modes(reduced, "open").omega[:5]
    assert np.max(np.abs(open_mine - open_full) / open_full) < 1e-4
    check = reduced.check(5)
    # the check's own sparse solve of the full model (K spans 1e16 here: 1e-6, not 1e-9)
    np.testing.assert_allclose(check.full_closed_hz, full / (2 * math.pi), rtol=1e-6)
    assert check.worst < 1e-4
    assert "worst relative error" in repr(check)


def test_the_reduction_is_exact_for_a_static_force_on_a_boundary_dof(long_beam: tuple) -> None:
    """A Craig-Bampton basis holds the constraint modes: the static response to a force on
    a kept DOF is exact (K_closed^-1 F by a dense solve)."""
    system, names, _, k, wa, wb = long_beam
    tip = names.index("n301w")
    reduced = reduce(system, modes=5, keep=["n301w"])
    force = np.zeros(system.n_dof)
    force[tip] = 10.0
    q = np.linalg.solve(reduced.closed_stiffness(), reduced.project_force(force))
    kd = k.toarray()
    for i, j, v in ((wa, wa, 1), (wb, wb, 1), (wa, wb, -1), (wb, wa, -1)):
        kd[i, j] += v * (2e3 + 2e6)
    exact = np.linalg.solve(kd, force)
    # exact up to round-off of a K spanning 1e16 (1.2e-7 measured)
    np.testing.assert_allclose(reduced.expand(q), exact, rtol=1e-6, atol=1e-12 * abs(exact).max())
    by_name = reduced.project_force({"n301w": 10.0})
    np.testing.assert_array_equal(by_name, reduced.project_force(force))


def test_a_cutoff_keeps_the_fixed_interface_modes_below_it(long_beam: tuple) -> None:
    system = long_beam[0]
    reduced = reduce(system, cutoff_hz="2kHz")
    top = reduced.interface_omega / (2 * math.pi)
    assert top.size > 0
    assert top[-1] <= 2000.0
    more = reduce(system, modes=top.size + 1)
    assert more.interface_omega[-1] / (2 * math.pi) > 2000.0  # the next one is above it
    assert reduce(system, cutoff_hz=2000.0, modes=3).interface_omega.size == 3


def two_chains(n: int = 15, k: float = 1e5, m: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Two chains of n masses, each held to the ground at its outer end, ends facing."""
    size = 2 * n
    stiffness = np.zeros((size, size))
    springs = [(0, None), (size - 1, None)]
    springs += [(i, i + 1) for i in range(n - 1)] + [(i, i + 1) for i in range(n, size - 1)]
    for i, j in springs:
        stiffness[i, i] += k
        if j is not None:
            stiffness[j, j] += k
            stiffness[i, j] -= k
            stiffness[j, i] -= k
    return np.diag(np.full(size, m)), stiffness


def test_the_exact_motion_of_the_reduced_model_is_within_1_percent_of_the_full_one() -> None:
    """Forced response in contact over 5 periods: two 15-mass chains joined by a joint."""
    m, k = two_chains()
    law = ClearanceJoint(0.05e-3, 1e5, gap_stiffness=2e3)
    names = [f"m{i + 1}" for i in range(30)]
    system = from_matrices(
        m, k, joints=[("m15", "m16", law)], dof_names=names, rayleigh=(2.0, 1e-5)
    )
    reduced = reduce(system, modes=12, keep=["m25"])
    force = np.zeros(30)
    force[24] = 3.0
    omega = 0.95 * system_modes(system).omega[0]
    duration = 5 * 2 * math.pi / omega
    full = time_response(system, force, omega, duration)
    red = time_response(reduced, reduced.project_force(force), omega, duration)
    delta = full.u[:, 14] - full.u[:, 15]
    assert delta.max() > law.compression_gap  # in contact, both sides
    assert delta.min() < -law.tension_gap
    u = reduced.expand(red.u)[:, 24]
    scale = np.max(np.abs(full.u[:, 24]))
    assert np.max(np.abs(u - full.u[:, 24])) < 0.01 * scale  # 0.58 % measured


def test_reduce_refuses_what_it_cannot_do(long_beam: tuple) -> None:
    system = long_beam[0]
    with pytest.raises(FEModelError, match="give modes"):
        reduce(system)
    with pytest.raises(FEModelError, match="'nope', which does not exist"):
        reduce(system, modes=3, keep=["nope"])
    free = from_matrices(
        np.eye(3),
        np.array([[1e4, -1e4, 0.0], [-1e4, 1e4, 0.0], [0.0, 0.0, 1e4]]),
        joints=[(2, None, LAW)],
    )
    with pytest.raises(FEModelError, match="move freely"):
        reduce(free, modes=1)
    reduced = reduce(system, modes=3)
    with pytest.raises(FEModelError, match="ending in 5 values"):
        reduced.expand(np.zeros(4))
    assert repr(reduced).startswith("ReducedSystem(5 DOF from 602")
