"""Floquet multipliers of a harmonic-balance orbit of a structure, from its exact monodromy.

MODEL.md 5.3 (stability of the periodic response). Linearised about the HB orbit
u(t), a perturbation obeys M y'' + C y' + K_T(t) y = 0 with K_T(t) = K + sum_j
b_j k_j(t) b_j^T, and each joint's tangent k_j(t) is piecewise constant (k0, k0 + k_c
or k0 + k_t: MODEL.md section 0). Between two instants where some b_j^T u(t) crosses a
gap edge the perturbation equation is linear with constant coefficients, so the
monodromy matrix is exactly the ordered product of matrix exponentials

    Phi = expm(A_m dt_m) ... expm(A_1 dt_1),  A = [[0, I], [-M^-1 K_T, -M^-1 C]],

and the 2N Floquet multipliers are its eigenvalues. The crossing instants are
roots of the orbit's trigonometric polynomial, located between the AFT samples
where a joint's state changes. No exponent has to be picked out of Hill's
truncated eigenproblem (whose 2N (2H + 1) eigenvalues hold each family lambda + i k
w once per shift, and whose smallest-abs(Im) members are not the resolved ones when
the structure's higher modes lie above H w): the only approximation left is the
HB orbit itself (a crossing the samples do not see, shorter than 2 pi / N_t,
is missed).

With Coulomb friction (regularised, mu_s P tanh(v_j / v_eps) on each joint's relative
speed v_j = b_j^T u') the perturbation also sees a time-varying damping C_T(t) = C +
sum_j b_j c_j(t) b_j^T, c_j = mu_s P (1 - tanh^2(v_j / v_eps)) / v_eps, smooth but
steep where v_j passes 0. There the monodromy is integrated instead
(:func:`integrated_monodromy`): the matrix equation Phi' = A(t) Phi over one period
by scipy's adaptive DOP853, restarted at every gap-edge crossing (K_T jumps) and at
every zero of a rubbing joint's relative speed (the peak of c_j, which an adaptive
step must not skip). Its cost grows as (2N)^2 states, so it is meant for small
structures.

Speed. Each segment's exponential depends on the contact pattern only through A, and
the patterns recur: within one orbit (a joint opens and closes more than once) and,
above all, from one continuation point to the next (the first 30 points of the 20-bay
mast's curve: 85 to 93 segments a period, 43 to 47 patterns each, 49 in all; the counts
over whole curves are printed by ``benchmarks/bench_harmonic.py --monodromy``). So each
pattern's A is decomposed
once, A = V B V^-1 with B real block-diagonal (1 x 1 blocks for real eigenvalues,
[[a, b], [-b, a]] for a pair a +- i b), after a diagonal balancing by powers of 2; then
expm(A t) = V expm(B t) V^-1 exactly, expm(B t) is closed form (e^(a t) times a rotation
by b t), and the product is carried in the patterns' eigen-coordinates: one (2N)^2
scaling and one matrix product V_q^-1 V_p per segment, the transition V_q^-1 V_p cached
per pair of patterns, instead of a Pade approximant with about log2(norm(A t))
squarings. The decompositions live in a bounded cache (``_FLOW_BYTES``) keyed by the
system's matrices and the pattern, so neighbouring curve points share them
(:func:`clear_cache` frees them). A pattern whose V is badly conditioned (1-norm
condition above ``clearjoint.exact.patterns.MAX_CONDITION``: a defective A, e.g. a free
mass with no damping, or nearly parallel eigenvectors) keeps ``scipy.linalg.expm``, and
so does an orbit whose patterns would not fit in the cache.
``method="expm"`` forces the plain product (the reference the tests compare with).
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.linalg
from numpy.typing import NDArray
from scipy.integrate import solve_ivp

from clearjoint.errors import ParameterError
from clearjoint.exact.patterns import PatternFlow as _Flow
from clearjoint.exact.patterns import ShortFlow, Stretch, chain
from clearjoint.exact.patterns import decompose as _decompose
from clearjoint.harmonic.aft import Basis
from clearjoint.harmonic.system import HarmonicError, LinearSystem
from clearjoint.parallel import usable_cores

FloatArray = NDArray[np.float64]

#: Bisection steps that place a gap-edge crossing between two samples (2^-40 of a sample).
_BISECTIONS = 40


def _states(delta: FloatArray, system: LinearSystem) -> NDArray[np.int64]:
    """Contact state of each joint: 1 beyond the compression edge, -1 beyond tension, 0 open."""
    return np.asarray(
        (delta > system.g_c).astype(np.int64) - (delta < -system.g_t).astype(np.int64)
    )


def crossings(system: LinearSystem, basis: Basis, coefficients: FloatArray) -> FloatArray:
    """Return the phases tau in [0, 2 pi) where some joint's b_j^T u crosses a gap edge.

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.

    Returns
    -------
    (k,) ndarray
        Sorted crossing phases, rad (tau = w t), each to 2^-40 of a sample interval.
    """
    rel = coefficients @ system.directions.T  # (2H + 1, n_j)
    n_t = basis.samples
    delta = basis.to_time @ rel  # (N_t, n_j)
    state = _states(delta, system)
    change = state != np.roll(state, -1, axis=0)
    rows, joints = np.nonzero(change)
    if rows.size == 0:
        return np.zeros(0)
    # the edge crossed: the compression one if either end is beyond it, else the tension one
    nxt = (rows + 1) % n_t
    compress = (state[rows, joints] == 1) | (state[nxt, joints] == 1)
    edge = np.where(compress, system.g_c[joints], -system.g_t[joints])
    return _bisect(basis, rel[:, joints], edge, rows)


def _bisect(
    basis: Basis, columns: FloatArray, level: FloatArray, rows: NDArray[np.intp]
) -> FloatArray:
    """Sorted phases where column k of ``columns`` (2H + 1, k) crosses ``level[k]`` inside the
    sample interval ``rows[k]`` (where its sign changes), by bisection to 2^-40 of it."""
    step = 2.0 * math.pi / basis.samples
    lo = np.asarray(rows * step, dtype=np.float64)
    hi = lo + step
    f_lo = basis.evaluate_each(columns, lo) - level
    for _ in range(_BISECTIONS):
        mid = np.asarray(0.5 * (lo + hi), dtype=np.float64)
        f_mid = basis.evaluate_each(columns, mid) - level
        same = np.sign(f_mid) == np.sign(f_lo)
        lo = np.where(same, mid, lo)
        f_lo = np.where(same, f_mid, f_lo)
        hi = np.where(same, hi, mid)
    return np.sort(np.mod(0.5 * (lo + hi), 2.0 * math.pi))


def _pattern_stiffness(system: LinearSystem, state: NDArray[np.int64]) -> FloatArray:
    """K plus each joint's tangent in its contact state (1 compression, -1 tension), N/m."""
    k_j = system.k0 + system.k_c * (state == 1) + system.k_t * (state == -1)
    b = system.directions
    return np.asarray(system.stiffness + (b.T * k_j) @ b, dtype=np.float64)


