"""The sparse algebra of harmonic balance on structures (harmonic/solve.py, MODEL.md 5.3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from clearjoint import ClearanceJoint, Friction
from clearjoint import continuation as cont
from clearjoint.harmonic import aft, frequency_response, solve
from clearjoint.harmonic.system import from_structure
from clearjoint.structure import Structure, chain, mast

FORCE = np.array([0.0, 0.0, 40.0])


def _friction_chain() -> Structure:
    rub = Friction(coefficient=0.2, lateral_load=100.0)
    j = ClearanceJoint(clearance=1e-4, compression_stiffness=1e7, gap_stiffness=1e5, friction=rub)
    return chain([1.0, 1.0], [math.inf, math.inf], [j, j], dampers=[5.0, 5.0])


def _small_mast() -> Structure:
    joint = ClearanceJoint(1e-4, 1e8, gap_stiffness=1e6)
    return mast(2, joints=joint, rayleigh=(0.0, 2e-6))


@pytest.mark.parametrize("case", ["chain", "friction", "mast", "epmc"])
def test_sparse_jacobian_is_the_dense_one(three_links: Structure, case: str) -> None:
    """The sparse assembly sums the same terms as aft.evaluate's dense one (block writes
    and a scatter into a dense array): equal at a random point in and out of contact."""
    structure = {"chain": three_links, "epmc": three_links}.get(case)
    if case == "friction":
        structure = _friction_chain()
    elif case == "mast":
        structure = _small_mast()
    assert structure is not None
    model = from_structure(structure, 1e-3 if case == "friction" else 0.0)
    basis = aft.Basis.make(4, 64)
    xi = 3.0 if case == "epmc" else 0.0
    rng = np.random.default_rng(7)
    q = rng.normal(scale=2e-4, size=9 * model.n_dof)  # gaps of 1e-4: some samples in contact
    ev = aft.evaluate(model, basis, q, 350.0, np.ones(model.n_dof), negative_damping=xi)
    assert np.ptp(ev.tangent) > 0.0  # the joints' tangents change within the period
    sparse = solve.SparseJacobian(model, basis)(ev, 350.0, model.damping - xi * model.mass)
    dense = ev.jacobian
    assert sparse.shape == dense.shape
    np.testing.assert_allclose(sparse.toarray(), dense, rtol=0.0, atol=1e-13 * np.abs(dense).max())
    if case == "mast":
        assert sparse.nnz < 0.5 * dense.size  # it is sparse


def _count_sparse_tangents(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Count the continuation's sparse tangents (one entry per call) from now on."""
    calls: list[int] = []
    original = cont._sparse_tangent

    def counted(a: object, previous: np.ndarray) -> np.ndarray:
        calls.append(1)
        return original(a, previous)

    monkeypatch.setattr(cont, "_sparse_tangent", counted)
    return calls


