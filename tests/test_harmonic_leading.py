"""The stability verdict of large structures (issue 25): Taylor stretches, warm starts, fallback.

Each by an independent route: scipy.linalg.expm of the dense generator, the eigenvalues
of the whole monodromy matrix, or a residual with no root.
"""

from __future__ import annotations

import logging
import math
import threading

import numpy as np
import pytest
import scipy.linalg

from clearjoint import ClearanceJoint
from clearjoint.exact.patterns import SHORT_STEP, PatternFlow, ShortFlow, chain, decompose
from clearjoint.harmonic import aft, frequency_response, monodromy
from clearjoint.harmonic.solve import newton
from clearjoint.harmonic.system import build
from clearjoint.structure import mast

BAYS = 4


@pytest.fixture(scope="module")
def curve() -> tuple[object, object, aft.Basis]:
    """Four points of the 4-bay mast (issue 25's hinges) at 10 N on the tip, from 0.8 x its
    first open mode: every orbit crosses the gap edges often, and 12 of its 21 contact
    patterns last under SHORT_LIMIT (two joints crossing their edges moments apart)."""
    structure = mast(
        BAYS, joints=ClearanceJoint(50e-6, 5e7, gap_stiffness=1e5), rayleigh=(0.0, 2e-6)
    )
    force = np.zeros(structure.n_dof)
    force[list(structure.dof_names).index(f"n{2 * BAYS + 1}x")] = 10.0
    w = float(structure.modes("open").omega[0])
    fr = frequency_response(
        structure, force, 0.8 * w, 2.0 * w, max_points=4, max_step=0.05, check_points=0
    )
    basis = aft.Basis.make(fr.settings["harmonics"], fr.settings["samples"])
    return structure, fr, basis


def _generator(model: object, state: np.ndarray) -> np.ndarray:
    n = model.n_dof  # type: ignore[attr-defined]
    inv_m = 1.0 / np.diag(model.mass)  # type: ignore[attr-defined]
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, n:] = -inv_m[:, None] * model.damping  # type: ignore[attr-defined]
    a[n:, :n] = -inv_m[:, None] * monodromy._pattern_stiffness(model, state)  # type: ignore[arg-type]
    return a


@pytest.mark.parametrize("units", [1e-6, 0.3, 3.9, 14.5])
def test_a_short_flow_is_the_exponential(
    curve: tuple[object, object, aft.Basis], units: float
) -> None:
    """ShortFlow.propagate = scipy.linalg.expm(A t) @ X (dense Pade, an independent route) on
    a block of 5 columns, for stretches from a millionth of a substep to four substeps."""
    structure, _, _ = curve
    model = build(structure, None, 1.0)
    state = np.ones(model.directions.shape[0], dtype=np.int64)  # every joint closed
    state[::2] = 0
    a = _generator(model, state)
    flow = ShortFlow.for_structure(
        1.0 / np.diag(model.mass), monodromy._pattern_stiffness(model, state), model.damping
    )
    t = units * SHORT_STEP / flow.bound
    assert flow.steps(t) == max(1, math.ceil(units))
    x = np.random.default_rng(1).standard_normal((a.shape[0], 5))
    x[model.n_dof :] *= 100.0  # velocities of the size the orbits' have
    exact = scipy.linalg.expm(a * t) @ x
    got = flow.propagate(t, x)
    assert np.linalg.norm(got - exact) <= 1e-12 * np.linalg.norm(exact)


