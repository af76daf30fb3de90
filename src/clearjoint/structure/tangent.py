"""The exact tangent flow along a structure's exact motion (MODEL.md 5.1 and 5.2).

Between two gap-edge events the structure is linear in one contact pattern p, so a
perturbation (du, dv) of its state obeys the constant-coefficient equation

    d/dt (du, dv) = A_p (du, dv),   A_p = [[0, I], [-M^-1 K_p, -M^-1 C]],

and is carried over a stretch of length dt by expm(A_p dt) exactly. At an event the
vector field is continuous (the clearance law's force is continuous in the shortening,
MODEL.md section 0), so the saltation matrix S = R + (f+ - R f-) grad(h)^T / (grad(h) . f-)
of MODEL.md 5.1 is the identity (R = I without restitution): the tangent flow over a
motion is the ordered product of the stretches' exponentials, the stretches and their
patterns being those the exact event-driven motion (``clearjoint.exact.march``) met.
Over one forcing period of a periodic orbit that product is the monodromy matrix.

A restitution e below 1 makes R differ from the identity at every impact (the joint's
relative speed drops to e times itself as it enters contact, MODEL.md 5.2), and S with it:
:func:`impact_saltation` gives S at one impact, :func:`impact_jumps` all of a motion's, and
:func:`carry` multiplies them in between the stretches (the shooting map's monodromy, the
stepped sine's Lyapunov exponent). :class:`PatternFlows` alone refuses restitution unless
its caller says it carries the jumps (``impacts=True``).

Each pattern's A is decomposed once, A = V B V^-1 with B real block-diagonal
(``clearjoint.exact.patterns``, as harmonic balance's monodromy uses it: an
ill-conditioned V keeps ``scipy.linalg.expm``), and the product is carried in the
patterns' eigen-coordinates, so a stretch costs one diagonal scaling and a change of
coordinates where the pattern changes.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint.compiled import prefer
from clearjoint.errors import SimulationError
from clearjoint.exact import march
from clearjoint.exact.patterns import PatternFlow as _Flow
from clearjoint.exact.patterns import chain
from clearjoint.exact.patterns import decompose as _decompose
from clearjoint.structure.model import StructureError
from clearjoint.structure.motion import _run
from clearjoint.system import VibrationSystem

FloatArray = NDArray[np.float64]

#: Bytes the decompositions and transitions of one PatternFlows may hold before it starts
#: anew (a rattling structure with many joints visits new patterns without end).
STORE_BYTES = 256 * 2**20


def refuse_restitution(system: VibrationSystem, *, below: float = 1.0) -> None:
    """Refuse, in one line, a joint whose restitution is below ``below`` (1: its impacts
    would need saltation jumps that a plain product of exponentials does not carry; 0 is
    always refused where impacts are carried, :func:`impact_saltation`)."""
    e = system.restitution()
    if below <= 0.0 and np.any(e <= 0.0):
        raise _no_saltation(int(np.flatnonzero(e <= 0.0)[0]))
    if np.any(e < below):
        joint = int(np.flatnonzero(e < below)[0])
        raise StructureError(
            f"joint {joint} has a restitution of {float(e[joint]):g}: the exact tangent "
            "flow (monodromy, Lyapunov exponent) of a structure carries continuous "
            "contact only; give that joint restitution=1 (its contact stiffness "
            "carries the impact), or study one joint with clearjoint.periodic"
        )


def _no_saltation(joint: int) -> StructureError:
    """The one line for a restitution of 0, whose impacts have no saltation matrix."""
    return StructureError(
        f"joint {joint} has a restitution of 0: the exact Jacobian of its impacts needs "
        "e > 0; give it a small positive restitution (0.01)"
    )


class PatternFlows:
    """The exact linear flows expm(A_p t) of one system's contact patterns, each decomposed once.

    Parameters
    ----------
    system : VibrationSystem
        Lumped (diagonal) M; every joint's restitution 1, unless ``impacts``.
    impacts : bool
        The caller multiplies each impact's saltation matrix (:func:`impact_saltation`)
        in between the products itself, so a restitution below 1 is allowed.

    Raises
    ------
    StructureError
        A joint with a restitution below 1 and ``impacts`` false.
    """

    def __init__(self, system: VibrationSystem, *, impacts: bool = False) -> None:
        if not impacts:
            refuse_restitution(system)
        self.system = system
        self.n = n = system.n_dof
        inv_m = 1.0 / system.mass_diagonal()
        damping = system.damping
        c = damping.toarray() if hasattr(damping, "toarray") else np.asarray(damping)
        self._inv_m = inv_m
        self._base = np.zeros((2 * n, 2 * n))
        self._base[:n, n:] = np.eye(n)
        self._base[n:, n:] = -inv_m[:, None] * np.asarray(c, dtype=np.float64)
        self._flows: dict[bytes, _Flow | FloatArray] = {}
        self._transitions: dict[tuple[bytes, bytes], FloatArray] = {}
        # patterns kept at once: a decomposition holds two (2N)^2 matrices, and a
        # transition one per pair met, so about 3 (2N)^2 8 bytes a pattern
        self._limit = max(16, int(STORE_BYTES // (3 * 8 * (2 * n) ** 2)))
        self._norms: dict[bytes, FloatArray] = {}
        self._mass = system.mass_diagonal()

    def energy_norm(self, states: NDArray[np.int8], w: FloatArray) -> float:
        """sqrt(du^T K_n du + dv^T M dv) of a perturbation w = (du, dv), K_n = K_p + 1e-3 K_closed.

        The pattern's own stiffness makes the norm of a perturbation along one lightly
        damped mode of that pattern vary only by its decay (an undamped mode keeps its
        energy), so a growth rate measured over a stretch in one pattern carries no
        oscillation of the norm; the small share of the closed stiffness keeps it a norm
        where the pattern leaves a mechanism (an open joint with k0 = 0).
        """
        key = np.asarray(states, dtype=np.int8).tobytes()
        k = self._norms.get(key)
        if k is None:
            k_p, _ = self.system.pattern_stiffness(np.asarray(states, dtype=np.int64))
            k_c = self.system.closed_stiffness()
            k = k_p + 1e-3 * k_c
            k = np.asarray(k.toarray() if hasattr(k, "toarray") else k, dtype=np.float64)
            k = 0.5 * (k + k.T)
            self._norms[key] = k
        du, dv = w[: self.n].ravel(), w[self.n :].ravel()
        value = float(du @ k @ du + dv @ (self._mass * dv))
        return math.sqrt(max(value, 0.0))

    def generator(self, states: NDArray[np.int8]) -> FloatArray:
        """A_p of the pattern ``states`` (n_j,), (2N, 2N) in 1/s."""
        k, _ = self.system.pattern_stiffness(np.asarray(states, dtype=np.int64))
        k = k.toarray() if hasattr(k, "toarray") else np.asarray(k)
        a = self._base.copy()
        a[self.n :, : self.n] = -self._inv_m[:, None] * k
        return a

    def flow(self, states: NDArray[np.int8]) -> tuple[bytes, _Flow | FloatArray]:
        """(key, the pattern's decomposition, or its generator A where V is ill-conditioned)."""
        key = np.asarray(states, dtype=np.int8).tobytes()
        found = self._flows.get(key)
        if found is None:
            if len(self._flows) >= self._limit:  # a rattling structure meets patterns
                self._flows.clear()  # without end (3^J of them): start the store anew
                self._transitions.clear()
            a = self.generator(states)
            decomposed = _decompose(a)
            found = a if decomposed is None else decomposed
            self._flows[key] = found
        return key, found

    def _transition(self, source: bytes, here: _Flow, target: bytes, there: _Flow) -> FloatArray:
        found = self._transitions.get((source, target))
        if found is None:
            if len(self._transitions) >= 2 * self._limit:
                self._transitions.clear()
            found = there.inverse @ here.vectors
            self._transitions[(source, target)] = found
        return found

    def product(
        self, widths: FloatArray, patterns: NDArray[np.int8], start: FloatArray | None = None
    ) -> FloatArray:
        """Return expm(A_k dt_k) ... expm(A_1 dt_1) @ start (start: identity by default).

        Parameters
        ----------
        widths : (k,) ndarray
            Each stretch's length, s (stretches of zero length are skipped).
        patterns : (k, n_j) ndarray of int8
            Each stretch's contact pattern.
        start : (2N, m) ndarray, optional
        """
        phi = np.eye(2 * self.n) if start is None else start
        keys = [np.asarray(states, dtype=np.int8).tobytes() for states in patterns]
        return chain(phi, widths, keys, lambda i: self.flow(patterns[i])[1], self._transition)


def impact_saltation(
    flow: Any, joint: int, t: float, u: FloatArray, v_after: FloatArray
) -> FloatArray:
    """The saltation matrix S (2N, 2N) of an impact of ``joint`` at time t (MODEL.md 5.1).

    At contact onset the joint's relative speed s = b^T v drops to e s through an impulse
    along b (MODEL.md 5.2): v+ = R_v v-, R_v = I - (1 - e) m_eff M^-1 b b^T, u unchanged,
    R = diag(I, R_v). With h(z) = b^T u - edge, grad(h) = (b, 0), the saltation matrix is

        S = R + (f+ - R f-) grad(h)^T / (b^T v-),

    f = (v, a) the vector field on each side. The spring and joint forces are continuous at
    the edge, so a+ - a- = -M^-1 C (v+ - v-), and f+ - R f- = (v+ - v-,
    -M^-1 C (v+ - v-) + (1 - e) m_eff M^-1 b (b^T a-)).

    Parameters
    ----------
    flow : clearjoint.structure.motion._Flow
        The structure's flow at the forcing (its M, C, K, b, e, m_eff and force).
    joint : int
    t : float
        The impact's time, s.
    u, v_after : (N,) ndarray
        The state just after the impact, m and m/s (v- is recovered: b^T v+ = e b^T v-).

    Raises
    ------
    StructureError
        A restitution of 0 (the speed before the impact cannot be recovered from after it).
    """
    e = float(flow.restitution[joint])
    if e <= 0.0:
        raise _no_saltation(joint)
    n = flow.n
    b = np.asarray(flow.b[joint], dtype=np.float64)
    push = np.asarray(flow.impulse_dirs[joint], dtype=np.float64)  # M^-1 b
    m_eff = float(flow.m_eff[joint])
    v_before = before_impact(flow, joint, v_after)
    before = float(b @ v_before)  # b^T v-
    system = flow.system
    delta = flow.b @ u
    f_joint, _ = system.joint_forces(delta)
    restoring = flow.k_linear @ u + flow.b.T @ f_joint
    a_before = (flow.force * math.sin(flow.omega * t) - flow.c @ v_before - restoring) / flow.m
    jump_v = v_after - v_before
    jump_a = -(flow.c @ jump_v) / flow.m + (1.0 - e) * m_eff * push * float(b @ a_before)
    salt = np.eye(2 * n)
    salt[n:, n:] -= (1.0 - e) * m_eff * np.outer(push, b)
    salt[:, :n] += np.outer(np.concatenate((jump_v, jump_a)), b) / before
    return salt


def before_impact(flow: Any, joint: int, v_after: FloatArray) -> FloatArray:
    """The velocity just before an impact of ``joint`` from the one just after it.

    The impulse along M^-1 b takes the joint's relative speed s = b^T v to e s
    (MODEL.md 5.2): b^T v+ = e b^T v-, so v- = v+ + (1 - e) m_eff M^-1 b (b^T v+ / e).
    """
    e = float(flow.restitution[joint])
    push = np.asarray(flow.impulse_dirs[joint], dtype=np.float64)
    speed = float(np.asarray(flow.b[joint], dtype=np.float64) @ v_after) / e
    return np.asarray(v_after + (1.0 - e) * float(flow.m_eff[joint]) * push * speed)


def impact_jumps(
    flow: Any,
    motion: Any,
    history: NDArray[np.int8],
    u0: FloatArray,
    v0: FloatArray,
    duration: float,
) -> dict[int, FloatArray]:
    """Each impact's saltation matrix along ``motion``, by the index of its event.

    An impact is an event that takes a joint with restitution below 1 from open into
    contact. The state just after each is read from a second run of the same motion
    (``flow`` from (u0, v0) over its ``duration``, s) sampled at the impacts' times: the
    march's steps do not depend on where it samples, and a sample at an event's time is
    taken at the start of the step after the event. That run's events are checked to be
    the first run's, bit for bit. Impacts at the same instant (the march meets them one
    after the other, in the order of their events, with no step between) are read back
    from the state after the last of them, one impulse at a time, each with its own
    saltation matrix, multiplied in in the march's order. An impact at the very end of
    the run takes the run's final state.

    Raises
    ------
    SimulationError
        The second run met its gap edges otherwise (it should not).
    StructureError
        A restitution of 0 (:func:`impact_saltation`).
    """
    joints = np.asarray(motion.event_joints, dtype=np.int64)
    times = np.asarray(motion.event_times, dtype=np.float64)
    order = np.arange(joints.size)
    entering = (history[order, joints] == march.OPEN) & (history[order + 1, joints] != march.OPEN)
    hits = np.flatnonzero(entering & (flow.restitution[joints] < 1.0))
    if hits.size == 0:
        return {}
    sampled = np.unique(times[hits][times[hits] < duration])
    after = _run(flow, u0, v0, duration, sampled)
    if not np.array_equal(np.asarray(after.event_times), times):
        raise SimulationError(
            "the exact motion met its gap edges differently when sampled at its impacts; "
            "its Jacobian with impacts cannot be formed (please report this)"
        )
    states = {float(t): (after.u[k], after.v[k]) for k, t in enumerate(sampled)}
    end_u, end_v = motion.final_state
    jumps: dict[int, FloatArray] = {}
    for t in np.unique(times[hits]):
        u, v = states.get(float(t), (np.asarray(end_u), np.asarray(end_v)))
        for i in hits[times[hits] == t][::-1]:  # the last impact of the instant first
            joint = int(joints[i])
            jumps[int(i)] = impact_saltation(flow, joint, float(t), u, v)
            v = before_impact(flow, joint, v)
    return jumps


def carry(
    flows: PatternFlows,
    motion: Any,
    history: NDArray[np.int8],
    start: float,
    stop: float,
    vectors: FloatArray | None = None,
    jumps: dict[int, FloatArray] | None = None,
) -> FloatArray:
    """The exact tangent flow of ``motion`` over [start, stop] applied to ``vectors``.

    The product of the stretches' exponentials (identity ``vectors`` by default), with
    each impact's saltation matrix in ``jumps`` (:func:`impact_jumps`) multiplied in at
    its event: those at start < t <= stop (an impact at a boundary of consecutive spans
    belongs to the span it ends), in the order of their events.
    """
    phi = np.eye(2 * flows.n) if vectors is None else vectors
    times = np.asarray(motion.event_times, dtype=np.float64)
    inside = [] if not jumps else [
        i for i in range(
            int(np.searchsorted(times, start, side="right")),
            int(np.searchsorted(times, stop, side="right")),
        ) if i in jumps
    ]  # fmt: skip
    for i in inside:
        if times[i] > start:
            widths, patterns = stretches(motion, start, float(times[i]), history)
            phi = flows.product(widths, patterns, start=phi)
        phi = jumps[i] @ phi  # type: ignore[index]
        start = float(times[i])
    if stop > start:
        widths, patterns = stretches(motion, start, stop, history)
        phi = flows.product(widths, patterns, start=phi)
    return phi


def stretches(
    motion: Any, start: float, stop: float, history: NDArray[np.int8] | None = None
) -> tuple[FloatArray, NDArray[np.int8]]:
    """The stretches between events of ``motion`` within [start, stop] and their patterns.

    Parameters
    ----------
    motion : StructureMotion
        An exact motion (it carries ``event_times``, ``event_joints``, ``event_states``
        and ``start_pattern``).
    start, stop : float
        s, within the motion's run.
    history : (E + 1, n_j) ndarray of int8, optional
        The motion's :func:`pattern_history` (computed here when not given).

    Returns
    -------
    widths : (k,) ndarray
        s; they sum to stop - start.
    patterns : (k, n_j) ndarray of int8
    """
    times = np.asarray(motion.event_times, dtype=np.float64)
    if history is None:
        history = pattern_history(motion)
    first = int(np.searchsorted(times, start, side="right"))
    last = int(np.searchsorted(times, stop, side="left"))
    inner = times[first:last]
    edges = np.concatenate(([start], inner, [stop]))
    return np.diff(edges), np.asarray(history[first : last + 1], dtype=np.int8)


def pattern_history(motion: Any) -> NDArray[np.int8]:
    """(E + 1, n_j): the motion's contact pattern at the start and after each event."""
    return np.asarray(
        prefer(march.pattern_history)(
            np.ascontiguousarray(motion.start_pattern, dtype=np.int8),
            np.ascontiguousarray(motion.event_joints, dtype=np.int64),
            np.ascontiguousarray(motion.event_states, dtype=np.int8),
        ),
        dtype=np.int8,
    )


def largest_exponent(
    flows: PatternFlows,
    motion: Any,
    period: float,
    periods: int,
    *,
    start: FloatArray | None = None,
    aligning: int = 0,
    jumps: dict[int, FloatArray] | None = None,
) -> tuple[float, float, FloatArray]:
    """The largest Lyapunov exponent of the motion from its exact tangent flow, and its error.

    One tangent vector (``start``, else a fixed pseudo-random one) is carried over the
    ``periods`` forcing periods of ``motion`` from t = 0 (Benettin's method with the
    exact flow), renormalised at the end of every period in the energy norm of the
    pattern in force there (:meth:`PatternFlows.energy_norm`). The first ``aligning``
    periods only turn it towards the most growing direction; the log growths g_k of
    the others give lambda = mean(g_k) / T (they telescope, so the norm biases lambda by
    at most the log of the norms' ratio over the whole record). The uncertainty is the
    standard error of the mean of g over blocks of periods (ten blocks, so neighbouring
    periods' correlation is averaged out), divided by T. With impacts, ``jumps``
    (:func:`impact_jumps` of the motion) multiplies each one's saltation matrix in.

    Returns
    -------
    (lambda, sigma, vector) : lambda and sigma in 1/s, and the tangent vector at the end
        (unit energy norm), to carry on to a next record.
    """
    if start is None:
        w = np.random.default_rng(0).standard_normal((2 * flows.n, 1))
    else:
        w = np.asarray(start, dtype=np.float64).reshape(2 * flows.n, 1).copy()
    history = pattern_history(motion)
    _, patterns = stretches(motion, 0.0, period, history)
    w /= flows.energy_norm(patterns[0], w)
    growth = np.empty(periods)
    for k in range(periods):
        t0 = k * period
        w = carry(flows, motion, history, t0, t0 + period, w, jumps)
        _, patterns = stretches(motion, t0, t0 + period, history)
        size = flows.energy_norm(patterns[-1], w)
        if not size > 0.0 or not math.isfinite(size):
            raise StructureError("the tangent vector vanished or overflowed over one period")
        growth[k] = math.log(size)
        w /= size
    used = growth[min(aligning, periods - 1) :]
    rate = float(np.mean(used)) / period
    block = max(1, used.size // 10)
    n_blocks = used.size // block
    means = used[: n_blocks * block].reshape(n_blocks, block).mean(axis=1)
    sigma = (
        float(np.std(means, ddof=1) / math.sqrt(n_blocks)) / period if n_blocks > 1 else math.inf
    )
    return rate, sigma, w
