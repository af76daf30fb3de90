"""Exact motion of a structure with many clearance joints, event by event (MODEL.md 5.2).

In one contact pattern s the structure is linear,

    M u'' + C u' + K_s u = F sin(w t) + r_s,

and so is the augmented state y = (u, v, sin w t, cos w t, 1): y' = A_s y. Its flow
exp(A_s tau) is therefore exact for the forcing and the joints' constant forces alike,
with no special case for a singular K_s (an open joint with k0 = 0), a defective A_s or
resonance. Steps start at a base step H (an eighth of the shortest period of forcing,
structure and damping) after each event and double after each step that meets no edge,
up to 4 H (``clearjoint.exact.march.MAX_STEP_GROWTH``), so abs(A_s tau) is of order one
and the Taylor series of exp(A_s tau) y, summed until its terms fall below 1e-18 of y,
is the exact flow to round-off. The same series carries the energy integrals exactly:
the input power F.v sin(w t) and the viscous power v^T C v are polynomials in tau,
integrated term by term. A_s y is applied matrix-free from sparse pieces (the plain
members' stiffness, C, and each joint's direction b_j with its stiffness and offset in
its present state), so a new contact pattern costs nothing to set up; the whole march
runs compiled, in one call (``clearjoint.exact.march``).

Events (a joint's shortening delta_j reaches a gap edge) are found without a miss: over
a step each edge distance g is the polynomial given by the step's Taylor series up to a
rigorous bound on the series' tail, and the first root of that lower bound (isolated in
the Bernstein basis, grazing included) is never later than the first root of g; the step
goes there and the event is declared. Restitution on a joint that links two masses
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
import scipy.sparse
from numpy.typing import ArrayLike, NDArray

from clearjoint import checks as _checks
from clearjoint.compiled import prefer
from clearjoint.errors import ParameterError
from clearjoint.exact import march, single
from clearjoint.laws import clearance
from clearjoint.progress import report
from clearjoint.results import EnergyLedger
from clearjoint.simulate.core import SimulationError
from clearjoint.structure.model import (
    Structure,
    StructureError,
    default_dof_names,
    require_masses,
    system_modes,
)
from clearjoint.system import Matrix, VibrationSystem, as_system

FloatArray = NDArray[np.float64]

#: The base step, in periods of the fastest rate (structure, forcing or damping).
BASE_STEP_PERIODS = 1.0 / 8.0

#: The most events allowed per base step on average before the run is called chattering.
MAX_EVENTS_PER_STEP = 1000
#: Pieces a forced response or a free decay is marched in, each ending in a progress
#: report (clearjoint.progress): the same steps as one march, so the same motion to the bit.
PROGRESS_PIECES = 100


def _dense(matrix: Matrix) -> FloatArray:
    """``matrix`` as a dense float64 array (the flow's set-up works on dense pieces)."""
    dense = matrix.toarray() if scipy.sparse.issparse(matrix) else matrix
    return np.asarray(dense, dtype=np.float64)


class _Flow:
    """A structure's exact flow, set up once for ``march.march`` (sparse pieces, scales)."""

    def __init__(
        self, system: VibrationSystem | Structure, force: FloatArray, omega: float
    ) -> None:
        s = as_system(system)
        self.n = n = s.n_dof
        self.m = s.mass_diagonal()
        self.c = _dense(s.damping)
        self.force = force
        self.omega = omega
        self.b = s.directions
        self.laws = s.laws
        law_parameters = clearance.parameters(self.laws)
        self.g_c, self.g_t = law_parameters[3:]
        self.restitution = s.restitution()
        inv_m = 1.0 / self.m
        self.impulse_dirs = self.b * inv_m  # rows M^-1 b_j
        self.m_eff = 1.0 / np.maximum(np.einsum("jn,jn->j", self.b, self.impulse_dirs), 1e-300)
        self.k_linear = _dense(s.stiffness)
        self.system = s
        n_j = len(self.laws)
        # each joint's (stiffness, offset) in state -1, 0, 1 (column state + 1)
        self.k_table, self.r_table = prefer(clearance.state_tables)(*law_parameters)
        k_stiff = self.k_linear + (self.b.T * np.max(self.k_table, axis=1)) @ self.b
        w2 = scipy.linalg.eigh(k_stiff, np.diag(self.m), eigvals_only=True)
        self.omega_ref = math.sqrt(max(float(w2[-1]), 1e-300))
        rates = [self.omega_ref, omega]
        c_rate = scipy.linalg.eigh(self.c, np.diag(self.m), eigvals_only=True)
        rates.append(float(c_rate[-1]))
        self.base_step = 2.0 * math.pi / max(rates) * BASE_STEP_PERIODS
        # scaling: u -> omega_ref u, v -> v, (sin, cos, 1) -> v_ref (sin, cos, 1)
        offsets = np.max(np.abs(self.r_table), axis=1)
        push_norm = float(np.linalg.norm(np.abs(force) * inv_m))
        push_norm += sum(
            o * float(np.linalg.norm(r)) for o, r in zip(offsets, self.impulse_dirs, strict=True)
        )
        self.v_ref = push_norm / self.omega_ref if push_norm > 0.0 else 1.0
        # infinity norm of the scaled generator, bounded over every pattern
        abs_b = np.abs(self.b)
        k_abs = np.abs(self.k_linear) + (abs_b.T * np.max(np.abs(self.k_table), axis=1)) @ abs_b
        rows_v = (
            np.sum(k_abs, axis=1) / self.omega_ref
            + np.sum(np.abs(self.c), axis=1)
            + (np.abs(force) + abs_b.T @ offsets) / self.v_ref
        ) * inv_m
        self.norm_a = float(max(self.omega_ref, omega, float(np.max(rows_v, initial=0.0))))
        self.c_csr = scipy.sparse.csr_matrix(self.c)
        self.b_csr = scipy.sparse.csr_matrix(self.b.reshape(n_j, n))
        self.scale = np.concatenate(  # y_scaled = scale * y
            (np.full(n, self.omega_ref), np.ones(n), np.full(3, self.v_ref))
        )

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
        """Each joint's contact state at shortenings ``delta`` moving at ``rate`` (n_j,)."""
        return prefer(clearance.contact_states)(
            np.ascontiguousarray(delta, dtype=np.float64),
            np.ascontiguousarray(rate, dtype=np.float64),
            self.g_c,
            self.g_t,
        )


@dataclass(frozen=True)
class StructureMotion:
    """The exact motion of a structure, sampled, with its contact patterns and energy ledger.

    Attributes
    ----------
    t : (n,) ndarray
        Sample times, s.
    u, v : (n, N) ndarray
        Displacements (m) and velocities (m/s) of the DOFs (``dof_names``).
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
        Which joint (row of the system's ``directions``; for a structure, index into
        ``structure.joint_members``) each event belongs to.
    patterns_visited : int
        How many distinct contact patterns were met.
    steps : int
        Steps of the exact flow taken (one ends at each event; the others are at most four
        base steps, a base step being an eighth of the shortest period).
    structure : Structure or None
        The structure moved (``system.source``); None for a system given as matrices.
    dof_names : tuple of str
        A name per DOF, from the system.
    system : VibrationSystem or None
        The system moved.
    event_states : (E,) ndarray of int8
        The state each event's joint entered (0 open, 1 compression, -1 tension).
    start_pattern : (J,) ndarray of int8
        Every joint's state at t = 0; with ``event_states`` it gives the pattern of every
        stretch between events (``clearjoint.exact.march.pattern_history``).
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
    structure: Structure | None = field(repr=False)
    omega: float = 0.0
    initial_energy: float = 0.0
    steps: int = 0
    dof_names: tuple[str, ...] = field(default=(), repr=False)
    system: VibrationSystem | None = field(default=None, repr=False)
    event_states: NDArray[np.int8] = field(
        default_factory=lambda: np.zeros(0, dtype=np.int8), repr=False
    )
    start_pattern: NDArray[np.int8] = field(
        default_factory=lambda: np.zeros(0, dtype=np.int8), repr=False
    )

    def __post_init__(self) -> None:
        if not self.dof_names:
            names = default_dof_names(self.structure, self.u.shape[1])
            object.__setattr__(self, "dof_names", names)

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
        ax.set_ylabel(f"{self.dof_names[dof]} displacement (mm)")
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
                "dof": list(self.dof_names),
                "joint": np.arange(self.pattern.shape[1]),
            },
            attrs={"events": self.events, "omega_rad_per_s": self.omega, **ledger},
        )

    def to_pandas(self) -> Any:
        """Return the sampled motion as a ``pandas.DataFrame``, one row per sample.

        Returns
        -------
        pandas.DataFrame
            Index ``time_s``; columns ``u_m[<dof name>]`` then ``v_m_per_s[<dof name>]``
            for each DOF (``dof_names``). The contact patterns, events and
            energy ledger are in :meth:`to_xarray`.
        """
        import pandas as pd

        names = self.dof_names
        columns = {f"u_m[{name}]": self.u[:, k] for k, name in enumerate(names)}
        columns.update({f"v_m_per_s[{name}]": self.v[:, k] for k, name in enumerate(names)})
        return pd.DataFrame(columns, index=pd.Index(self.t, name="time_s"))


def _vector(name: str, value: ArrayLike, structure: Structure | VibrationSystem) -> FloatArray:
    array = np.asarray(value, dtype=np.float64)
    n = structure.n_dof
    names = ", ".join(structure.dof_names[:4]) + (", ..." if n > 4 else "")
    if array.ndim != 1:  # a scalar or a table is not "n entries": name its shape
        raise StructureError(
            f"{name} must be a 1-D array of {n} value{'s' if n > 1 else ''} per DOF ({names}), "
            f"got shape {array.shape}"
        )
    if array.size != n:
        raise StructureError(
            f"{name} has {array.size} entries but the structure has {n} DOF ({names}); "
            f"give one value per DOF"
        )
    if not np.all(np.isfinite(array)):
        raise StructureError(f"{name} must be finite")
    return array


def _initial(structure: Structure | VibrationSystem, initial: Any) -> tuple[FloatArray, FloatArray]:
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


def _check_joints(system: VibrationSystem) -> None:
    source = system.source
    for j, loss in enumerate(system.losses):
        if loss.friction is not None:
            where = (
                f"member {source.joint_members[j]}"
                if isinstance(source, Structure)
                else f"joint {j}"
            )
            raise StructureError(
                f"{where}: Coulomb friction in a joint of a structure is not carried "
                "(sticking would be a constraint the exact pattern flow does not model); "
                "set friction=None, or use clearjoint.simulate for a single joint"
            )


def _sample_times(duration: float, period: float, samples_per_period: int) -> FloatArray:
    """Uniform sample times over [0, duration), as the one-joint simulator samples them.

    By :func:`clearjoint.exact.single.sample_times`; its refusal of ``samples_per_period``
    is raised as a StructureError, with the same message.
    """
    try:
        return single.sample_times(duration, period, samples_per_period, None)
    except ParameterError as exc:
        raise StructureError(str(exc)) from None


def _patterns_visited(
    start: NDArray[np.int8], joints: NDArray[np.int64], new_states: NDArray[np.int8]
) -> int:
    """How many distinct contact patterns the event sequence passes through."""
    if start.size == 0:
        return 1
    history = np.ascontiguousarray(prefer(march.pattern_history)(start, joints, new_states))
    rows = history.view(np.dtype((np.void, history.shape[1])))
    return int(np.unique(rows).size)


def _run(
    flow: _Flow,
    u0: FloatArray,
    v0: FloatArray,
    duration: float,
    times: FloatArray,
    *,
    pieces: int = 1,
) -> StructureMotion:
    """March the exact motion over ``duration`` s, sampled at ``times``.

    With ``pieces`` > 1 the march pauses that many times, at equal stretches of time, to
    report its progress (:func:`clearjoint.progress.report`, in seconds of motion); the
    pieces make exactly the steps of one march, so the result is the same to the bit.
    """
    n = flow.n
    y = flow.scaled(u0, v0, 0.0)
    states = flow.states_at(flow.b @ u0, flow.b @ v0)
    start_states = states.copy()
    max_events = MAX_EVENTS_PER_STEP * (int(duration / flow.base_step) + 1)
    c, b = flow.c_csr, flow.b_csr
    # one sparsity pattern for the plain stiffness and the damping, M^-1 and scaling in
    a = scipy.sparse.csr_matrix((np.abs(flow.k_linear) + np.abs(flow.c)) > 0.0, dtype=np.float64)
    a.sort_indices()
    rows = np.repeat(np.arange(n), np.diff(a.indptr))
    a_u = flow.k_linear[rows, a.indices] / (flow.m[rows] * flow.omega_ref)
    a_v = flow.c[rows, a.indices] / flow.m[rows]
    out_y = np.zeros((times.shape[0], 2 * n + 3))
    out_p = np.zeros((times.shape[0], states.shape[0]), dtype=np.int8)
    energy = np.zeros(2)
    clock = np.zeros(march.N_CLOCK)
    clock[march.C_H] = flow.base_step
    events: list[tuple[FloatArray, NDArray[np.int64], NDArray[np.int8]]] = []
    count = 0
    fixed = (
        np.asarray(flow.force, dtype=np.float64),
        a.indptr.astype(np.int64),
        a.indices.astype(np.int64),
        a_u,
        a_v,
        c.indptr.astype(np.int64),
        c.indices.astype(np.int64),
        c.data.astype(np.float64),
        b.indptr.astype(np.int64),
        b.indices.astype(np.int64),
        b.data.astype(np.float64),
    )
    status = march.PAUSED
    piece = 0
    while status == march.PAUSED:
        piece += 1
        t_pause = math.inf if piece >= pieces else duration * piece / pieces
        y, states, impact, ev_t, ev_j, ev_s, steps, status = prefer(march.march)(
            y,
            states,
            float(duration),
            times,
            flow.base_step,
            n,
            float(flow.omega),
            flow.omega_ref,
            flow.v_ref,
            1.0 / flow.m,
            *fixed,
            flow.k_table,
            flow.r_table,
            flow.g_c,
            flow.g_t,
            flow.restitution,
            flow.m_eff,
            flow.norm_a,
            max_events - count,
            out_y,
            out_p,
            energy,
            clock,
            t_pause,
        )
        events.append((ev_t, ev_j, ev_s))
        count += ev_t.size
        if pieces > 1:
            report(min(clock[march.C_T], duration), duration)
    y_end = y
    ev_t = np.concatenate([e[0] for e in events])
    ev_j = np.concatenate([e[1] for e in events])
    ev_s = np.concatenate([e[2] for e in events])
    if status == march.CHATTER:
        raise SimulationError(
            f"more than {max_events} gap-edge events in {float(ev_t[-1]):.4g} s (chattering "
            f"at joint {int(ev_j[-1])}); add damping or a restitution below 1"
        )
    if status != march.DONE:
        raise SimulationError(
            "the pattern flow's Taylor series did not converge even on a step 1e-12 of the "
            "base step; check the structure's stiffness and mass for extreme values"
        )
    u_end, v_end = flow.split(y_end)
    u = out_y[:, :n] / flow.omega_ref
    v = out_y[:, n : 2 * n].copy()
    ledger = EnergyLedger(
        input=float(energy[0]),
        viscous=float(energy[1]),
        sliding_friction=0.0,
        impact=float(impact),
        mechanical_energy_change=flow.mechanical_energy(u_end, v_end)
        - flow.mechanical_energy(u0, v0),
    )
    return StructureMotion(
        t=times,
        u=u,
        v=v,
        pattern=out_p,
        energy=ledger,
        events=int(ev_t.size),
        event_times=np.asarray(ev_t, dtype=np.float64),
        event_joints=np.asarray(ev_j, dtype=np.int64),
        patterns_visited=_patterns_visited(start_states, ev_j, ev_s),
        final_state=(u_end, v_end),
        structure=flow.system.source if isinstance(flow.system.source, Structure) else None,
        omega=flow.omega,
        initial_energy=flow.mechanical_energy(u0, v0),
        steps=int(steps),
        dof_names=flow.system.dof_names,
        system=flow.system,
        event_states=np.asarray(ev_s, dtype=np.int8),
        start_pattern=np.asarray(start_states, dtype=np.int8).copy(),
    )


def time_response(
    structure: Structure | VibrationSystem,
    force: ArrayLike,
    omega: float,
    duration: float,
    *,
    initial: Any = None,
    samples_per_period: int = 256,
) -> StructureMotion:
    """Return the exact forced motion under F sin(omega t) from ``initial`` over ``duration`` s.

    MODEL.md 5.2: piecewise-linear per contact pattern, solved in closed form per
    pattern, events certified (see the module docstring).

    Parameters
    ----------
    structure : Structure or VibrationSystem
        A Structure is turned into its system once (``as_system``); the system's M
        must be lumped (diagonal).
    force : (N,) array_like
        Per-DOF force amplitudes F, N (``dof_names`` gives the order).
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
    ParameterError
        A consistent (non-diagonal) mass matrix.
    SimulationError
        Chattering (too many events).
    """
    system = _system(structure)
    f = _vector("force", force, system)
    w = _checks.positive("omega", omega, unit="rad/s")
    duration = _checks.positive("duration", duration, unit="s")
    u0, v0 = _initial(system, initial)
    times = _sample_times(duration, 2.0 * math.pi / w, samples_per_period)
    return _run(_Flow(system, f, w), u0, v0, duration, times, pieces=PROGRESS_PIECES)


def free_decay(
    structure: Structure | VibrationSystem,
    initial: Any,
    duration: float,
    *,
    samples_per_period: int = 256,
) -> StructureMotion:
    """Return the exact free motion from ``initial`` = (u0, v0) over ``duration`` s.

    Sampled ``samples_per_period`` times per period of the first closed-pattern mode.
    Same solver as :func:`time_response` with no forcing; a Structure or a
    VibrationSystem (lumped M).
    """
    system = _system(structure)
    duration = _checks.positive("duration", duration, unit="s")
    u0, v0 = _initial(system, initial)
    source = system.source
    # a structure's own modes keep its arithmetic order (the sample times to the bit)
    modes = source.modes("closed") if isinstance(source, Structure) else system_modes(system)
    first = float(modes.omega[0])
    times = _sample_times(duration, 2.0 * math.pi / first, samples_per_period)
    flow = _Flow(system, np.zeros(system.n_dof), 0.0)
    return _run(flow, u0, v0, duration, times, pieces=PROGRESS_PIECES)


def _system(structure: Any) -> VibrationSystem:
    """A Structure's system (built once) or a VibrationSystem, checked for the flow."""
    if not isinstance(structure, Structure | VibrationSystem):
        raise StructureError(
            "structure must be a clearjoint.structure.Structure or a "
            f"clearjoint.system.VibrationSystem, got {structure!r}"
        )
    system = as_system(structure)
    _check_joints(system)
    # a consistent mass is refused here, in one line, and so is a DOF without mass
    require_masses(system.mass_diagonal(), "the exact motion", system.dof_names)
    return system