def test_a_chain_mixing_short_and_decomposed_stretches_is_the_product(
    curve: tuple[object, object, aft.Basis],
) -> None:
    """chain over long (decomposed), short (Taylor) and long stretches again equals the
    product of dense exponentials."""
    structure, _, _ = curve
    model = build(structure, None, 1.0)
    n_j = model.directions.shape[0]
    states = [np.zeros(n_j, np.int64), np.ones(n_j, np.int64), -np.ones(n_j, np.int64)]
    states.append(states[0])
    generators = [_generator(model, s) for s in states]
    short = ShortFlow.for_structure(
        1.0 / np.diag(model.mass), monodromy._pattern_stiffness(model, states[1]), model.damping
    )
    times = [0.01, 2.0 / short.bound, 3e-3, 5e-3]
    flows = [decompose(generators[0]), short, decompose(generators[2]), decompose(generators[3])]
    assert isinstance(flows[0], PatternFlow)
    assert isinstance(flows[2], PatternFlow)
    keys = [s.tobytes() for s in states]
    x = np.random.default_rng(2).standard_normal((generators[0].shape[0], 3))
    got = chain(
        x,
        times,
        keys,
        lambda i: flows[i],  # type: ignore[return-value]
        lambda _k, source, _l, target: target.inverse @ source.vectors,
    )
    exact = x
    for a, t in zip(generators, times, strict=True):
        exact = scipy.linalg.expm(a * t) @ exact
    assert np.linalg.norm(got - exact) <= 1e-10 * np.linalg.norm(exact)


def test_the_leading_block_gives_the_whole_monodromys_multipliers_cold_and_warm(
    curve: tuple[object, object, aft.Basis], monkeypatch: pytest.MonkeyPatch
) -> None:
    """At each point, cold (random columns, the short patterns taken by Taylor) and warm
    (the last point's block, the short patterns met again: decomposed): the leading
    multipliers equal the eigenvalues of the whole monodromy matrix (formed by the
    decompositions alone) to 1e-9 of the largest; the warm start needs no more passes
    than the cold one."""
    structure, fr, basis = curve
    model = build(structure, None, 1.0)
    monkeypatch.setattr(monodromy, "LEADING_ABOVE", 0)  # 2N = 32: forced onto the block
    monodromy.clear_cache()
    block = None
    taylor = []
    original = ShortFlow.propagate

    def counted(self: ShortFlow, t: float, phi: np.ndarray) -> np.ndarray:
        taylor.append(t)
        return original(self, t, phi)

    monkeypatch.setattr(ShortFlow, "propagate", counted)
    for i in range(fr.omega.size):
        coef, w = fr.coefficients[i], float(fr.omega[i])
        monodromy.clear_cache()  # the cold start meets the short patterns first: Taylor
        cold = monodromy.leading_block(model, basis, coef, w)
        met = len(taylor)
        warm = monodromy.leading_block(model, basis, coef, w, block)
        assert len(taylor) == met  # met again by another orbit: decomposed, not Taylor
        exact = monodromy.multipliers(model, basis, coef, w)
        for found in (cold, warm):
            assert not found.full
            k = found.block.shape[1]
            np.testing.assert_allclose(
                np.abs(found.multipliers[:k]), np.abs(exact[:k]), rtol=0, atol=1e-9 * abs(exact[0])
            )
            assert (abs(found.multipliers[0]) < 1.0) == (abs(exact[0]) < 1.0)
        assert warm.passes <= cold.passes
        block = warm.block
    assert taylor  # the short patterns went through Taylor's series
    monodromy.clear_cache()


