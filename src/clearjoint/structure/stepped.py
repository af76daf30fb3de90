"""A stepped-sine test of a structure, run exactly: what the motion is where no orbit is stable.

MODEL.md 5.1-5.2. At each frequency of the list, from the state the previous frequency
left (as a lab's stepped-sine test does), the exact event-driven motion runs
``settle_periods`` forcing periods and then ``record_periods`` more, sampled. Per
frequency:

- ``amplitude``: max abs(u) of each DOF over the recorded periods (the sampled extremes
  refined by the local cubic of the exact motion), or, where the verdict is a confirmed
  orbit, over that orbit (what the recorded periods tend to once settled: a lightly
  damped transient may not have died out in them); ``rms`` over the recorded samples;
- ``poincare``: the state (u, v) at forcing phase 0 at the start of each recorded period;
- ``lyapunov``: the largest Lyapunov exponent (1/s) of the recorded motion, from its
  exact tangent flow (``clearjoint.structure.tangent``: the contact patterns'
  exponentials over the stretches the motion met, a tangent vector renormalised every
  period), with its standard error over blocks of periods;
- ``kind``, decided in this order:

  1. "periodic" or "period-k": the Poincaré samples repeat after k periods (the smallest k
     up to ``MAX_PERIOD``) within ``LOOSE`` of their size over the last 4k samples, or the
     exponent is negative (the motion contracts, still settling) and k <= ``SETTLING_PERIOD``;
     and Newton on the exact k-period map (``clearjoint.structure.periodic_orbit``, closure
     1e-10) converges from the last sample to an orbit whose Floquet multipliers all lie
     inside the unit circle. The verdict is that orbit's, never the samples' alone.
  2. "chaotic": the exponent is positive by more than three standard errors and more than
     ``ZERO_RATE`` / T (bounded, non-periodic, with exponential separation).
  3. "quasi-periodic": the exponent is zero within three standard errors (or within
     ``ZERO_RATE`` / T) and the samples do not repeat.
  4. "unsettled": the exponent is negative beyond that (the motion converges to an
     attractor) but no stable orbit was confirmed: more settling periods would decide it.

``direction="both"`` runs up then down and marks the ``jumps``: steps whose largest
amplitude changes by more than ``JUMP_RATIO`` where the two sweeps disagree (by as much)
at one end of the step, the hysteresis that makes it a jump (one direction alone: every
change by more than ``JUMP_RATIO``).

With a ``runner`` (a ``concurrent.futures`` executor or a ``dask.distributed`` client,
:mod:`clearjoint.parallel`) each direction's frequencies are cut into ``chunks``
contiguous runs that go in parallel; the state carries within a run, and each run's
first frequency starts from rest and settles twice as long. So a parallel diagram may
differ from a serial one where several attractors coexist at a run's first frequency
(``chunk_starts`` says where the runs begin).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint.errors import ParameterError
from clearjoint.parallel import run_ordered
from clearjoint.progress import report
from clearjoint.simulate.core import SimulationError
from clearjoint.structure.motion import _Flow, _run, _system, _vector
from clearjoint.structure.poincare import OrbitError, ShootingMap, newton_orbit, turning_extremes
from clearjoint.structure.tangent import (
    PatternFlows,
    impact_jumps,
    largest_exponent,
    pattern_history,
    refuse_restitution,
)
from clearjoint.system import VibrationSystem

FloatArray = NDArray[np.float64]

#: Samples a recorded period (amplitude, rms).
SAMPLES_PER_PERIOD = 32
#: Longest period (in forcing periods) a periodic verdict looks for.
MAX_PERIOD = 8
#: Poincaré samples that repeat within this fraction of their size suggest a period-k
#: orbit, which Newton then confirms (or not) to closure 1e-10.
LOOSE = 1e-3
#: A contracting motion (negative exponent) whose samples do not repeat yet is tried for
#: orbits up to this period from its last sample.
SETTLING_PERIOD = 2
#: An exponent within this many forcing periods' worth (lambda T) of 0 counts as zero.
ZERO_RATE = 1e-3
#: Neighbouring frequencies whose largest amplitudes differ by more than this factor jump.
JUMP_RATIO = 1.5
#: The first 1/ALIGNING of the recorded periods turn the tangent vector (carried from the
#: previous frequency) towards the most growing direction; the exponent is measured over
#: the rest.
ALIGNING = 4
#: Kinds, in the order of their integer codes in :meth:`SteppedSine.to_xarray`.
KINDS = ("periodic", "period-k", "quasi-periodic", "chaotic", "unsettled")


class SteppedSineError(ParameterError):
    """A stepped-sine request that cannot be run as given."""


@dataclass(frozen=True)
class _Chunk:
    """One contiguous run of frequencies (rad/s) in the order they are stepped."""

    system: VibrationSystem
    force: FloatArray
    omegas: FloatArray
    settle_periods: int
    record_periods: int
    first_settle: int
    done_before: int = 0
    total: int = 0


@dataclass(frozen=True)
class _Point:
    amplitude: FloatArray
    rms: FloatArray
    poincare: FloatArray
    lyapunov: float
    lyapunov_error: float
    kind: str
    period: int
    events: int


def _classify(
    shoot: ShootingMap, flows: PatternFlows, poincare: FloatArray, rate: float, error: float
) -> tuple[str, int, FloatArray | None]:
    """The kind of the recorded motion, its period (0 where none) and, for a confirmed
    orbit, its amplitude per DOF (module docstring)."""
    n = shoot.n
    period = shoot.period
    scaled = np.concatenate((shoot.omega * poincare[:, :n], poincare[:, n:]), axis=1)
    size = max(float(np.max(np.linalg.norm(scaled, axis=1))), 1e-300)
    count = scaled.shape[0]
    zero = ZERO_RATE / period
    settling = rate + 3.0 * error < 0.0 and rate < -zero
    for k in range(1, min(MAX_PERIOD, count // 4) + 1):
        tail = scaled[count - 4 * k :]
        gap = float(np.max(np.linalg.norm(tail[k:] - tail[:-k], axis=1)))
        # a contracting motion still settling may be near an orbit of low period
        if gap > LOOSE * size and not (settling and k <= SETTLING_PERIOD):
            continue
        orbit_map = ShootingMap(shoot.system, shoot.force, shoot.omega, k, flows)
        found = newton_orbit(orbit_map, poincare[-1].copy(), 1e-12 * size)
        if found is None:
            continue
        mu = np.linalg.eigvals(found[1])
        if np.all(np.abs(mu) < 1.0):
            orbit = orbit_map.run(found[0], SAMPLES_PER_PERIOD * 4)
            x_max, x_min = turning_extremes(orbit, shoot.system, shoot.force, np.eye(shoot.n))
            reach = np.maximum(np.abs(x_max), np.abs(x_min))
            return ("periodic", 1, reach) if k == 1 else ("period-k", k, reach)
    if rate - 3.0 * error > 0.0 and rate > zero:
        return "chaotic", 0, None
    if settling:
        return "unsettled", 0, None
    return "quasi-periodic", 0, None


def _run_chunk(chunk: _Chunk) -> list[_Point]:
    """Step through one run of frequencies from rest; a pure function of ``chunk``."""
    system = chunk.system
    n = system.n_dof
    impacts = bool(np.any(system.restitution() < 1.0))
    flows = PatternFlows(system, impacts=impacts)
    u = np.zeros(n)
    v = np.zeros(n)
    out: list[_Point] = []
    eye = np.eye(n)
    tangent: FloatArray | None = None
    for i, omega in enumerate(chunk.omegas):
        shoot = ShootingMap(system, chunk.force, float(omega), 1, flows)
        flow: _Flow = shoot.flow
        period = shoot.period
        settle = chunk.first_settle if i == 0 else chunk.settle_periods
        settled = _run(flow, u, v, settle * period, np.zeros(1))
        u, v = settled.final_state
        count = chunk.record_periods * SAMPLES_PER_PERIOD
        times = np.arange(count, dtype=np.float64) * (period / SAMPLES_PER_PERIOD)
        recorded = _run(flow, u, v, chunk.record_periods * period, times)
        x_max, x_min = turning_extremes(recorded, system, chunk.force, eye)
        jumps = (
            impact_jumps(
                flow, recorded, pattern_history(recorded), u, v, chunk.record_periods * period
            )
            if impacts
            else None
        )
        rate, error, tangent = largest_exponent(
            flows,
            recorded,
            period,
            chunk.record_periods,
            start=tangent,
            aligning=chunk.record_periods // ALIGNING,
            jumps=jumps,
        )
        poincare = np.concatenate(
            (recorded.u[::SAMPLES_PER_PERIOD], recorded.v[::SAMPLES_PER_PERIOD]), axis=1
        )
        kind, k, reach = _classify(shoot, flows, poincare, rate, error)
        out.append(
            _Point(
                amplitude=np.maximum(np.abs(x_max), np.abs(x_min)) if reach is None else reach,
                rms=np.sqrt(np.mean(recorded.u**2, axis=0)),
                poincare=poincare,
                lyapunov=rate,
                lyapunov_error=error,
                kind=kind,
                period=k,
                events=recorded.events,
            )
        )
        u, v = recorded.final_state
        report(chunk.done_before + i + 1, chunk.total)  # heard in this process only
    return out


@dataclass(frozen=True)
class SteppedSine:
    """What a stepped-sine test of a structure reads, computed exactly (module docstring).

    Attributes
    ----------
    omega : (n,) ndarray
        The frequencies, rad/s, increasing.
    directions : tuple of str
        ("up",), ("down",) or ("up", "down"); the first axis of every per-point array.
    amplitude, rms : (d, n, N) ndarray
        max abs(u) and the RMS of u per DOF over the recorded periods, m.
    kind : (d, n) ndarray of str
        "periodic", "period-k", "quasi-periodic", "chaotic" or "unsettled".
    period : (d, n) ndarray of int
        k of a periodic (1) or period-k orbit; 0 otherwise.
    lyapunov, lyapunov_error : (d, n) ndarray
        Largest Lyapunov exponent and its standard error, 1/s.
    poincare : (d, n, r, 2N) ndarray
        (u, v) at forcing phase 0 at each recorded period, m and m/s.
    events : (d, n) ndarray of int
        Gap-edge events over the recorded periods.
    jumps : list of dict
        Each: direction, from_hz, to_hz, from_amplitude_m, to_amplitude_m (largest DOF).
    settle_periods, record_periods : int
    chunk_starts : tuple of tuple of int
        Per direction, the indices (into that direction's stepping order) where a run
        starts from rest (only 0 without a runner).
    force : (N,) ndarray
        N.
    dof_names : tuple of str
    """

    omega: FloatArray
    directions: tuple[str, ...]
    amplitude: FloatArray = field(repr=False)
    rms: FloatArray = field(repr=False)
    kind: NDArray[np.str_] = field(repr=False)
    period: NDArray[np.int64] = field(repr=False)
    lyapunov: FloatArray = field(repr=False)
    lyapunov_error: FloatArray = field(repr=False)
    poincare: FloatArray = field(repr=False)
    events: NDArray[np.int64] = field(repr=False)
    jumps: list[dict[str, Any]] = field(repr=False)
    settle_periods: int = 0
    record_periods: int = 0
    chunk_starts: tuple[tuple[int, ...], ...] = field(repr=False, default=())
    force: FloatArray = field(repr=False, default_factory=lambda: np.zeros(0))
    dof_names: tuple[str, ...] = field(repr=False, default=())

    def __repr__(self) -> str:
        f = self.omega / (2 * math.pi)
        counts = ", ".join(
            f"{int(np.sum(self.kind == k))} {k}" for k in KINDS if np.any(self.kind == k)
        )
        return (
            f"SteppedSine({self.omega.size} frequencies {f[0]:.4g}-{f[-1]:.4g} Hz, "
            f"{'+'.join(self.directions)}, {counts}, {len(self.jumps)} jumps)"
        )

    def plot(
        self,
        ax: Any = None,
        *,
        dof: int | str | None = None,
        curves: Any = (),
    ) -> Any:
        """The bifurcation diagram: Poincaré samples of ``dof`` against frequency, by kind.

        Each frequency shows its recorded states at forcing phase 0; a periodic or
        period-k one only its last k (settled: its verdict is the orbit Newton closed
        from them). Curves drawn over it show their orbits' state at phase 0 too
        (``initial_state``), so a stable orbit of a curve and a periodic point meet.

        Parameters
        ----------
        ax : matplotlib Axes, optional
        dof : int or str, optional
            A DOF index or name; default the DOF that moves most.
        curves : sequence of FrequencyResponse
            Curves to draw over it (harmonic balance, shooting), stable solid, unstable
            dashed.

        Returns
        -------
        matplotlib.axes.Axes
        """
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(7.0, 4.2))
        k = self._dof_index(dof)
        colours = {
            "periodic": "C0",
            "period-k": "C2",
            "quasi-periodic": "C1",
            "chaotic": "C3",
            "unsettled": "0.6",
        }
        markers = {"up": ".", "down": "x"}
        f = self.omega / (2 * math.pi)
        r = self.poincare.shape[2]
        for d, name in enumerate(self.directions):
            for kind, colour in colours.items():
                chosen = np.flatnonzero(self.kind[d] == kind)
                if not chosen.size:
                    continue
                xs: list[float] = []
                ys: list[float] = []
                for i in chosen:
                    keep = int(self.period[d, i]) if self.period[d, i] > 0 else r
                    xs += [float(f[i])] * keep
                    ys += (1e3 * self.poincare[d, i, r - keep :, k]).tolist()
                label = f"{kind} ({name})" if len(self.directions) > 1 else kind
                ax.plot(
                    xs,
                    ys,
                    markers[name],
                    color=colour,
                    ms=2.0 if name == "up" else 3.0,
                    alpha=0.6,
                    ls="none",
                    label=label,
                )
        for j, curve in enumerate(curves):
            state = np.asarray(curve.initial_state)
            column = state[:, k]
            cf = curve.omega / (2 * math.pi)
            stable = np.asarray(curve.stable, dtype=bool)
            tag = getattr(curve, "method", "curve")
            colour = f"C{4 + j}"
            ax.plot(
                cf,
                1e3 * np.where(stable, column, np.nan),
                "-",
                color=colour,
                lw=1.2,
                label=f"{tag} {j + 1}: stable",
            )
            ax.plot(
                cf,
                1e3 * np.where(stable, np.nan, column),
                "--",
                color=colour,
                lw=0.8,
                label=f"{tag} {j + 1}: unstable",
            )
        name = self.dof_names[k] if self.dof_names else f"DOF {k}"
        margin = 0.02 * float(f[-1] - f[0]) if f.size > 1 else 0.5
        ax.set_xlim(float(f[0]) - margin, float(f[-1]) + margin)  # curves may run past
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel(f"{name} at forcing phase 0 (mm)")
        ax.legend(frameon=False, fontsize="x-small", markerscale=3, ncol=2)
        return ax

    def _dof_index(self, dof: int | str | None) -> int:
        if dof is None:
            return int(np.argmax(np.max(self.amplitude, axis=(0, 1))))
        if isinstance(dof, str):
            if dof not in self.dof_names:
                raise ParameterError(f"no DOF named {dof!r}; the DOFs are {list(self.dof_names)}")
            return self.dof_names.index(dof)
        n = self.amplitude.shape[2]
        if not 0 <= int(dof) < n:
            raise ParameterError(f"dof must be in 0..{n - 1}, got {dof!r}")
        return int(dof)

    def to_xarray(self) -> Any:
        """The diagram as an xarray Dataset (direction, frequency, dof, record), units in attrs."""
        import xarray as xr

        n = self.amplitude.shape[2]
        names = list(self.dof_names) or [f"u{k + 1}" for k in range(n)]
        state = [f"u[{x}]" for x in names] + [f"v[{x}]" for x in names]
        dims = ("direction", "frequency")
        ds = xr.Dataset(
            {
                "amplitude": ((*dims, "dof"), self.amplitude, {"units": "m"}),
                "rms": ((*dims, "dof"), self.rms, {"units": "m"}),
                "kind": (dims, self.kind.astype(str), {"values": ", ".join(KINDS)}),
                "period": (dims, self.period, {"units": "forcing periods (0: none)"}),
                "lyapunov": (dims, self.lyapunov, {"units": "1/s"}),
                "lyapunov_error": (dims, self.lyapunov_error, {"units": "1/s"}),
                "events": (dims, self.events, {"units": "gap-edge events, recorded periods"}),
                "poincare": (
                    (*dims, "record", "state"),
                    self.poincare,
                    {"units": "m (u), m/s (v)", "meaning": "state at forcing phase 0"},
                ),
            },
            coords={
                "direction": list(self.directions),
                "frequency": ("frequency", self.omega / (2 * math.pi), {"units": "Hz"}),
                "dof": names,
                "state": state,
                "record": np.arange(self.poincare.shape[2]),
            },
            attrs={
                "title": "clearjoint stepped sine (exact motion)",
                "settle_periods": self.settle_periods,
                "record_periods": self.record_periods,
                "force_N": ", ".join(f"{x:g}" for x in self.force),
                "jumps": "; ".join(
                    f"{j['direction']}: {j['from_hz']:.4g} -> {j['to_hz']:.4g} Hz, "
                    f"{1e3 * j['from_amplitude_m']:.4g} -> {1e3 * j['to_amplitude_m']:.4g} mm"
                    for j in self.jumps
                ),
            },
        )
        return ds


def _whole(name: str, value: Any, least: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < least:
        raise SteppedSineError(f"{name} must be an integer >= {least}, got {value!r}")
    return int(value)


def _frequencies(omegas: ArrayLike) -> FloatArray:
    try:
        w = np.asarray(omegas, dtype=np.float64)
    except (TypeError, ValueError):
        raise SteppedSineError(
            f"omegas must be a sequence of frequencies in rad/s, got {omegas!r}"
        ) from None
    if w.ndim != 1 or w.size < 1:
        raise SteppedSineError("omegas must be a 1-D sequence of at least one frequency (rad/s)")
    if not np.all(np.isfinite(w)) or np.any(w <= 0.0):
        bad = w[~(np.isfinite(w) & (w > 0.0))][0]
        raise SteppedSineError(f"every frequency must be finite and > 0 rad/s, got {bad!r}")
    if np.any(np.diff(w) <= 0.0):
        i = int(np.flatnonzero(np.diff(w) <= 0.0)[0])
        raise SteppedSineError(
            f"omegas must be strictly increasing (omegas[{i + 1}] = {w[i + 1]!r} follows "
            f"{w[i]!r}); give them in increasing order and choose the sweep with direction="
        )
    return w


def _jumps(
    omega: FloatArray, directions: tuple[str, ...], amplitude: FloatArray
) -> list[dict[str, Any]]:
    """Steps where the largest amplitude changes by more than ``JUMP_RATIO``; with both
    directions, only those where the two sweeps disagree at one end of the step (by more
    than ``JUMP_RATIO``): the hysteresis of a jump, not a steep slope of one branch."""
    out: list[dict[str, Any]] = []
    f = omega / (2 * math.pi)
    top = np.max(amplitude, axis=2)  # (d, n)
    both = len(directions) == 2
    if both:
        low, high = np.minimum(top[0], top[1]), np.maximum(top[0], top[1])
        apart = high > JUMP_RATIO * np.maximum(low, 1e-300)
    for d, name in enumerate(directions):
        order = np.arange(f.size) if name == "up" else np.arange(f.size)[::-1]
        for a, b in itertools.pairwise(order):
            small, large = sorted((float(top[d, a]), float(top[d, b])))
            if large <= JUMP_RATIO * max(small, 1e-300):
                continue
            if both and not (apart[a] or apart[b]):
                continue
            out.append(
                {
                    "direction": name,
                    "from_hz": float(f[a]),
                    "to_hz": float(f[b]),
                    "from_amplitude_m": float(top[d, a]),
                    "to_amplitude_m": float(top[d, b]),
                }
            )
    return out


def stepped_sine(
    structure: Any,
    force: ArrayLike,
    omegas: ArrayLike,
    *,
    direction: Literal["up", "down", "both"] = "up",
    settle_periods: int = 200,
    record_periods: int = 100,
    runner: Any = None,
    chunks: int | None = None,
) -> SteppedSine:
    """Run a stepped-sine test of ``structure`` exactly (module docstring).

    Parameters
    ----------
    structure : Structure or VibrationSystem
        Lumped mass; joints without friction; a restitution in (0, 1] (each impact's
        saltation matrix enters the tangent flow).
    force : (N,) array_like
        Force amplitude per DOF, N.
    omegas : (n,) array_like
        The frequencies, rad/s, > 0 and strictly increasing (``direction`` says which
        way they are stepped).
    direction : {"up", "down", "both"}
    settle_periods, record_periods : int
        Forcing periods to settle (>= 1) and to record (>= 1; the kind needs >= 4).
    runner : executor or dask.distributed.Client, optional
        Run contiguous chunks of frequencies in parallel (module docstring).
    chunks : int, optional
        Runs per direction with a runner (default 8, at most one per frequency).

    Returns
    -------
    SteppedSine

    Raises
    ------
    SteppedSineError
        Frequencies not positive or not increasing, periods below 1, a bad direction.
    StructureError
        A force vector of the wrong length, friction, a restitution of 0.
    """
    system = _system(structure)
    f = _vector("force", force, system)
    w = _frequencies(omegas)
    if direction not in ("up", "down", "both"):
        raise SteppedSineError(f"direction must be 'up', 'down' or 'both', got {direction!r}")
    settle = _whole("settle_periods", settle_periods, 1)
    record = _whole("record_periods", record_periods, 1)
    refuse_restitution(system, below=0.0)  # before any work: e = 0 has no saltation
    names: tuple[str, ...] = ("up", "down") if direction == "both" else (direction,)
    n_runs = 1 if runner is None else _whole("chunks", 8 if chunks is None else chunks, 1)
    n_runs = min(n_runs, w.size)
    bounds = np.linspace(0, w.size, n_runs + 1).round().astype(int)
    tasks: list[_Chunk] = []
    starts: list[tuple[int, ...]] = []
    total = len(names) * w.size
    for d, name in enumerate(names):
        order = w if name == "up" else w[::-1]
        starts.append(tuple(int(b) for b in bounds[:-1]))
        for a, b in itertools.pairwise(bounds):
            chunk = _Chunk(system, f, order[a:b].copy(), settle, record, 2 * settle)
            tasks.append(dataclasses.replace(chunk, done_before=d * w.size + a, total=total))
    sizes = [task.omegas.size for task in tasks]

    def chunks_done(done: int, _: int) -> None:  # with a runner: whole chunks
        report(sum(sorted(sizes)[:done]), total)

    try:
        results = run_ordered(_run_chunk, tasks, runner, progress=chunks_done)
    except (SimulationError, OrbitError) as exc:
        raise SimulationError(f"stepped sine: {exc}") from None
    per_dir: list[list[_Point]] = []
    for d in range(len(names)):
        points = [p for chunk in results[d * n_runs : (d + 1) * n_runs] for p in chunk]
        per_dir.append(points if names[d] == "up" else points[::-1])

    def stack(attr: str) -> Any:
        return np.array([[getattr(p, attr) for p in points] for points in per_dir])

    amplitude = stack("amplitude")
    return SteppedSine(
        omega=w,
        directions=names,
        amplitude=amplitude,
        rms=stack("rms"),
        kind=stack("kind").astype(str),
        period=stack("period").astype(np.int64),
        lyapunov=stack("lyapunov"),
        lyapunov_error=stack("lyapunov_error"),
        poincare=stack("poincare"),
        events=stack("events").astype(np.int64),
        jumps=_jumps(w, names, amplitude),
        settle_periods=settle,
        record_periods=record,
        chunk_starts=tuple(starts),
        force=f,
        dof_names=system.dof_names,
    )