#: Bytes the decompositions may hold (the 40-bay mast's orbits need about 200 MiB each;
#: 1 GiB since issue 25 holds about 160 of the 80-bay mast's, 6.5 MB each), and the
#: transitions between patterns; each store drops its least recently used entries first.
#: An orbit whose own patterns' decompositions would not fit keeps scipy.linalg.expm for
#: the whole Phi, and holds them for itself alone on the leading block's route (a
#: transition that does not fit only costs its one matrix product again).
_FLOW_BYTES = 1024 * 2**20
_TRANSITION_BYTES = 256 * 2**20


class _Cache:
    """A bounded, thread-safe least-recently-used store of decompositions and transitions."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self.held = 0
        self._items: OrderedDict[tuple[bytes, ...], tuple[object, int]] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: tuple[bytes, ...]) -> tuple[bool, object]:
        """Return (found, value), marking the key as recently used."""
        with self._lock:
            item = self._items.get(key)
            if item is None:
                return False, None
            self._items.move_to_end(key)
            return True, item[0]

    def put(self, key: tuple[bytes, ...], value: object, size: int) -> None:
        """Store ``value`` (``size`` bytes), evicting the least recently used beyond the limit."""
        with self._lock:
            old = self._items.pop(key, None)
            if old is not None:
                self.held -= old[1]
            self._items[key] = (value, size)
            self.held += size
            while self.held > self.limit and len(self._items) > 1:
                _, (_, freed) = self._items.popitem(last=False)
                self.held -= freed

    def clear(self) -> None:
        """Forget everything."""
        with self._lock:
            self._items.clear()
            self.held = 0


_FLOWS = _Cache(_FLOW_BYTES)
_TRANSITIONS = _Cache(_TRANSITION_BYTES)
#: The short patterns' Taylor flows (:class:`ShortFlow`: a sparse A, about 100 kB at 2N =
#: 640), kept across orbits: building one costs a dense (N, N) pattern stiffness and its
#: conversion, 0.7 s a point on the 80-bay mast's 134 short patterns before issue 25's
#: fourth round, when each orbit built its own.
_SHORT_FLOW_BYTES = 64 * 2**20
_SHORT_FLOWS = _Cache(_SHORT_FLOW_BYTES)
#: The short patterns met so far (each counted as 1 "byte": up to 65536 of them), marked
#: by the orbit that met them first.
_SEEN_SHORT = _Cache(2**16)


def clear_cache() -> None:
    """Free the cached decompositions, transitions and short flows (up to 1.3 GiB; module
    docstring)."""
    _FLOWS.clear()
    _TRANSITIONS.clear()
    _SEEN_SHORT.clear()
    _SHORT_FLOWS.clear()


def _fingerprint(system: LinearSystem) -> bytes:
    """A digest of what A depends on: M, C, K, the joint directions and tangents."""
    digest = hashlib.blake2b(digest_size=16)
    for array in (
        system.mass,
        system.damping,
        system.stiffness,
        system.directions,
        system.k0,
        system.k_c,
        system.k_t,
    ):
        digest.update(np.ascontiguousarray(array, dtype=np.float64).tobytes())
        digest.update(str(np.shape(array)).encode())
    return digest.digest()


def _segments(
    system: LinearSystem, basis: Basis, coefficients: FloatArray
) -> tuple[FloatArray, NDArray[np.int64]]:
    """The phase widths (k + 1,) between gap-edge crossings and each one's contact state."""
    rel = coefficients @ system.directions.T
    edges = np.concatenate(([0.0], crossings(system, basis, coefficients), [2.0 * math.pi]))
    middles = 0.5 * (edges[:-1] + edges[1:])
    return np.diff(edges), _states(basis.evaluate(rel, middles), system)