def test_a_block_that_never_converges_falls_back_to_the_whole_monodromy_and_says_so(
    curve: tuple[object, object, aft.Basis],
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    """With an invariance test no block can pass, every point takes the whole monodromy:
    its multipliers are exactly those of monodromy.multipliers, the point is listed in
    settings["monodromy_full"] and a warning is logged."""
    structure, fr, basis = curve
    model = build(structure, None, 1.0)
    monkeypatch.setattr(monodromy, "LEADING_ABOVE", 0)
    monkeypatch.setattr(monodromy, "_INVARIANT", -1.0)
    coef, w = fr.coefficients[0], float(fr.omega[0])
    found = monodromy.leading_block(model, basis, coef, w)
    assert found.full
    assert found.block is None
    np.testing.assert_array_equal(found.multipliers, monodromy.multipliers(model, basis, coef, w))
    assert "full=True" in repr(found)
    force = np.zeros(structure.n_dof)
    force[list(structure.dof_names).index(f"n{2 * BAYS + 1}x")] = 10.0
    with caplog.at_level(logging.WARNING, logger="clearjoint.harmonic"):
        again = frequency_response(
            structure, force, fr.omega[0], 2.0 * fr.omega[0], max_points=2, check_points=0
        )
    assert again.settings["monodromy_full"] == [0, 1]
    assert any("did not converge at 2 point(s)" in r.getMessage() for r in caplog.records)


def test_newton_that_stalls_is_given_up_early() -> None:
    """R(q) = q^2 + 1 has no real root: Newton's residual never halves. With stall=10 it
    stops after about 10 iterations (counted evaluations), without after max_iterations;
    on R(q) = q^2 - 4 from 3 it converges to 2 either way."""
    calls = []

    def no_root(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        calls.append(1)
        return q**2 + 1.0, np.diag(2.0 * q + 1e-3)

    assert newton(no_root, np.array([0.3]), 1.0, max_iterations=80, stall=10) is None
    stalled = len(calls)
    calls.clear()
    assert newton(no_root, np.array([0.3]), 1.0, max_iterations=80) is None
    assert stalled < 16 * 13 < len(calls)  # at most ~11 iterations of up to 13 trials

    def root(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return q**2 - 4.0, np.diag(2.0 * q)

    for stall in (None, 10):
        found = newton(root, np.array([3.0]), 1.0, stall=stall)
        assert found is not None
        assert found[0][0] == pytest.approx(2.0, rel=1e-12)


def test_an_orbit_too_big_for_the_caches_keeps_the_block_route(
    curve: tuple[object, object, aft.Basis], monkeypatch: pytest.MonkeyPatch
) -> None:
    """With no room in either cache (as the 80-bay mast's orbits), the block route holds its
    decompositions for the orbit alone and passes between patterns through y instead of
    forming transitions: its multipliers still equal the eigenvalues of the monodromy
    matrix, which then is the plain product of scipy.linalg.expm (no decomposition)."""
    structure, fr, basis = curve
    model = build(structure, None, 1.0)
    monkeypatch.setattr(monodromy, "LEADING_ABOVE", 0)
    monkeypatch.setattr(monodromy._FLOWS, "limit", 0)
    monkeypatch.setattr(monodromy._TRANSITIONS, "limit", 0)
    monodromy.clear_cache()
    formed = []
    original = monodromy._transition

    def counted(*args: object) -> np.ndarray:
        formed.append(1)
        return original(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(monodromy, "_transition", counted)
    coef, w = fr.coefficients[-1], float(fr.omega[-1])
    found = monodromy.leading_block(model, basis, coef, w)
    assert not formed
    assert not found.full
    exact = monodromy.multipliers(model, basis, coef, w)
    k = found.block.shape[1]
    np.testing.assert_allclose(
        np.abs(found.multipliers[:k]), np.abs(exact[:k]), rtol=0, atol=1e-9 * abs(exact[0])
    )
    monodromy.clear_cache()


def test_short_patterns_stay_taylor_when_the_orbits_patterns_would_not_all_fit(
    curve: tuple[object, object, aft.Basis], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A cache that holds the curve's long patterns but not all of an orbit's patterns (as
    the 80-bay mast's: 137 long ones, 856 MiB of 1 GiB): the short patterns are not
    decomposed when met again (they would evict the long ones, decomposed again at every
    pass). Along the curve, warm, only the long patterns are decomposed, each once; the
    short ones keep Taylor's series; the leading multipliers equal the eigenvalues of the
    whole monodromy (the plain expm product, the cache being too small for it) to 1e-9."""
    structure, fr, basis = curve
    model = build(structure, None, 1.0)
    monkeypatch.setattr(monodromy, "LEADING_ABOVE", 0)
    bound = monodromy._short_bound(model)
    long_keys: set[bytes] = set()
    totals = []
    for i in range(fr.omega.size):
        widths, states = monodromy._segments(model, basis, fr.coefficients[i])
        longest: dict[bytes, float] = {}
        for state, width in zip(states, widths, strict=True):
            key = state.tobytes()
            longest[key] = max(longest.get(key, 0.0), float(width) / float(fr.omega[i]))
        long_keys |= {k for k, t in longest.items() if bound * t > monodromy.SHORT_LIMIT}
        totals.append(len(longest))
    matrix_bytes = (2 * model.n_dof) ** 2 * 8
    limit = 2 * matrix_bytes * len(long_keys)  # room for every long pattern of the curve
    assert all(2 * matrix_bytes * total > limit for total in totals)  # not for all of one orbit
    monodromy.clear_cache()
    monkeypatch.setattr(monodromy._FLOWS, "limit", limit)
    decomposed = []
    taylor = []
    original, propagate = monodromy._decompose, ShortFlow.propagate

    def counted(a: np.ndarray) -> object:
        decomposed.append(1)
        return original(a)

    def stepped(self: ShortFlow, t: float, phi: np.ndarray) -> np.ndarray:
        taylor.append(t)
        return propagate(self, t, phi)

    monkeypatch.setattr(ShortFlow, "propagate", stepped)
    block = None
    for i in range(fr.omega.size):
        coef, w = fr.coefficients[i], float(fr.omega[i])
        monkeypatch.setattr(monodromy, "_decompose", counted)
        before = len(taylor)
        found = monodromy.leading_block(model, basis, coef, w, block)
        assert len(taylor) > before  # the short patterns, met again or not: Taylor
        monkeypatch.setattr(monodromy, "_decompose", original)
        exact = monodromy.multipliers(model, basis, coef, w)
        k = found.block.shape[1]
        np.testing.assert_allclose(
            np.abs(found.multipliers[:k]), np.abs(exact[:k]), rtol=0, atol=1e-9 * abs(exact[0])
        )
        block = found.block
    assert len(decomposed) == len(long_keys)  # each long pattern once, no short one
    monodromy.clear_cache()


def _operator_with(moduli: list[float], size: int, seed: int) -> np.ndarray:
    """A real (size, size) matrix with the given eigenvalue moduli (pairs where a modulus
    repeats: a +- ib at that modulus), the rest 1e-12, in random well-conditioned axes."""
    rng = np.random.default_rng(seed)
    blocks = np.zeros((size, size))
    i, j = 0, 0
    while i < len(moduli):
        if i + 1 < len(moduli) and moduli[i + 1] == moduli[i]:
            r = moduli[i]
            blocks[j : j + 2, j : j + 2] = r * np.array([[0.6, 0.8], [-0.8, 0.6]])
            i, j = i + 2, j + 2
        else:
            blocks[j, j] = moduli[i]
            i, j = i + 1, j + 1
    for m in range(j, size):
        blocks[m, m] = 1e-12
    axes = np.linalg.qr(rng.standard_normal((size, size)))[0] + 0.1 * np.eye(size)
    return np.asarray(axes @ blocks @ np.linalg.inv(axes), dtype=np.float64)


def test_the_leading_part_of_a_block_splitting_a_pair_is_accepted_and_exact() -> None:
    """A block of 4 columns whose last two split a complex pair is never invariant as a
    whole; its leading part (3 multipliers, a gap below them) is, and its Ritz values are
    the matrix's own eigenvalues (numpy's eigvals of the whole matrix, an independent
    route). A random block that is not converged gives None."""
    phi = _operator_with([5.0, 2.0, 0.9, 1e-3, 1e-3], 40, seed=1)
    rng = np.random.default_rng(2)
    q = np.linalg.qr(rng.standard_normal((40, 4)))[0]
    assert monodromy._invariant_part(q, phi @ q, q.T @ phi @ q) is None
    for _ in range(60):  # subspace iteration: the leading 3 converge, the pair rotates
        q = np.linalg.qr(phi @ q)[0]
    z = phi @ q
    b = q.T @ z
    assert np.linalg.norm(z - q @ b) > 1e-6 * np.linalg.norm(z)  # the whole block is not
    part = monodromy._invariant_part(q, z, b)
    assert part is not None
    assert part.size == 3
    exact = np.linalg.eigvals(phi)
    exact = exact[np.argsort(-np.abs(exact))][:3]
    np.testing.assert_allclose(np.sort(part.real), np.sort(exact.real), rtol=1e-9)


def test_a_doubled_block_is_narrowed_to_its_leading_directions_for_the_next_point() -> None:
    """An invariant block of 24 columns on a matrix with 16 multipliers from 3 down, a pair
    at 1e-6 (above 1e-7 of the largest: kept) and the rest 1e-12 is narrowed to the 18
    leading Schur vectors (at least _LEADING = 16, at a gap below 1e-7 of the largest),
    which span an invariant subspace of the matrix (its
    own residual, measured); with no such gap the block is kept whole."""
    moduli = [3.0 / 1.5**i for i in range(16)] + [1e-6, 1e-6]
    phi = _operator_with(moduli, 60, seed=3)
    q = np.linalg.qr(np.random.default_rng(4).standard_normal((60, 24)))[0]
    for _ in range(40):
        q = np.linalg.qr(phi @ q)[0]
    b = q.T @ phi @ q
    ritz = np.linalg.eigvals(b)
    ritz = ritz[np.argsort(-np.abs(ritz))]
    narrow = monodromy._narrowed(q, b, ritz)
    assert narrow.shape == (60, 18)
    np.testing.assert_allclose(narrow.T @ narrow, np.eye(18), atol=1e-12)
    resid = phi @ narrow - narrow @ (narrow.T @ phi @ narrow)
    assert np.linalg.norm(resid) <= 1e-9 * np.linalg.norm(phi @ narrow)
    b = np.diag(1.0 - 0.01 * np.arange(24))  # no gap anywhere inside the block
    assert monodromy._narrowed(q, b, np.diag(b).astype(complex)) is q


def test_a_pass_split_among_threads_gives_the_same_multipliers(
    curve: tuple[object, object, aft.Basis], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The leading block's passes split by columns among two threads (forced on the 4-bay
    mast, below SPLIT_ABOVE), with the orbit's patterns decomposed side by side: the same
    multipliers as one thread to rounding, and the eigenvalues of the whole monodromy
    (formed on one thread) to 1e-9 of the largest."""
    structure, fr, basis = curve
    model = build(structure, None, 1.0)
    monkeypatch.setattr(monodromy, "LEADING_ABOVE", 0)
    coef, w = fr.coefficients[-1], float(fr.omega[-1])
    monkeypatch.setattr(monodromy, "_WORKERS", 1)
    monodromy.clear_cache()
    exact = monodromy.multipliers(model, basis, coef, w)
    monodromy.clear_cache()
    alone = monodromy.leading_block(model, basis, coef, w)
    monkeypatch.setattr(monodromy, "_WORKERS", 2)
    monkeypatch.setattr(monodromy, "SPLIT_ABOVE", 0)
    monodromy.clear_cache()
    split = monodromy.leading_block(model, basis, coef, w)
    k = np.count_nonzero(split.multipliers)
    assert k >= 1
    np.testing.assert_allclose(
        np.abs(split.multipliers[:k]), np.abs(alone.multipliers[:k]), rtol=1e-12, atol=1e-13
    )
    np.testing.assert_allclose(
        np.abs(split.multipliers[:k]), np.abs(exact[:k]), rtol=0, atol=1e-9 * abs(exact[0])
    )
    monodromy.clear_cache()


def test_overlapping_one_blas_thread_sections_restore_the_callers_limit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Two threads inside the BLAS limit at once, the first leaving first (two orbits'
    passes side by side): BLAS stays on one thread until the last leaves, then the
    caller's own limit (2) is back. threadpoolctl's limiter is replaced by a stand-in
    with its semantics (process-wide, each limiter restores what it found when made):
    OpenBLAS's own count, read back from threads, depends on which thread set it last."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    current = [2]

    class Limits:
        def __init__(self, limits: int, user_api: str) -> None:
            self.original = current[0]
            current[0] = limits

        def restore_original_limits(self) -> None:
            current[0] = self.original

        def __enter__(self) -> Limits:
            return self

        def __exit__(self, *exc: object) -> None:
            self.restore_original_limits()

    monkeypatch.setattr(threadpoolctl, "threadpool_limits", Limits)
    entered, second_in, left_first = threading.Event(), threading.Event(), threading.Event()
    seen: list[int] = []

    def first() -> None:
        with monodromy._one_blas_thread():
            entered.set()
            second_in.wait(5)
        left_first.set()

    def second() -> None:
        entered.wait(5)
        with monodromy._one_blas_thread():
            second_in.set()
            left_first.wait(5)
            seen.append(current[0])

    threads = [threading.Thread(target=first), threading.Thread(target=second)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    assert seen == [1]
    assert current == [2]


def test_no_leading_part_is_accepted_that_leaves_out_a_ritz_value_near_the_circle() -> None:
    """Multipliers 5, 2, 1.8, then 0.8 and 0.79 (then 1e-12), a block of 4 columns after
    subspace iteration: the leading 3 are invariant and a gap lies below them, but the
    4th column, between 0.8 and 0.79, has not converged, and its Ritz value (near 0.8,
    above _DROPPED = 0.5) is left out: the part is refused (a multiplier near the circle
    must not drop out of the events' tests). With 0.1 and 0.099 instead the same part is
    accepted (5, 2, 1.8: numpy's eigvals of the matrix)."""
    for low, accepted in ((0.8, False), (0.1, True)):
        phi = _operator_with([5.0, 2.0, 1.8, low, 0.9875 * low], 40, seed=5)
        q = np.linalg.qr(np.random.default_rng(6).standard_normal((40, 4)))[0]
        for _ in range(80):
            q = np.linalg.qr(phi @ q)[0]
        z = phi @ q
        b = q.T @ z
        assert np.linalg.norm(z - q @ b) > 1e-6 * np.linalg.norm(z)  # not invariant whole
        ritz = np.sort(np.abs(np.linalg.eigvals(b)))[::-1]
        assert ritz[3] <= monodromy._GAP * ritz[2]  # a gap: the part would pass the residual
        part = monodromy._invariant_part(q, z, b)
        if not accepted:
            assert ritz[3] > 0.5
            assert part is None
        else:
            assert part is not None
            assert part.size == 3
            np.testing.assert_allclose(np.abs(part), [5.0, 2.0, 1.8], rtol=1e-9)


def test_patterns_decomposed_side_by_side_enter_the_cache_as_each_is_done(
    curve: tuple[object, object, aft.Basis], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Eight new patterns of the 4-bay mast decomposed by two threads: each enters the
    cache as soon as it is done, so when the i-th decomposition starts at least i - 1
    are stored (the two threads' in flight aside), and no more than two are ever held
    outside the cache (its 1 GiB cap then bounds the memory); all eight end stored."""
    structure, _, _ = curve
    model = build(structure, None, 1.0)
    rng = np.random.default_rng(7)
    n_j = model.directions.shape[0]
    states = np.unique(rng.integers(-1, 2, size=(40, n_j)), axis=0)[:8]
    keys = [state.tobytes() for state in states]
    n = model.n_dof
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, n:] = -(1.0 / np.diag(model.mass))[:, None] * model.damping
    system_key = monodromy._fingerprint(model)
    lock = threading.Lock()
    stored_at_start: list[int] = []
    decompose = monodromy._decompose

    def counting(generator: np.ndarray) -> object:
        with lock:
            held = sum(monodromy._FLOWS.get((system_key, key))[0] for key in keys)
            stored_at_start.append(int(held))
        return decompose(generator)

    monkeypatch.setattr(monodromy, "_decompose", counting)
    monkeypatch.setattr(monodromy, "_WORKERS", 2)
    monodromy.clear_cache()
    monodromy._decompose_patterns(model, system_key, states, keys, keys, a, None)
    assert len(stored_at_start) == 8
    assert all(held >= i - 1 for i, held in enumerate(stored_at_start))
    assert all(monodromy._FLOWS.get((system_key, key))[0] for key in keys)
    monodromy.clear_cache()
