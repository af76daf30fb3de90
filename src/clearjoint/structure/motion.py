"""Exact motion of a structure with many clearance joints, event by event (MODEL.md 5.2).

In one contact pattern s the structure is linear,

    M u'' + C u' + K_s u = F sin(w t) + r_s,

and so is the augmented state y = (u, v, sin w t, cos w t, 1): y' = A_s y. Its flow
exp(A_s tau) is therefore exact for the forcing and the joints' constant forces alike,
with no special case for a singular K_s (an open joint with k0 = 0), a defective A_s or
resonance. Steps never exceed a base step H (an eighth of the shortest period of forcing,
structure and damping), so abs(A_s tau) is of order one and the Taylor series of
exp(A_s tau) y, summed until its terms fall below 1e-18 of y, is the exact flow to
round-off. The same series carries the energy integrals exactly: the input power
F.v sin(w t) and the viscous power v^T C v are quadratic forms of y, integrated term by
term. Per visited pattern its generator is cached, and, once the motion has spent
MODAL_AFTER_STEPS steps in it, its eigen-decomposition (for the event bound below).

Events (a joint's shortening delta_j reaches a gap edge) are found by *certified
marching*, as in the one-joint kernel: from the state at tau = 0 the event function
g = distance to the edge satisfies g(tau) >= g + g' tau + g'' tau^2/2 - B tau^3/6 on the
whole base step, where B bounds abs(g'''): g''' = w_j^T A^3 y(tau), so
abs(g''') <= sum_k abs(w_j^T v_k) abs(lambda_k)^3 abs(c_k) max(1, exp(Re lambda_k H)) over the modes
(v_k, lambda_k) of A_s with y = sum_k c_k v_k, or, for a pattern met only briefly or with
ill-conditioned eigenvectors, abs(w_j^T A^3) exp(mu H) abs(y(0)), mu a Gershgorin bound of the
logarithmic norm of A in scaled variables. Stepping to the first
root of that lower bound never passes a root, grazing included; near a transversal
crossing the steps shrink like Newton's. Restitution on a joint that links two masses
directly (a rigid member) applies an impulse along b_j that takes the relative speed
delta' to e delta' and removes (1 - e^2)/2 m_eff delta'^2 with m_eff = 1/(b_j^T M^-1 b_j)
(MODEL.md eq 16 with the joint's effective mass); this is the one-joint kernel's rule.
Coulomb friction in a joint is refused (a sticking joint is a constraint the pattern
flow does not carry).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg
from numba import njit
from numpy.typing import ArrayLike, NDArray

from clearjoint import _checks
from clearjoint.simulate._kernel import certified_step
from clearjoint.simulate.core import EnergyLedger, SimulationError
from clearjoint.structure.model import (
    COMPRESSION,
    OPEN,
    TENSION,
    Structure,
    StructureError,
    edge_positions,
)

FloatArray = NDArray[np.float64]

#: Largest number of Taylor terms for a step shorter than the base step.
TAYLOR_TERMS = 60
#: A pattern gets its modal jerk bound (an eigen-decomposition) after this many steps in it;
#: before, the plain norm bound (cheap, but shorter steps) is used.
MODAL_AFTER_STEPS = 16
#: Above this condition number of the pattern's eigenvectors, the modal jerk bound gives
#: way to the plain norm bound.
MODAL_CONDITION_LIMIT = 1e10

#: The most events allowed per base step on average before the run is called chattering.
MAX_EVENTS_PER_STEP = 1000


@njit(cache=True)
def _first_event(
    g0: np.ndarray, g1: np.ndarray, g2: np.ndarray, bound: np.ndarray, h_max: float
) -> tuple[float, int]:
    """The largest certified step over every event function, and which one limits it (-1)."""
    best = h_max
    which = -1
    for i in range(g0.shape[0]):
        if g0[i] > 1e299:
            continue
        h = certified_step(g0[i], g1[i], g2[i], bound[i], best)
        if h < best:
            best = h
            which = i
    return best, which


@dataclass
class _Pattern:
    """The cached exact flow of one contact pattern, in scaled variables."""

    a: FloatArray  # scaled generator (n_aug, n_aug)
    norm: float  # |a|_F >= |a|_2
    jerk_rows: FloatArray  # (J, n_aug) w_j^T A^3 (plain bound: |rows| |y| growth)
    growth: float  # exp(mu(A) H) >= sup |exp(A tau)| on [0, H]
    modal_inverse: NDArray[np.complex128] | None  # V^-1, or None when V is ill-conditioned
    modal_weights: FloatArray | None  # (J, n_aug) |w_j v_k| |lambda_k|^3 max(1, e^(Re lambda_k H))
    uses: int = 0
    modal_tried: bool = False


class _Flow:
    """Exact pattern-by-pattern flow of a structure's augmented state, with caches."""

    def __init__(self, structure: Structure, force: FloatArray, omega: float) -> None:
        s = structure
        self.n = n = s.n_dof
        self.m = s.mass_diagonal()
        self.c = s.damping_matrix()
        self.force = force
        self.omega = omega
        self.b = s.joint_directions
        self.laws = s.joint_laws
        self.g_c, self.g_t = edge_positions(self.laws)
        self.restitution = np.array([law.restitution for law in self.laws])
        inv_m = 1.0 / self.m
        self.impulse_dirs = self.b * inv_m  # rows M^-1 b_j
        self.m_eff = 1.0 / np.maximum(np.einsum("jn,jn->j", self.b, self.impulse_dirs), 1e-300)
        plain = [i for i, mem in enumerate(s.members) if mem.joint is None]
        bm = s.member_directions[plain]
        self.k_linear = (bm.T * s._k_member[plain]) @ bm
        self.structure = s
        k_closed, _ = s.pattern_stiffness(np.full(len(self.laws), COMPRESSION))
        k_stiff = k_closed.copy()
        for j, law in enumerate(self.laws):  # the stiffest state of every joint
            extra = max(law.tension_stiffness - law.compression_stiffness, 0.0)
            k_stiff += extra * np.outer(self.b[j], self.b[j])
        w2 = scipy.linalg.eigh(k_stiff, np.diag(self.m), eigvals_only=True)
        self.omega_ref = math.sqrt(max(float(w2[-1]), 1e-300))
        rates = [self.omega_ref, omega]
        c_rate = scipy.linalg.eigh(self.c, np.diag(self.m), eigvals_only=True)
        rates.append(float(c_rate[-1]))
        self.base_step = 2.0 * math.pi / max(rates) / 8.0
        # scaling: u -> omega_ref u, v -> v, (sin, cos, 1) -> v_ref (sin, cos, 1)
        offsets = [
            max(
                law.compression_stiffness * law.compression_gap,
                law.tension_stiffness * law.tension_gap,
            )
            for law in self.laws
        ]
        push = np.abs(force) * inv_m
        push_norm = float(np.linalg.norm(push))
        push_norm += sum(
            o * float(np.linalg.norm(r)) for o, r in zip(offsets, self.impulse_dirs, strict=True)
        )
        self.v_ref = push_norm / self.omega_ref if push_norm > 0.0 else 1.0
        self.scale = np.concatenate(  # y_scaled = scale * y
            (np.full(n, self.omega_ref), np.ones(n), np.full(3, self.v_ref))
        )
        self.patterns: dict[bytes, _Pattern] = {}
        # energy forms on the scaled state: input F.v sin(wt), viscous v^T C v
        n_aug = 2 * n + 3
        q_in = np.zeros((n_aug, n_aug))
        q_in[n : 2 * n, 2 * n] = 0.5 * force / self.v_ref
        q_in[2 * n, n : 2 * n] = 0.5 * force / self.v_ref
        q_visc = np.zeros((n_aug, n_aug))
        q_visc[n : 2 * n, n : 2 * n] = self.c
        self.q = np.stack((q_in, q_visc))
        self.delta_rows = np.zeros((len(self.laws), n_aug))  # delta_j = rows . y_scaled
        self.delta_rows[:, :n] = self.b / self.omega_ref

    # ---- one pattern's exact flow ----------------------------------------------------------

    def pattern(self, states: NDArray[np.int8]) -> _Pattern:
        key = states.tobytes()
        cached = self.patterns.get(key)
        if cached is not None:
            return cached
        n = self.n
        k, r = self.structure.pattern_stiffness(states)
        n_aug = 2 * n + 3
        gen = np.zeros((n_aug, n_aug))
        gen[:n, n : 2 * n] = np.eye(n)
        inv_m = 1.0 / self.m
        gen[n : 2 * n, :n] = -(k * inv_m[:, None])
        gen[n : 2 * n, n : 2 * n] = -(self.c * inv_m[:, None])
        gen[n : 2 * n, 2 * n] = self.force * inv_m
        gen[n : 2 * n, 2 * n + 2] = r * inv_m
        gen[2 * n, 2 * n + 1] = self.omega
        gen[2 * n + 1, 2 * n] = -self.omega
        a = gen * self.scale[:, None] / self.scale[None, :]
        h = self.base_step
        norm = float(np.linalg.norm(a))  # Frobenius: an upper bound of the 2-norm
        jerk = self.delta_rows @ np.linalg.matrix_power(a, 3)
        # logarithmic norm mu_2(a) <= largest Gershgorin bound of the symmetric part
        sym = 0.5 * (a + a.T)
        mu = float(np.max(np.diag(sym) + np.sum(np.abs(sym), axis=1) - np.abs(np.diag(sym))))
        pat = _Pattern(
            a=a,
            norm=norm,
            jerk_rows=jerk,
            growth=math.exp(max(mu, 0.0) * h),
            modal_inverse=None,
            modal_weights=None,
        )
        self.patterns[key] = pat
        return pat

    def _modal(self, pat: _Pattern) -> None:
        """Add the modal jerk bound to a pattern used long enough to repay its cost."""
        pat.modal_tried = True
        # the jerk is sum_k (w_j v_k) lambda_k^3 c_k e^(lambda_k t)
        lam, vec = np.linalg.eig(pat.a)
        try:
            inverse = np.linalg.inv(vec)
        except np.linalg.LinAlgError:
            return
        condition = float(np.linalg.norm(vec, 1) * np.linalg.norm(inverse, 1))
        if condition < MODAL_CONDITION_LIMIT:
            growth_k = np.exp(np.maximum(lam.real, 0.0) * self.base_step)
            pat.modal_inverse = inverse
            pat.modal_weights = np.abs(self.delta_rows @ vec) * (np.abs(lam) ** 3 * growth_k)

    def jerk_bound(self, pat: _Pattern, y: FloatArray) -> FloatArray:
        """(J,) bounds on each joint's third derivative of delta over the next base step."""
        norms = np.linalg.norm(pat.jerk_rows, axis=1)
        plain: FloatArray = norms * (pat.growth * float(np.linalg.norm(y)))
        pat.uses += 1
        if pat.uses > MODAL_AFTER_STEPS and not pat.modal_tried:
            self._modal(pat)
        if pat.modal_weights is None or pat.modal_inverse is None:
            return plain
        modal = pat.modal_weights @ np.abs(pat.modal_inverse @ y)
        # round-off in the eigenvectors: keep a sliver of the plain bound as a margin
        bound: FloatArray = np.minimum(modal * (1.0 + 1e-9) + 1e-9 * plain, plain)
        return bound

    def propagate(
        self, pat: _Pattern, y: FloatArray, tau: float, energy: FloatArray | None
    ) -> FloatArray:
        """y (scaled) after tau in [0, H]; adds the energy integrals to ``energy`` if given."""
        if tau <= 0.0:
            return y
        terms = [y]
        size = float(np.abs(y).max())
        while len(terms) < TAYLOR_TERMS:
            terms.append(pat.a @ terms[-1] * (tau / len(terms)))
            if float(np.abs(terms[-1]).max()) <= 1e-18 * size and pat.norm * tau < len(terms):
                break
        d = np.array(terms)
        if energy is not None:
            gram = (d @ self.q) @ d.T  # (2, K, K)
            order = np.arange(d.shape[0])
            weights = tau / (order[:, None] + order[None, :] + 1.0)
            energy += np.sum(gram * weights, axis=(1, 2))
        return np.asarray(d.sum(axis=0), dtype=np.float64)

    # ---- conversions --------------------------------------------------------------------

    def scaled(self, u: FloatArray, v: FloatArray, t: float) -> FloatArray:
        wt = self.omega * t
        state = np.concatenate((u, v, [math.sin(wt), math.cos(wt), 1.0])) * self.scale
        return np.asarray(state, dtype=np.float64)

    def split(self, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        n = self.n
        return y[:n] / self.omega_ref, y[n : 2 * n].copy()

    def mechanical_energy(self, u: FloatArray, v: FloatArray) -> float:
        delta = self.b @ u
        stored = sum(
            float(law.potential_energy(d)) for law, d in zip(self.laws, delta, strict=True)
        )
        return 0.5 * float(v @ (self.m * v)) + 0.5 * float(u @ self.k_linear @ u) + stored

    def states_at(self, delta: FloatArray, rate: FloatArray) -> NDArray[np.int8]:
        states = np.zeros(delta.size, dtype=np.int8)
        states[(delta > self.g_c) | ((delta == self.g_c) & (rate > 0.0))] = COMPRESSION
        states[(delta < -self.g_t) | ((delta == -self.g_t) & (rate < 0.0))] = TENSION
        return states


@dataclass(frozen=True)
class StructureMotion:
    """The exact motion of a structure, sampled, with its contact patterns and energy ledger.

    Attributes
    ----------
    t : (n,) ndarray
        Sample times, s.
    u, v : (n, N) ndarray
        Displacements (m) and velocities (m/s) of the DOFs (``structure.dof_names``).
    pattern : (n, J) ndarray of int8
        Each joint's state at each sample: 0 open, 1 compression, -1 tension.
    energy : EnergyLedger
        input, viscous, sliding_friction (always 0: friction is refused), impact and
        mechanical_energy_change over the whole run, J; ``balance_error`` closes it.
    events : int
        Gap-edge events over the run.
    event_times : (E,) ndarray
        When each event happened, s.
    event_joints : (E,) ndarray of int
        Which joint (index into ``structure.joint_members``) each event belongs to.
    patterns_visited : int
        How many distinct contact patterns were met (each one cached).
    """

    t: FloatArray
    u: FloatArray
    v: FloatArray
    pattern: NDArray[np.int8]
    energy: EnergyLedger
    events: int
    event_times: FloatArray
    event_joints: NDArray[np.int64]
    patterns_visited: int
    final_state: tuple[FloatArray, FloatArray] = field(repr=False)
    structure: Structure = field(repr=False)
    omega: float = 0.0
    initial_energy: float = 0.0

    @property
    def balance_error(self) -> float:
        """abs(input - losses - change of mechanical energy) over the largest energy in play."""
        e = self.energy
        scale = max(abs(e.input), e.losses, self.initial_energy, 1e-300)
        return abs(e.input - e.losses - e.mechanical_energy_change) / scale

    def __repr__(self) -> str:
        return (
            f"StructureMotion({self.t.size} samples over {self.t[-1]:.4g} s, "
            f"{self.u.shape[1]} DOF, {self.events} events, {self.patterns_visited} patterns, "
            f"energy balance error {self.balance_error:.1e})"
        )

    def plot(self, ax: Any = None, *, dof: int | None = None) -> Any:
        """Plot the displacement of ``dof`` (default: the largest moving one) in mm; return Axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        if dof is None:
            dof = int(np.argmax(np.ptp(self.u, axis=0)))
        ax.plot(self.t, 1e3 * self.u[:, dof], lw=0.8)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"{self.structure.dof_names[dof]} displacement (mm)")
        return ax

    def to_xarray(self) -> Any:
        """The motion as an xarray Dataset, units in attrs."""
        import xarray as xr

        ledger = {f"energy_{k}_J": v for k, v in self.energy.as_dict().items()}
        return xr.Dataset(
            {
                "u": (("time", "dof"), self.u, {"units": "m"}),
                "v": (("time", "dof"), self.v, {"units": "m/s"}),
                "pattern": (
                    ("time", "joint"),
                    self.pattern,
                    {"units": "1", "meaning": "0 open, 1 compression, -1 tension"},
                ),
            },
            coords={
                "time": ("time", self.t, {"units": "s"}),
                "dof": self.structure.dof_names,
                "joint": np.arange(self.pattern.shape[1]),
            },
            attrs={"events": self.events, "omega_rad_per_s": self.omega, **ledger},
        )


def _vector(name: str, value: ArrayLike, structure: Structure) -> FloatArray:
    array = np.asarray(value, dtype=np.float64)
    n = structure.n_dof
    if array.ndim != 1 or array.size != n:
        names = ", ".join(structure.dof_names[:4]) + (", ..." if n > 4 else "")
        raise StructureError(
            f"{name} has {array.size} entries but the structure has {n} DOF ({names}); "
            f"give one value per DOF"
        )
    if not np.all(np.isfinite(array)):
        raise StructureError(f"{name} must be finite")
    return array


def _initial(structure: Structure, initial: Any) -> tuple[FloatArray, FloatArray]:
    n = structure.n_dof
    if initial is None:
        return np.zeros(n), np.zeros(n)
    if isinstance(initial, tuple | list) and len(initial) == 2:
        return _vector("initial u0", initial[0], structure), _vector(
            "initial v0", initial[1], structure
        )
    array = np.asarray(initial, dtype=np.float64)
    if array.shape == (2, n):
        return _vector("initial u0", array[0], structure), _vector(
            "initial v0", array[1], structure
        )
    raise StructureError(
        f"initial must be (u0, v0), each of {n} values (m, m/s), got shape {array.shape}"
    )


def _check_joints(structure: Structure) -> None:
    for index in structure.joint_members:
        joint = structure.members[index].joint
        if joint is not None and joint.friction is not None:
            raise StructureError(
                f"member {index}: Coulomb friction in a joint of a structure is not carried "
                "(sticking would be a constraint the exact pattern flow does not model); "
                "set friction=None, or use clearjoint.simulate for a single joint"
            )


def _sample_times(duration: float, period: float, samples_per_period: int) -> FloatArray:
    """As the one-joint simulator samples: uniform over [0, duration)."""
    if (
        isinstance(samples_per_period, bool)
        or not isinstance(samples_per_period, int)
        or (samples_per_period < 8)
    ):
        raise StructureError(
            f"samples_per_period must be an integer >= 8, got {samples_per_period!r}"
        )
    n = max(round(samples_per_period * duration / period), 2)
    if duration >= period:
        return np.linspace(0.0, duration, n + 1)[:-1]
    return np.linspace(0.0, duration, n)


def _run(
    flow: _Flow,
    u0: FloatArray,
    v0: FloatArray,
    duration: float,
    times: FloatArray,
) -> StructureMotion:
    n_j = len(flow.laws)
    h_base = flow.base_step
    t = 0.0
    y = flow.scaled(u0, v0, 0.0)
    delta0 = flow.b @ u0
    states = flow.states_at(delta0, flow.b @ v0)
    energy = np.zeros(2)
    impact = 0.0
    out_y = np.zeros((times.size, y.size))
    out_p = np.zeros((times.size, n_j), dtype=np.int8)
    next_sample = 0
    event_times: list[float] = []
    event_joints: list[int] = []
    eps = 1e-14 * h_base
    max_events = MAX_EVENTS_PER_STEP * (int(duration / h_base) + 1)
    g0 = np.full(2 * n_j, 1e300)
    g1 = np.zeros(2 * n_j)
    g2 = np.zeros(2 * n_j)
    bounds = np.zeros(2 * n_j)
    open_ = states == OPEN
    while True:
        pat = flow.pattern(states)
        y[-3:] = flow.scale[-3:] * np.array(
            [math.sin(flow.omega * t), math.cos(flow.omega * t), 1.0]
        )
        dy = pat.a @ y
        ddy = pat.a @ dy
        d = flow.delta_rows @ np.column_stack((y, dy, ddy))  # (J, 3): delta, delta', delta''
        open_ = states == OPEN
        comp = states == COMPRESSION
        tens = states == TENSION
        # slot 2j: the compression edge; slot 2j + 1: the tension edge (each > 0 inside)
        sign_c = np.where(comp, 1.0, -1.0)
        g0[0::2] = np.where(open_ | comp, sign_c * (d[:, 0] - flow.g_c), 1e300)
        g1[0::2] = sign_c * d[:, 1]
        g2[0::2] = sign_c * d[:, 2]
        sign_t = np.where(tens, -1.0, 1.0)
        g0[1::2] = np.where(open_ | tens, sign_t * (d[:, 0] + flow.g_t), 1e300)
        g1[1::2] = sign_t * d[:, 1]
        g2[1::2] = sign_t * d[:, 2]
        bound = flow.jerk_bound(pat, y)
        bounds[0::2] = bound
        bounds[1::2] = bound
        remaining = duration - t
        h_max = min(h_base, remaining)
        h, which = _first_event(g0, g1, g2, bounds, h_max)
        # an event when the certified step has shrunk to round-off of the step or of t
        event = which >= 0 and h <= max(eps, 8.0 * math.ulp(t))
        if not event and which >= 0:
            which = -1  # a certified step short of the event
        # samples that fall inside [t, t + h)
        while next_sample < times.size and times[next_sample] < t + h:
            tau = max(times[next_sample] - t, 0.0)
            out_y[next_sample] = flow.propagate(pat, y, tau, None)
            out_p[next_sample] = states
            next_sample += 1
        y = flow.propagate(pat, y, h, energy)
        t += h
        if h >= remaining and not event:
            break
        if not event:
            continue
        joint = which // 2
        event_times.append(t)
        event_joints.append(joint)
        if len(event_times) > max_events:
            raise SimulationError(
                f"more than {max_events} gap-edge events in {t:.4g} s (chattering at joint "
                f"{joint}); add damping or a restitution below 1"
            )
        entering = states[joint] == OPEN
        if which % 2 == 0:
            states[joint] = COMPRESSION if entering else OPEN
        else:
            states[joint] = TENSION if entering else OPEN
        e = flow.restitution[joint]
        if entering and e < 1.0:
            n = flow.n
            speed = float(flow.b[joint] @ y[n : 2 * n])
            impact += 0.5 * (1.0 - e * e) * flow.m_eff[joint] * speed * speed
            y[n : 2 * n] -= (1.0 - e) * speed * flow.m_eff[joint] * flow.impulse_dirs[joint]
    u_end, v_end = flow.split(y)
    u = out_y[:, : flow.n] / flow.omega_ref
    v = out_y[:, flow.n : 2 * flow.n].copy()
    ledger = EnergyLedger(
        input=float(energy[0]),
        viscous=float(energy[1]),
        sliding_friction=0.0,
        impact=impact,
        mechanical_energy_change=flow.mechanical_energy(u_end, v_end)
        - flow.mechanical_energy(u0, v0),
    )
    return StructureMotion(
        t=times,
        u=u,
        v=v,
        pattern=out_p,
        energy=ledger,
        events=len(event_times),
        event_times=np.array(event_times),
        event_joints=np.array(event_joints, dtype=np.int64),
        patterns_visited=len(flow.patterns),
        final_state=(u_end, v_end),
        structure=flow.structure,
        omega=flow.omega,
        initial_energy=flow.mechanical_energy(u0, v0),
    )


def time_response(
    structure: Structure,
    force: ArrayLike,
    omega: float,
    duration: float,
    *,
    initial: Any = None,
    samples_per_period: int = 256,
) -> StructureMotion:
    """Return the exact forced motion under F sin(omega t) from ``initial`` over ``duration`` s.

    MODEL.md 5.2: piecewise-linear per contact pattern, solved in closed form per
    pattern (cached), events certified (see the module docstring).

    Parameters
    ----------
    structure : Structure
    force : (N,) array_like
        Per-DOF force amplitudes F, N (``structure.dof_names`` gives the order).
    omega : float
        Forcing circular frequency, rad/s, > 0.
    duration : float
        s, > 0.
    initial : (u0, v0), optional
        Each (N,) in m and m/s; default at rest at u = 0.
    samples_per_period : int
        Samples per forcing period, uniform over [0, duration).

    Returns
    -------
    StructureMotion

    Raises
    ------
    StructureError
        A force or initial vector of the wrong length, friction in a joint.
    SimulationError
        Chattering (too many events).
    """
    if not isinstance(structure, Structure):
        raise StructureError(
            f"structure must be a clearjoint.structure.Structure, got {structure!r}"
        )
    _check_joints(structure)
    f = _vector("force", force, structure)
    w = _checks.positive("omega", omega, unit="rad/s")
    duration = _checks.positive("duration", duration, unit="s")
    u0, v0 = _initial(structure, initial)
    times = _sample_times(duration, 2.0 * math.pi / w, samples_per_period)
    return _run(_Flow(structure, f, w), u0, v0, duration, times)


def free_decay(
    structure: Structure,
    initial: Any,
    duration: float,
    *,
    samples_per_period: int = 256,
) -> StructureMotion:
    """Return the exact free motion from ``initial`` = (u0, v0) over ``duration`` s.

    Sampled ``samples_per_period`` times per period of the first closed-pattern mode.
    Same solver as :func:`time_response` with no forcing.
    """
    if not isinstance(structure, Structure):
        raise StructureError(
            f"structure must be a clearjoint.structure.Structure, got {structure!r}"
        )
    _check_joints(structure)
    duration = _checks.positive("duration", duration, unit="s")
    u0, v0 = _initial(structure, initial)
    first = float(structure.modes("closed").omega[0])
    times = _sample_times(duration, 2.0 * math.pi / first, samples_per_period)
    return _run(_Flow(structure, np.zeros(structure.n_dof), 0.0), u0, v0, duration, times)