def test_sparse_and_dense_tangents_follow_the_same_branch(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Above solve.SPARSE_ABOVE unknowns the Jacobian, the corrector and the continuation
    tangent are sparse; the same curve through the resonance as the dense route."""
    dense = frequency_response(three_links, FORCE, 300.0, 700.0, harmonics=5, max_points=25)
    calls = _count_sparse_tangents(monkeypatch)
    again = frequency_response(three_links, FORCE, 300.0, 700.0, harmonics=5, max_points=25)
    assert not calls  # 33 unknowns: the dense route
    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    sparse = frequency_response(three_links, FORCE, 300.0, 700.0, harmonics=5, max_points=25)
    assert len(calls) >= 24  # a sparse tangent at every point
    assert np.array_equal(again.omega, dense.omega)
    assert sparse.omega.size == dense.omega.size == 25
    np.testing.assert_allclose(sparse.omega, dense.omega, rtol=1e-10)
    size = float(np.abs(dense.coefficients).max())  # type: ignore[arg-type]
    np.testing.assert_allclose(sparse.coefficients, dense.coefficients, rtol=0.0, atol=1e-10 * size)
    assert np.array_equal(sparse.stable, dense.stable)


def test_sparse_start_homotopy_is_the_dense_one(
    three_links: Structure, monkeypatch: pytest.MonkeyPatch
) -> None:
    """When Newton from the linear guesses fails, the start follows the force up from a
    level inside the gaps; above SPARSE_ABOVE by the sparse corrector and tangent: the
    same orbit as the dense continuation, and one that solves HB."""
    from clearjoint.harmonic import response

    model = from_structure(three_links)
    basis = aft.Basis.make(5, 128)
    k_ref = model.reference_stiffness
    monkeypatch.setattr(response, "newton", lambda *args, **kwargs: None)
    dense = response._start_plain(model, basis, 400.0, FORCE, k_ref)
    calls = _count_sparse_tangents(monkeypatch)
    monkeypatch.setattr(solve, "SPARSE_ABOVE", 0)
    sparse = response._start_plain(model, basis, 400.0, FORCE, k_ref)
    assert calls
    size = float(np.abs(dense).max())
    np.testing.assert_allclose(sparse, dense, rtol=0.0, atol=1e-10 * size)
    ev = aft.evaluate(model, basis, sparse, 400.0, FORCE)
    assert float(np.abs(ev.residual).max()) < 1e-9 * k_ref * size


def test_epmc_sparse_jacobian_is_the_dense_one() -> None:
    """EPMC's bordered Jacobian assembled sparse (nonlinear_modes above SPARSE_ABOVE) holds
    the dense one's entries, the w and xi columns and the two phase rows included."""
    from clearjoint.harmonic.modes import epmc_residual

    model = from_structure(_small_mast())
    basis = aft.Basis.make(5, 64)
    n_u = 11 * model.n_dof
    rng = np.random.default_rng(11)
    z = np.concatenate((rng.normal(scale=0.5, size=n_u), [1.1, 0.02]))
    r, dense = epmc_residual(model, basis, z, 2e-4, 80.0, 2)
    r_s, sparse = epmc_residual(
        model, basis, z, 2e-4, 80.0, 2, sparse_jacobian=solve.SparseJacobian(model, basis)
    )
    assert np.array_equal(r, r_s)
    assert sparse.shape == dense.shape
    np.testing.assert_allclose(sparse.toarray(), dense, rtol=0.0, atol=1e-13 * np.abs(dense).max())


def test_epmc_sparse_jacobian_has_scipys_stacked_pattern() -> None:
    """The bordered CSR written directly holds exactly scipy's hstack/vstack of the blocks:
    the same entries, the explicit zeros of dR/dq kept and the zeros of the w and xi
    columns dropped (so the sparse LU sees the same matrix and ordering as before)."""
    import scipy.sparse

    from clearjoint.harmonic.modes import _sparse_epmc_jacobian

    rng = np.random.default_rng(3)
    n = 40
    jac = scipy.sparse.random(n, n, density=0.1, random_state=4, format="csr")
    jac.data[::5] = 0.0
    d_w, d_xi = rng.normal(size=n), rng.normal(size=n)
    d_w[rng.random(n) < 0.3] = 0.0
    d_xi[rng.random(n) < 0.3] = 0.0
    border = scipy.sparse.csr_matrix((np.ones(2), ([0, 1], [3, 17])), shape=(2, n + 2))
    stacked = scipy.sparse.vstack(
        (scipy.sparse.hstack((jac, np.column_stack((d_w, d_xi)))), border), format="csc"
    )
    direct = scipy.sparse.csc_matrix(_sparse_epmc_jacobian(jac, d_w, d_xi, 3, 17))
    stacked.sort_indices()
    direct.sort_indices()
    assert direct.nnz == stacked.nnz == jac.nnz + np.count_nonzero(d_w) + np.count_nonzero(d_xi) + 2
    assert np.array_equal(direct.indptr, stacked.indptr)
    assert np.array_equal(direct.indices, stacked.indices)
    assert np.array_equal(direct.data, stacked.data)