def monodromy(
    system: LinearSystem,
    basis: Basis,
    coefficients: FloatArray,
    omega: float,
    *,
    method: Literal["eigen", "expm"] = "eigen",
) -> FloatArray:
    """Return the monodromy matrix of the HB orbit's linearisation, (2N, 2N).

    Parameters
    ----------
    system : LinearSystem
        Without friction (its tangent would not be piecewise constant): with
        friction use :func:`integrated_monodromy`.
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.
    method : {"eigen", "expm"}
        ``"eigen"``: each contact pattern's cached eigen-decomposition, chained in
        eigen-coordinates, ``scipy.linalg.expm`` where it is ill-conditioned (module
        docstring, "Speed"). ``"expm"``: ``scipy.linalg.expm`` on every segment.

    Returns
    -------
    (2N, 2N) ndarray
        Phi, mapping (y(0), y'(0)) to (y(T), y'(T)), T = 2 pi / w.

    Raises
    ------
    ParameterError
        ``method`` is neither "eigen" nor "expm".
    """
    if method not in ("eigen", "expm"):
        raise ParameterError(f"method must be 'eigen' or 'expm', got {method!r}")
    return _product(system, basis, coefficients, omega, method)(np.eye(2 * system.n_dof))


def _product(
    system: LinearSystem,
    basis: Basis,
    coefficients: FloatArray,
    omega: float,
    method: Literal["eigen", "expm"] = "eigen",
    short: bool = False,
) -> Callable[[FloatArray], FloatArray]:
    """Return x -> Phi @ x for x (2N, m): the orbit's segments found once, the product
    applied to any block (the identity for Phi itself, a few columns for
    :func:`leading_multipliers`), as :func:`monodromy` describes. ``short``: a pattern
    whose stretches are all short (``SHORT_LIMIT``) is not decomposed but taken by
    Taylor's series on the block (:class:`~clearjoint.exact.patterns.ShortFlow`: cheap on
    a few columns; on the 2N columns of Phi itself the decomposition is cheaper)."""
    n = system.n_dof
    inv_m = 1.0 / np.diag(system.mass)
    widths, states = _segments(system, basis, coefficients)
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    a[n:, n:] = -inv_m[:, None] * system.damping
    keys = [state.tobytes() for state in states]
    # a pattern whose every stretch is short: Taylor's series on the block (ShortFlow),
    # no decomposition (module docstring, "Speed")
    longest: dict[bytes, float] = {}
    for key, width in zip(keys, widths, strict=True):
        longest[key] = max(longest.get(key, 0.0), float(width) / omega)
    bound = _short_bound(system) if short and method == "eigen" else math.inf
    decomposed = [key for key, t in longest.items() if not short or bound * t > SHORT_LIMIT]
    # each decomposition holds two (2N, 2N) matrices; if the orbit's own would not fit,
    # they would evict each other at every segment: on the whole Phi expm is cheaper then,
    # on a block they are held for this orbit alone (``local``)
    fits = 2 * len(decomposed) * a.nbytes <= _FLOWS.limit
    # the short patterns are decomposed when met again only if all the orbit's patterns fit:
    # else they would evict the long ones, to be decomposed again at every pass (the 80-bay
    # mast: 2N = 640, 6.5 MB a decomposition)
    room = 2 * len(longest) * a.nbytes <= _FLOWS.limit
    eigen = method == "eigen" and (fits or short)
    local: dict[bytes, _Flow | None] | None = None if fits else {}
    system_key = _fingerprint(system) if eigen else b""
    if eigen:  # the patterns flow_of would decompose, side by side beforehand
        wanted = list(decomposed)
        if short and local is None and room:  # short ones met by another orbit before
            for key, t in longest.items():
                if bound * t <= SHORT_LIMIT and not _FLOWS.get((system_key, key))[0]:
                    seen, _ = _SEEN_SHORT.get((system_key, key))
                    if seen:
                        wanted.append(key)
        _decompose_patterns(system, system_key, states, keys, wanted, a, local)
    # on a block, a transition V_q^-1 V_p costs (2N)^3 to form against 2 (2N)^2 k to pass
    # through y: formed and cached only if the orbit's would fit in the cache
    pairs = len(set(itertools.pairwise(keys)))
    transitions = not short or pairs * a.nbytes <= _TRANSITIONS.limit
    taylor: dict[bytes, ShortFlow] = {}
    token = object()  # this orbit's mark in _SEEN_SHORT

    def flow_of(i: int) -> Stretch:
        key = keys[i]
        if eigen:
            if local is None:
                found, cached = _FLOWS.get((system_key, key))
            else:
                found, cached = key in local, local.get(key)
            if not found and bound * longest[key] <= SHORT_LIMIT:
                # Taylor the first orbit a short pattern is met in; decomposed (and cached)
                # when another orbit meets it again: a pattern that recurs along the curve
                # costs one decomposition, one that does not costs none
                seen, mark = _SEEN_SHORT.get((system_key, key))
                if local is not None or not room or not seen or mark is token:
                    _SEEN_SHORT.put((system_key, key), token, 1)
                    if key not in taylor:
                        taylor[key] = _short_flow(system_key, key, system, inv_m, states[i])
                    return taylor[key]
            if not found:
                cached = _decompose_held(system, system_key, key, states[i], a, inv_m, local)
            if isinstance(cached, _Flow):
                return cached
        # the plain exponential (the reference and the fallback)
        return _generator(system, states[i], a, inv_m)

    def apply(start: FloatArray) -> FloatArray:
        return chain(start, widths / omega, keys, flow_of, transition)

    def transition(
        source_key: bytes, source: _Flow, target_key: bytes, target: _Flow
    ) -> FloatArray | None:
        if not transitions:
            return None
        return _transition(system_key, source_key, source, target_key, target)

    return apply


#: Threads that decompose an orbit's new patterns side by side (each with one BLAS thread:
#: LAPACK's eigensolver gains little from more, and on a shared machine OpenBLAS's own
#: threads slowed one decomposition of the 80-bay mast's 640 x 640 A tenfold, 0.5 s to
#: 2-9 s, when another process held a core).
_WORKERS = max(1, min(4, usable_cores()))


def _decompose_patterns(
    system: LinearSystem,
    system_key: bytes,
    states: NDArray[np.int64],
    keys: list[bytes],
    wanted: list[bytes],
    a: FloatArray,
    local: dict[bytes, _Flow | None] | None,
) -> None:
    """Decompose the patterns of ``wanted`` not held yet (in the cache, or in ``local`` for
    an orbit too big for it) in ``_WORKERS`` threads, BLAS on one thread meanwhile, and
    store them as :func:`_product`'s ``flow_of`` would one by one: the same
    decompositions (each is its own LAPACK call), only side by side. The first point of
    the 80-bay curve decomposes 137 patterns (0.5 s each on one core)."""
    first: dict[bytes, int] = {}
    for i, key in enumerate(keys):
        first.setdefault(key, i)
    if local is None:
        missing = [key for key in wanted if not _FLOWS.get((system_key, key))[0]]
    else:
        missing = [key for key in wanted if key not in local]
    if len(missing) < 2 or _WORKERS < 2:
        return
    inv_m = 1.0 / np.diag(system.mass)

    def one(key: bytes) -> None:
        # stored at once (the cache evicts as it goes): held until all were done, an
        # orbit's new decompositions would sit beside a full cache, up to twice its 1 GiB
        _decompose_held(system, system_key, key, states[first[key]], a, inv_m, local)

    with _one_blas_thread(), ThreadPoolExecutor(_WORKERS) as pool:
        for _ in pool.map(one, missing):  # a worker's exception is raised here
            pass


def _generator(
    system: LinearSystem, state: NDArray[np.int64], a: FloatArray, inv_m: FloatArray
) -> FloatArray:
    """The pattern's A: a copy of ``a`` (its pattern-free blocks) with -M^-1 K_T below left
    (a copy: passes and decompositions run in threads)."""
    n = system.n_dof
    generator = a.copy()
    generator[n:, :n] = -inv_m[:, None] * _pattern_stiffness(system, state)
    return generator


def _decompose_held(
    system: LinearSystem,
    system_key: bytes,
    key: bytes,
    state: NDArray[np.int64],
    a: FloatArray,
    inv_m: FloatArray,
    local: dict[bytes, _Flow | None] | None,
) -> _Flow | None:
    """Decompose the pattern's A and hold the result at once: in the cache, or in
    ``local`` for an orbit too big for it (None: keep ``scipy.linalg.expm``)."""
    flow = _decompose(_generator(system, state, a, inv_m))
    if local is None:
        _FLOWS.put((system_key, key), flow, 2 * a.nbytes if flow else 0)
    else:
        local[key] = flow
    return flow


#: Callers inside :func:`_one_blas_thread` now, and the limiter that set BLAS to one thread
#: for them (threadpoolctl's limits are process-wide: one per process, not per caller).
_BLAS_LOCK = threading.Lock()
_BLAS_USERS = [0]
_BLAS_LIMITER: list[object] = []


@contextlib.contextmanager
def _one_blas_thread() -> Iterator[None]:
    """BLAS held to one thread (threadpoolctl, if installed; else nothing changes).

    The limit is process-wide, so it is set by the first caller in and restored by the
    last one out: two orbits' passes run side by side (two threads of a caller) would
    otherwise restore each other's limits in the wrong order and leave the process on
    one BLAS thread for good."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        yield
        return
    with _BLAS_LOCK:
        if _BLAS_USERS[0] == 0:
            _BLAS_LIMITER.append(threadpool_limits(limits=1, user_api="blas"))
        _BLAS_USERS[0] += 1
    try:
        yield
    finally:
        with _BLAS_LOCK:
            _BLAS_USERS[0] -= 1
            if _BLAS_USERS[0] == 0:
                _BLAS_LIMITER.pop().restore_original_limits()  # type: ignore[attr-defined]


#: A pattern none of whose stretches in an orbit exceeds this many units of the scaled
#: norm bound (``ShortFlow.bound * t``; about 30 sparse products per unit of 4) is not
#: decomposed: its stretches are taken by Taylor's series on the block. On the 40-bay mast
#: half the patterns of an orbit last below 4 units (two joints crossing their edges
#: within 0.2 ms), the others above 64.
SHORT_LIMIT = 16.0


def _short_flow(
    system_key: bytes,
    key: bytes,
    system: LinearSystem,
    inv_m: FloatArray,
    state: NDArray[np.int64],
) -> ShortFlow:
    """The pattern's :class:`ShortFlow`, built once per system and pattern (cached)."""
    found, cached = _SHORT_FLOWS.get((system_key, key))
    if found and isinstance(cached, ShortFlow):
        return cached
    flow = ShortFlow.for_structure(inv_m, _pattern_stiffness(system, state), system.damping)
    g = flow.generator
    _SHORT_FLOWS.put((system_key, key), flow, g.data.nbytes + g.indices.nbytes + g.indptr.nbytes)
    return flow


def _short_bound(system: LinearSystem) -> float:
    """ShortFlow's norm bound for the stiffest pattern (every joint at its stiffer contact
    stiffness), 1/s: a bound for each pattern's own, cheap to find once."""
    inv_m = 1.0 / np.diag(system.mass)
    b = system.directions
    k_j = system.k0 + np.maximum(system.k_c, system.k_t)
    stiffest = np.abs(system.stiffness) + (np.abs(b.T) * k_j) @ np.abs(b)
    sigma = math.sqrt(max(float(np.max(inv_m * stiffest.sum(axis=1))), 1e-300))
    return sigma + float(np.max(inv_m * np.abs(system.damping).sum(axis=1)))


#: :func:`leading_multipliers` starts from this many columns (doubled until they hold an
#: invariant subspace of Phi to ``_INVARIANT``).
_LEADING = 16

#: Ritz steps tried on one block size (each after one more pass of Phi over the block)
#: before the block doubles.
_PASSES = 3

#: The block Q is accepted as invariant when ||Phi Q - Q (Q^T Phi Q)|| (Frobenius) is at
#: most this times ||Phi Q||: the Ritz values are then the eigenvalues of a matrix within
#: that of Phi (relative), far below the verdict's margins and the monodromy's own rounding.
_INVARIANT = 1e-10

#: Above this many states (2N) :func:`leading_multipliers` works on a block of columns;
#: below, the whole Phi costs less than the passes.
LEADING_ABOVE = 6 * _LEADING


def leading_multipliers(
    system: LinearSystem,
    basis: Basis,
    coefficients: FloatArray,
    omega: float,
) -> NDArray[np.complex128]:
    """Return the 2N Floquet multipliers, the leading ones exact and the rest 0 (issue 25).

    The monodromy is never formed: its product of per-pattern exponentials (cached
    decompositions, as :func:`monodromy`) is applied to a block of k random columns (16
    first), orthonormalised, applied again (subspace iteration), and the Ritz values of
    B = Q^T Phi Q are the leading multipliers. Accepted when Q spans an invariant subspace
    of Phi to ``_INVARIANT`` (the residual ||Phi Q - Q B|| measured, not assumed), or when
    the Schur vectors of B's leading p Ritz values (p at a gap in their moduli) do, by the
    same test (:func:`_invariant_part`: a block whose last columns split a complex pair;
    the p found are returned, the rest 0); else one more pass, up to ``_PASSES``, then k
    doubles. On a large structure (``SPLIT_ABOVE``) a pass is split by columns among
    threads. A structure's multipliers fall off
    fast (the mast: fewer than 5 above 0.5, none of the 20th above 1e-6), so k stays far
    below 2N and the cost per point is about 2 k products of (2N)^2 per stretch instead of
    one of (2N)^3. The multipliers
    outside the block are below the resolved ones by the residual test's margin and are
    returned as 0 (the stability verdict and the events see only the leading ones).
    At or below ``LEADING_ABOVE`` states, and with friction, it is :func:`multipliers`.
    Along a curve, :func:`leading_block` starts each point from the last one's block.

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.

    Returns
    -------
    (2N,) complex ndarray
        Largest modulus first.
    """
    return leading_block(system, basis, coefficients, omega).multipliers


@dataclass(frozen=True)
class LeadingBlock:
    """What :func:`leading_block` found at one orbit.

    Attributes
    ----------
    multipliers : (2N,) complex ndarray
        Largest modulus first; those outside the block 0.
    block : (2N, k) ndarray or None
        An orthonormal basis of Phi's leading invariant subspace (the next point's start);
        where only its leading part passed the invariance test (:func:`_invariant_part`)
        the whole block, whose first columns' span is that part (``multipliers`` then
        holds that part's values only). None where all 2N multipliers were computed.
    full : bool
        True where the block did not become invariant at any size and the whole monodromy
        was decomposed instead (the fallback: the caller says so).
    passes : int
        Applications of Phi to a block.
    """

    multipliers: NDArray[np.complex128]
    block: FloatArray | None
    full: bool
    passes: int

    def __repr__(self) -> str:
        k = 0 if self.block is None else self.block.shape[1]
        top = float(np.abs(self.multipliers[0])) if self.multipliers.size else math.nan
        return f"LeadingBlock(|mu_1|={top:.6g}, k={k}, full={self.full}, passes={self.passes})"


def leading_block(
    system: LinearSystem,
    basis: Basis,
    coefficients: FloatArray,
    omega: float,
    start: FloatArray | None = None,
) -> LeadingBlock:
    """:func:`leading_multipliers`, started from a block at hand and returning its own.

    ``start`` (2N, k), e.g. the previous curve point's ``block``: the first pass applies
    Phi to it and tests its invariance at once, so where the orbit moved little one or
    two passes replace the cold start's three to five. If it is not invariant after
    ``_PASSES`` passes, the cold start from random columns follows, as
    :func:`leading_multipliers` describes (the verdict never rests on the start).

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.
    start : (2N, k) ndarray, optional

    Returns
    -------
    LeadingBlock
    """
    size = 2 * system.n_dof
    if system.friction_force is not None or size <= LEADING_ABOVE:
        return LeadingBlock(multipliers(system, basis, coefficients, omega), None, False, 0)
    apply = _split(_product(system, basis, coefficients, omega, short=True))
    passes = [0]

    def iterate(q: FloatArray, limit: int) -> NDArray[np.complex128] | None:
        """Up to ``limit`` passes from the orthonormal q; the multipliers once invariant."""
        for _ in range(limit):
            z = apply(q)
            passes[0] += 1
            b = q.T @ z
            miss = float(np.linalg.norm(z - q @ b))
            if miss <= _INVARIANT * max(float(np.linalg.norm(z)), 1e-300):
                mu = np.zeros(size, dtype=np.complex128)
                ritz = np.linalg.eigvals(b)
                mu[: ritz.size] = ritz[np.argsort(-np.abs(ritz), kind="stable")]
                found[0] = _narrowed(q, b, mu[: ritz.size])
                return mu
            part = _invariant_part(q, z, b)
            if part is not None:  # the block's leading part is invariant already
                mu = np.zeros(size, dtype=np.complex128)
                mu[: part.size] = part
                found[0] = q
                return mu
            q = np.linalg.qr(z)[0]  # not invariant yet: one more pass
        return None

    found: list[FloatArray | None] = [None]
    if start is not None and start.ndim == 2 and start.shape[0] == size and start.shape[1] >= 1:
        mu = iterate(np.linalg.qr(start)[0], _PASSES + 1)
        if mu is not None:
            return LeadingBlock(mu, found[0], False, passes[0])
    rng = np.random.default_rng(0)  # the same start at every point: reproducible
    k = _LEADING
    while 2 * k <= size:
        first = np.linalg.qr(apply(np.linalg.qr(rng.standard_normal((size, k)))[0]))[0]
        passes[0] += 1
        mu = iterate(first, _PASSES)
        if mu is not None:
            return LeadingBlock(mu, found[0], False, passes[0])
        k *= 2
    return LeadingBlock(multipliers(system, basis, coefficients, omega), None, True, passes[0])


#: The next point's start keeps the leading j >= ``_LEADING`` directions of an invariant
#: block where the (j + 1)-th Ritz value's modulus is at most ``_TAIL`` times the largest
#: and at most ``_GAP`` times the j-th (a gap, so never inside a complex pair).
_TAIL = 1e-7
_GAP = 0.5

#: :func:`_invariant_part` leaves out only Ritz values of modulus at most this: far inside
#: the unit circle, so no test on the multipliers (the verdict, a multiplier through -1, a
#: complex pair through the circle; :func:`clearjoint.harmonic.response.curve_events`)
#: can turn on one of the directions left out, whose Ritz values are not converged.
_DROPPED = 0.5


def _narrowed(q: FloatArray, b: FloatArray, ritz: NDArray[np.complex128]) -> FloatArray:
    """The next point's start from an invariant block q (2N, k), B = Q^T Phi Q and its
    Ritz values ``ritz`` (largest modulus first): the Schur vectors of the leading j of
    them, j the least from ``_LEADING`` on with abs(ritz[j]) <= ``_TAIL`` abs(ritz[0])
    and <= ``_GAP`` abs(ritz[j - 1]), or q itself where there is no such j < k.

    Why: a block doubled where the leading 16 directions split a complex pair (the 80-bay
    mast's 11th point: 32 columns) would otherwise stay doubled for the rest of the curve,
    each pass costing twice. The directions dropped have multipliers below 1e-7 of the
    largest, so their part of the next point's invariance residual (at most that times
    the start's own error) is far below ``_INVARIANT`` after one pass. Only the start
    changes: each point's multipliers still come from a block tested invariant there."""
    k = q.shape[1]
    moduli = np.abs(ritz)
    for j in range(_LEADING, k):
        if moduli[j] <= _TAIL * moduli[0] and moduli[j] <= _GAP * moduli[j - 1]:
            threshold = 0.5 * (moduli[j] + moduli[j - 1])
            _, z, kept = scipy.linalg.schur(
                b, output="real", sort=lambda re, im, cut=threshold: math.hypot(re, im) > cut
            )
            if kept != j:  # rounding put a Ritz value on the other side: keep them all
                return q
            return np.asarray(q @ z[:, :j], dtype=np.float64)
    return q


#: From this many states (2N) on, :func:`leading_block` splits a pass among threads: below,
#: each stretch's products (2N x 2N by 2N x 8) are too thin for two threads to gain over
#: the Python between them (the 20-bay mast, 2N = 160: the verdict took 62 ms a point
#: split against 25 ms whole, at load 2.5).
SPLIT_ABOVE = 480


def _split(apply: Callable[[FloatArray], FloatArray]) -> Callable[[FloatArray], FloatArray]:
    """``apply`` run on the block's columns split among ``_WORKERS`` threads, BLAS on one
    thread meanwhile: each column's product is its own (the same arithmetic as on the
    whole block), two cores share a pass, and OpenBLAS's threads, slow on a shared
    machine for these thin (2N, k) products, stay idle."""

    def split(q: FloatArray) -> FloatArray:
        parts = min(_WORKERS, q.shape[1] // 4)
        if parts < 2 or q.shape[0] < SPLIT_ABOVE:
            return apply(q)
        with _one_blas_thread(), ThreadPoolExecutor(parts) as pool:
            done = list(pool.map(apply, np.array_split(q, parts, axis=1)))
        return np.asarray(np.hstack(done), dtype=np.float64)

    return split


def _invariant_part(q: FloatArray, z: FloatArray, b: FloatArray) -> NDArray[np.complex128] | None:
    """The Ritz values of the leading part of a block q (2N, k) that is invariant although
    q is not: z = Phi q, B = Q^T Phi Q. For each p < k (largest first) where the Ritz
    values' moduli have a gap (the (p + 1)-th at most ``_GAP`` times the p-th, so no
    complex pair is split), the Schur vectors Z_p of B's leading p Ritz values give Q_p =
    Q Z_p and Phi Q_p = z Z_p (exactly: Phi is linear), and the part is accepted by the
    same test as the whole block, ||Phi Q_p - Q_p T_p|| <= ``_INVARIANT`` ||Phi Q_p||,
    and only where every Ritz value left out has modulus at most ``_DROPPED``.
    Returns its p Ritz values (largest modulus first), or None.

    What the test proves: the p values are eigenvalues of a matrix within ``_INVARIANT``
    (relative) of Phi. That no multiplier of Phi outside the part exceeds them is not
    proved by it, for the part as for a whole block: it rests, as there, on the block
    having passed through Phi from a start spanning the leading directions (subspace
    iteration; the previous point's block along a curve). ``_DROPPED`` keeps the Ritz
    values left out far from the unit circle, so no verdict or event turns on them.

    Why: a warm start whose last columns split a complex pair of the new orbit's
    multipliers (or sit where they are close together) is never invariant as a whole,
    and would send the point to the cold start; its leading part may already be."""
    k = q.shape[1]
    ritz = np.linalg.eigvals(b)
    ritz = ritz[np.argsort(-np.abs(ritz), kind="stable")]
    moduli = np.abs(ritz)
    for p in range(k - 1, 0, -1):
        if not moduli[p] <= _DROPPED:  # and so for every smaller p: none left out near 1
            return None
        if not moduli[p] <= _GAP * moduli[p - 1]:
            continue
        threshold = 0.5 * (moduli[p] + moduli[p - 1])
        t, vectors, kept = scipy.linalg.schur(
            b, output="real", sort=lambda re, im, cut=threshold: math.hypot(re, im) > cut
        )
        if kept != p:
            continue
        qp, zp = q @ vectors[:, :p], z @ vectors[:, :p]
        miss = float(np.linalg.norm(zp - qp @ t[:p, :p]))
        if miss <= _INVARIANT * max(float(np.linalg.norm(zp)), 1e-300):
            return np.asarray(ritz[:p], dtype=np.complex128)
    return None


def _transition(
    system_key: bytes, source_key: bytes, source: _Flow, target_key: bytes, target: _Flow
) -> FloatArray:
    """V_target^-1 V_source (cached): from the eigen-coordinates of one pattern to the next's."""
    found, cached = _TRANSITIONS.get((system_key, source_key, target_key))
    if found and isinstance(cached, np.ndarray):
        return cached
    matrix = target.inverse @ source.vectors
    _TRANSITIONS.put((system_key, source_key, target_key), matrix, matrix.nbytes)
    return matrix


def multipliers(
    system: LinearSystem, basis: Basis, coefficients: FloatArray, omega: float
) -> NDArray[np.complex128]:
    """Return the 2N Floquet multipliers of the HB orbit, largest modulus first.

    The exact product of exponentials without friction (:func:`monodromy`), the
    integrated monodromy with it (:func:`integrated_monodromy`).

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.

    Returns
    -------
    (2N,) complex ndarray
    """
    if system.friction_force is None:
        phi = monodromy(system, basis, coefficients, omega)
    else:
        phi = integrated_monodromy(system, basis, coefficients, omega)
    mu = np.linalg.eigvals(phi)
    return np.asarray(mu[np.argsort(-np.abs(mu), kind="stable")], dtype=np.complex128)


def _roots(basis: Basis, columns: FloatArray, level: FloatArray) -> FloatArray:
    """Phases in [0, 2 pi) where some column of ``columns`` (2H + 1, k) crosses its ``level``."""
    values = basis.to_time @ columns - level  # (N_t, k)
    above = values > 0.0
    rows, cols = np.nonzero(above != np.roll(above, -1, axis=0))
    if rows.size == 0:
        return np.zeros(0)
    return _bisect(basis, columns[:, cols], level[cols], rows)


def integrated_monodromy(
    system: LinearSystem,
    basis: Basis,
    coefficients: FloatArray,
    omega: float,
    *,
    rtol: float = 1e-10,
) -> FloatArray:
    """Return the monodromy of the HB orbit's linearisation by integration, (2N, 2N).

    Integrates Phi' = A(t) Phi, A = [[0, I], [-M^-1 K_T(t), -M^-1 C_T(t)]], over one
    period (module docstring): K_T piecewise constant between gap-edge crossings,
    C_T(t) the viscous C plus each rubbing joint's regularised friction slope at the
    orbit's relative speed. Valid with or without friction (without, it reproduces
    :func:`monodromy` to about ``rtol``).

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.
    omega : float
        w, rad/s.
    rtol : float
        Relative (and absolute, on the phase-scaled state) tolerance of DOP853.

    Returns
    -------
    (2N, 2N) ndarray
        Phi, mapping (y(0), y'(0)) to (y(T), y'(T)), T = 2 pi / w.

    Raises
    ------
    HarmonicError
        The integrator failed on a segment (the message names it).
    """
    n = system.n_dof
    inv_m = 1.0 / np.diag(system.mass)
    b = system.directions
    rel = coefficients @ b.T  # (2H + 1, n_j)
    rate = basis.derivative @ rel  # d delta / d tau
    cuts = [crossings(system, basis, coefficients)]
    rubbing = (
        np.zeros(0, dtype=np.int64)
        if system.friction_force is None
        else np.flatnonzero(system.friction_force > 0.0)
    )
    if rubbing.size:
        cuts.append(_roots(basis, rate[:, rubbing], np.zeros(rubbing.size)))
    edges = np.unique(np.concatenate([[0.0], *cuts, [2.0 * math.pi]]))
    middles = 0.5 * (edges[:-1] + edges[1:])
    states = _states(basis.evaluate(rel, middles), system)
    # phase-scaled state (y, y' / w) in tau = w t: d/dtau = [[0, I], [-M^-1 K / w^2, -M^-1 C / w]]
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    damping = -inv_m[:, None] * system.damping / omega
    phi = np.eye(2 * n)
    for lo, hi, state in zip(edges[:-1], edges[1:], states, strict=True):
        if hi <= lo:
            continue
        a[n:, :n] = -inv_m[:, None] * _pattern_stiffness(system, state) / omega**2

        def rhs(tau: float, y: FloatArray) -> FloatArray:
            gen = a.copy()
            gen[n:, n:] = damping
            if rubbing.size:
                speed = omega * basis.evaluate(rate, np.array([tau]))  # (1, n_j)
                _, slope = system.friction_forces(speed)
                gen[n:, n:] -= inv_m[:, None] * ((b.T * slope[0]) @ b) / omega
            return np.asarray((gen @ y.reshape(2 * n, 2 * n)).ravel(), dtype=np.float64)

        sol = solve_ivp(rhs, (lo, hi), phi.ravel(), method="DOP853", rtol=rtol, atol=rtol)
        if not sol.success:
            raise HarmonicError(
                f"the monodromy integration failed on the phase segment {lo:.6g} to {hi:.6g} "
                f"rad at w = {omega!r} rad/s ({sol.message}); use more samples or a larger "
                "friction_regularization"
            )
        phi = sol.y[:, -1].reshape(2 * n, 2 * n)
    scale = np.concatenate((np.ones(n), np.full(n, omega)))
    return np.asarray(scale[:, None] * phi / scale[None, :], dtype=np.float64)


def speed_reversals(system: LinearSystem, basis: Basis, coefficients: FloatArray) -> FloatArray:
    """Return how often each joint's relative speed b_j^T u' changes sign in one period.

    A joint that slides back and forth reverses twice; more reversals mean the HB
    orbit's speed ripples about 0, i.e. the joint sticks (with friction), where the
    regularised slope c_j swings between 0 and mu_s P / v_eps and the linearisation
    is not to be trusted.

    Parameters
    ----------
    system : LinearSystem
    basis : Basis
    coefficients : (2H + 1, N) ndarray
        The HB orbit, m.

    Returns
    -------
    (n_j,) ndarray
        The number of sign changes per joint (as floats).
    """
    rate = basis.derivative @ (coefficients @ system.directions.T)
    return np.array(
        [float(_roots(basis, rate[:, [j]], np.zeros(1)).size) for j in range(rate.shape[1])]
    )
