"""A sweep file: the base study, the task, grid axes and Monte Carlo draws, with units.

The format (docs/sweep.md; an example in examples/sweep.toml)::

    base = "study.toml"          # a study, a structure study, a rig campaign or a glob of
                                 # records; relative to this file
    seed = 2026                  # the draws and every point's own seed
    samples = 200                # Monte Carlo samples (the `sample` dimension)
    chunk_size = 16              # points per task chunk and per zarr chunk

    [task]
    name = "steady_state"        # clearjoint.sweep.TASKS
    outputs = ["amplitude_m"]    # default: every output of the task
    # and the task's options, e.g. amplitude = "5um" for "energies"

    [axes.joint]                 # a grid axis: a list, or start/stop/num (spacing linear or log)
    clearance = ["0.05mm", "0.1mm", "0.2mm"]
    [axes.excitation]
    force_amplitude = { start = "200N", stop = "2kN", num = 10 }

    [draws.joint.clearance]      # a Monte Carlo draw per sample
    distribution = "normal"      # normal (mean, std), uniform (low, high), lognormal
    mean = "0.1mm"               #   (median, sigma: the spread of ln x)
    std = "0.02mm"
    lower = "0mm"                # truncate below (and/or upper = ...)
    per_joint = true             # structure tasks: one draw per joint per sample

Dimensional values need a unit (``"0.1mm"``; a bare number only for zero or a
dimensionless key), read by clearjoint.io_toml as in study files; unknown keys are
refused. A normal draw that falls outside a parameter's range (a negative clearance)
is refused unless the distribution is truncated there with ``lower``/``upper``: the
truncated normal is then drawn exactly (by its inverse CDF), never clipped.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import special

from clearjoint.errors import ClearjointError
from clearjoint.io_toml import quantity, read_toml
from clearjoint.sweep.tasks import TASKS, Parameter, Task

__all__ = [
    "Axis",
    "Draw",
    "Sweep",
    "SweepError",
]

FloatArray = NDArray[np.float64]

_TOP_KEYS = ("base", "seed", "samples", "chunk_size", "task", "axes", "draws")
_DISTRIBUTIONS = {
    "normal": ("mean", "std"),
    "uniform": ("low", "high"),
    "lognormal": ("median", "sigma"),
}


class SweepError(ClearjointError, ValueError):
    """A sweep file is missing, unreadable or holds a bad value; the message names the key."""


@dataclass(frozen=True)
class Axis:
    """A grid axis: the parameter's name (``joint.clearance``), its values (SI, Hz) and unit."""

    name: str
    values: tuple[float, ...]
    unit: str


@dataclass(frozen=True)
class Draw:
    """A Monte Carlo draw of one parameter per sample.

    ``first``, ``second`` are (mean, std), (low, high) or (median, sigma) by
    ``distribution``; ``lower``/``upper`` truncate it (None: not truncated);
    ``per_joint`` > 0 draws that many independent values per sample (one per joint
    of a structure study), else one.
    """

    name: str
    distribution: str
    first: float
    second: float
    lower: float | None
    upper: float | None
    unit: str
    per_joint: int = 0  # > 0: that many independent values per sample, one per joint

    def sample(self, rng: np.random.Generator, n: int) -> FloatArray:
        """Return ``n`` draws: shape (n,), or (n, per_joint) for a per-joint draw."""
        if self.per_joint:
            flat = replace(self, per_joint=0).sample(rng, n * self.per_joint)
            return flat.reshape(n, self.per_joint)
        if self.distribution == "uniform":
            return rng.uniform(self.first, self.second, n)
        if self.distribution == "lognormal":
            return self.first * np.exp(self.second * rng.standard_normal(n))
        lo = -math.inf if self.lower is None else (self.lower - self.first) / self.second
        hi = math.inf if self.upper is None else (self.upper - self.first) / self.second
        if self.lower is None and self.upper is None:
            return self.first + self.second * rng.standard_normal(n)
        u = rng.uniform(special.ndtr(lo), special.ndtr(hi), n)
        return np.asarray(self.first + self.second * special.ndtri(u), dtype=np.float64)


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep: the task at every point of the grid x samples (SI, frequencies in Hz).

    Points run in C order over (``sample``, axis 1, axis 2, ...); ``fixed`` holds the
    task's options; ``fingerprint`` identifies the sweep in its result store.
    """

    task: Task
    base: Any
    fixed: tuple[tuple[str, float], ...]
    axes: tuple[Axis, ...]
    draws: tuple[Draw, ...]
    samples: int
    seed: int
    outputs: tuple[str, ...]
    chunk_size: int
    source: str

    def __repr__(self) -> str:
        dims = ", ".join(
            f"{name}: {size}" for name, size in zip(self.dims, self.shape, strict=True)
        )
        return (
            f"Sweep({self.task.name!r}, {self.n_points} points ({dims}), "
            f"{len(self.outputs)} outputs, source={self.source!r})"
        )

    @classmethod
    def from_toml(cls, path: str | Path) -> Sweep:
        """Read a sweep file (see the module docstring).

        Raises
        ------
        SweepError
            The file or its base is missing or unreadable, a key is unknown, an axis
            has no values, or a draw leaves a parameter's valid range untruncated.
        """
        return _read(Path(path))

    @property
    def dims(self) -> tuple[str, ...]:
        """The dimension names: ``sample`` (with samples) then each axis's name."""
        return (("sample",) if self.samples else ()) + tuple(a.name for a in self.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        """The size of each dimension."""
        return ((self.samples,) if self.samples else ()) + tuple(len(a.values) for a in self.axes)

    @property
    def n_points(self) -> int:
        """The number of points: the product of :attr:`shape`."""
        return math.prod(self.shape)

    def drawn(self) -> dict[str, FloatArray]:
        """Each drawn parameter's values, from ``default_rng(SeedSequence(seed))``.

        Shape (samples,), or (samples, n_joints) for a per-joint draw.

        Draws are made in file order, each parameter's samples at once, so they do not
        depend on chunking or workers; points' own seeds are ``point_seed(seed, index)``.
        """
        rng = np.random.default_rng(np.random.SeedSequence(self.seed))
        return {d.name: d.sample(rng, self.samples) for d in self.draws}

    @property
    def fingerprint(self) -> str:
        """A sha256 of every value that shapes the results (not the file's path)."""
        base = self.base
        if hasattr(base, "structure"):  # its repr is a summary: take every value instead
            s = base.structure
            base = (
                s.nodes.tolist(),
                s.masses.tolist(),
                s.members,
                s.supports,
                s.rayleigh,
                base.omega,
                None if base.force is None else base.force.tolist(),
            )
        elif hasattr(base, "source"):
            base = replace(base, source="")
        text = repr(
            (
                "clearjoint sweep 1",
                self.task.name,
                base,
                self.fixed,
                self.axes,
                self.draws,
                self.samples,
                self.seed,
                self.outputs,
                self.chunk_size,
            )
        )
        return hashlib.sha256(text.encode("utf-8")).hexdigest()


# ---- reading ---------------------------------------------------------------------------------


def _quantity(where: str, key: str, raw: Any, parameter: Parameter) -> float:
    """One value in SI, read as every clearjoint file reads it (clearjoint.io_toml)."""
    name = f"{where}: {key}"
    return float(quantity(raw, parameter.kind, name=name, error=SweepError, unit_keys=False))


def _check_range(where: str, key: str, values: FloatArray, p: Parameter, hint: str) -> None:
    low = values < p.lower if not p.open_lower else values <= p.lower
    bad = int(np.count_nonzero(low | (values > p.upper) | np.isnan(values)))
    if bad:
        edge = f"> {p.lower:g}" if p.open_lower else f">= {p.lower:g}"
        valid = edge + (f" and <= {p.upper:g}" if math.isfinite(p.upper) else "")
        raise SweepError(
            f"{where}: {key}: {bad} of {values.size} values lie outside its range "
            f"({valid} {p.unit}); {hint}"
        )


def _table(where: str, raw: Any, name: str) -> dict[str, Any]:
    if not isinstance(raw, dict):
        raise SweepError(f"{where}: [{name}] must be a table")
    return raw


def _parameter(where: str, task: Task, name: str) -> Parameter:
    if name in task.parameters:
        return task.parameters[name]
    if name in task.options:
        return task.options[name][1]
    known = sorted([*task.parameters, *task.options])
    raise SweepError(f"{where}: task {task.name!r} has no parameter {name!r}; known: {known}")


def _read_axis(where: str, name: str, raw: Any, p: Parameter) -> Axis:
    key = f"[axes] {name}"
    if isinstance(raw, list):
        values = [_quantity(where, key, v, p) for v in raw]
    elif isinstance(raw, dict):
        extra = sorted(set(raw) - {"start", "stop", "num", "spacing"})
        if extra or not {"start", "stop", "num"} <= set(raw):
            raise SweepError(
                f"{where}: {key} takes start, stop, num and spacing (linear or log); "
                f"got {sorted(raw)}"
            )
        num = raw["num"]
        if isinstance(num, bool) or not isinstance(num, int):
            raise SweepError(f"{where}: {key} num must be a whole number, got {num!r}")
        start = _quantity(where, key, raw["start"], p)
        stop = _quantity(where, key, raw["stop"], p)
        if num > 1 and start == stop:
            raise SweepError(
                f"{where}: {key} start and stop are equal ({start:g} {p.unit}), so its "
                f"{num} points would all be the same; give a wider range, or num = 1"
            )
        spacing = raw.get("spacing", "linear")
        if spacing == "log":
            if start <= 0 or stop <= 0:
                raise SweepError(f"{where}: {key} log spacing needs start and stop > 0")
            values = list(np.geomspace(start, stop, max(num, 0)))
        elif spacing == "linear":
            values = list(np.linspace(start, stop, max(num, 0)))
        else:
            raise SweepError(f"{where}: {key} spacing must be 'linear' or 'log', got {spacing!r}")
    else:
        raise SweepError(f"{where}: {key} must be a list of values or a start/stop/num table")
    if not values:
        raise SweepError(f"{where}: {key} has no values; give at least one")
    array = np.asarray(values, dtype=np.float64)
    if np.unique(array).size < array.size:
        raise SweepError(
            f"{where}: {key} repeats a value (points that would all be the same); "
            "give each value once"
        )
    _check_range(where, key, array, p, "change the axis")
    return Axis(name, tuple(float(v) for v in array), p.unit)


def _read_draw(
    where: str, name: str, raw: dict[str, Any], p: Parameter, joints: int | None
) -> Draw:
    """One [draws.X] table; ``joints``: the base structure's joint count (None: not one)."""
    key = f"[draws.{name}]"
    raw = dict(raw)
    per_joint = raw.pop("per_joint", False)
    if not isinstance(per_joint, bool):
        raise SweepError(f"{where}: {key} per_joint must be true or false, got {per_joint!r}")
    if per_joint and joints is None:
        raise SweepError(
            f"{where}: {key} per_joint = true needs a structure task (its joints); "
            "remove it for a single joint"
        )
    if per_joint and not joints:
        raise SweepError(f"{where}: {key} per_joint = true, but the base structure has no joints")
    kind = raw.get("distribution")
    if kind not in _DISTRIBUTIONS:
        raise SweepError(
            f"{where}: {key} distribution must be one of {sorted(_DISTRIBUTIONS)}, got {kind!r}"
        )
    first_key, second_key = _DISTRIBUTIONS[kind]
    allowed = {"distribution", first_key, second_key} | (
        {"lower", "upper"} if kind == "normal" else set()
    )
    shown = sorted(allowed | ({"per_joint"} if joints is not None else set()))
    extra = sorted(set(raw) - allowed)
    missing = sorted({first_key, second_key} - set(raw))
    if extra or missing:
        raise SweepError(
            f"{where}: {key} ({kind}) takes {shown}; unknown {extra}, missing {missing}"
        )
    first = _quantity(where, f"{key} {first_key}", raw[first_key], p)
    spread = Parameter("dimensionless", "") if kind == "lognormal" else replace(p, lower=0.0)
    second = _quantity(where, f"{key} {second_key}", raw[second_key], spread)
    bounds = [
        _quantity(where, f"{key} {edge}", raw[edge], replace(p, lower=-math.inf))
        if edge in raw
        else None
        for edge in ("lower", "upper")
    ]
    if kind == "normal" and not second > 0:
        raise SweepError(f"{where}: {key} std must be > 0, got {second!r}")
    if kind == "uniform" and not second > first:
        raise SweepError(f"{where}: {key} needs high > low, got {first!r} and {second!r}")
    if kind == "lognormal" and not (first > 0 and second > 0):
        raise SweepError(f"{where}: {key} needs median > 0 and sigma > 0")
    lo, hi = bounds
    if lo is not None and hi is not None and not hi > lo:
        raise SweepError(f"{where}: {key} needs upper > lower")
    return Draw(name, kind, first, second, lo, hi, p.unit, joints if per_joint and joints else 0)


def _load_base(where: str, task: Task, raw: Any, folder: Path) -> Any:
    if task.base == "campaign":
        from clearjoint.rig import CampaignError, load_campaign

        try:
            return load_campaign(None if raw is None else folder / str(raw))
        except CampaignError as exc:
            raise SweepError(f"{where}: base: {exc}") from None
    if task.base == "study":
        from clearjoint.simulate.study import StudyError, load_study

        if not isinstance(raw, str):
            raise SweepError(f'{where}: base must name a study file, e.g. base = "study.toml"')
        try:
            return load_study(folder / raw)
        except StudyError as exc:
            raise SweepError(f"{where}: base: {exc}") from None
    if task.base == "records":
        from clearjoint.sweep.tasks import RecordSet

        if not isinstance(raw, str):
            raise SweepError(f'{where}: base must be a glob of record files, e.g. "records/*.nc"')
        pattern = Path(raw)
        if not pattern.is_absolute():
            pattern = folder / pattern
        files = sorted(str(p) for p in pattern.parent.glob(pattern.name) if p.is_file())
        if not files:
            raise SweepError(f"{where}: base {raw!r} matches no file; check the folder and pattern")
        return RecordSet(tuple(files), source=raw)
    if task.base == "structure":
        from clearjoint.structure.model import Structure
        from clearjoint.structure.study import StructureStudyError, load_structure_study

        if not isinstance(raw, str):
            raise SweepError(
                f'{where}: base must name a structure study file, e.g. base = "mast.toml"'
            )
        try:
            study = load_structure_study(folder / raw)
        except StructureStudyError as exc:
            raise SweepError(f"{where}: base: {exc}") from None
        if not isinstance(study.structure, Structure):
            raise SweepError(
                f"{where}: base {raw!r} is a [model] (matrix files); a sweep takes a "
                "[structure] study"
            )
        if not study.structure.joint_members:
            raise SweepError(
                f"{where}: base {raw!r} has no clearance joints; add a [joint] section to it"
            )
        return study
    raise SweepError(f"{where}: task {task.name!r} needs a {task.base} base, not readable yet")


def _read(path: Path) -> Sweep:
    where = str(path)
    raw = read_toml(path, what="sweep", error=SweepError)
    extra = sorted(set(raw) - set(_TOP_KEYS))
    if extra:
        raise SweepError(f"{where}: unknown key(s) {extra}; known: {sorted(_TOP_KEYS)}")
    task_t = dict(_table(where, raw.get("task"), "task"))
    name = task_t.pop("name", None)
    if name not in TASKS:
        raise SweepError(f"{where}: [task] name must be one of {sorted(TASKS)}, got {name!r}")
    task = TASKS[name]
    outputs = task_t.pop("outputs", list(task.outputs))
    if not isinstance(outputs, list) or not outputs:
        raise SweepError(f"{where}: [task] outputs must be a non-empty list of names")
    unknown = sorted(set(outputs) - set(task.outputs))
    if unknown:
        raise SweepError(
            f"{where}: [task] outputs {unknown} are not outputs of {name!r}; "
            f"known: {list(task.outputs)}"
        )
    base = _load_base(where, task, raw.get("base"), path.parent)

    axes: list[Axis] = []
    if task.base == "records":  # one point per record file
        axes.append(Axis("record", tuple(float(i) for i in range(len(base.files))), ""))
    for section, table in _table(where, raw.get("axes", {}), "axes").items():
        for key, value in _table(where, table, f"axes.{section}").items():
            p = _parameter(where, task, f"{section}.{key}")
            axes.append(_read_axis(where, f"{section}.{key}", value, p))
    draws: list[Draw] = []
    for section, table in _table(where, raw.get("draws", {}), "draws").items():
        for key, value in _table(where, table, f"draws.{section}").items():
            p = _parameter(where, task, f"{section}.{key}")
            joints = len(base.structure.joint_members) if task.base == "structure" else None
            table = _table(where, value, key)
            draws.append(_read_draw(where, f"{section}.{key}", table, p, joints))
    varied = {a.name for a in axes}
    both = sorted(varied & {d.name for d in draws})
    if both:
        raise SweepError(f"{where}: {both} are both an axis and a draw; keep one")
    varied |= {d.name for d in draws}

    fixed: dict[str, float] = {}
    for key, value in task_t.items():
        full = f"task.{key}"
        if full not in task.options:
            known = ["name", "outputs", *(k.split(".", 1)[1] for k in task.options)]
            raise SweepError(f"{where}: unknown key {key!r} in [task]; known: {known}")
        fixed[full] = _quantity(where, f"[task] {key}", value, task.options[full][1])
        _check_range(
            where, f"[task] {key}", np.array([fixed[full]]), task.options[full][1], "change it"
        )
    for full, (default, parameter) in task.options.items():
        if full in fixed or full in varied:
            continue
        if default is None:
            raise SweepError(
                f"{where}: task {name!r} needs {full.split('.', 1)[1]} in [task] "
                f'or an [axes.task] axis, e.g. {full.split(".", 1)[1]} = "5{parameter.unit}"'
            )
        fixed[full] = default

    start, stop = fixed.get("task.frequency_start"), fixed.get("task.frequency_stop")
    if start is not None and stop is not None and not stop > start:
        raise SweepError(
            f"{where}: [task] frequency_stop ({stop:g} Hz) must exceed frequency_start "
            f"({start:g} Hz)"
        )

    samples = _count(where, raw, "samples", 0)
    if draws and samples < 1:
        raise SweepError(f"{where}: [draws] need samples = N (N >= 1) at the top of the file")
    sweep = Sweep(
        task=task,
        base=base,
        fixed=tuple(sorted(fixed.items())),
        axes=tuple(axes),
        draws=tuple(draws),
        samples=samples,
        seed=_count(where, raw, "seed", 0),
        outputs=tuple(outputs),
        chunk_size=_count(where, raw, "chunk_size", 16),
        source=where,
    )
    if sweep.chunk_size < 1:
        raise SweepError(f"{where}: chunk_size must be >= 1, got {sweep.chunk_size}")
    if sweep.n_points == 0 or not sweep.shape:
        raise SweepError(f"{where}: the sweep has no points; give [axes] or samples")
    for draw, values in zip(sweep.draws, sweep.drawn().values(), strict=True):
        _check_range(
            where,
            f"[draws.{draw.name}]",
            values,
            _parameter(where, task, draw.name),
            "truncate the normal with lower = ... (and/or upper = ...), or narrow it",
        )
    return sweep


def _count(where: str, raw: dict[str, Any], key: str, default: int) -> int:
    value = raw.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise SweepError(f"{where}: {key} must be a whole number >= 0, got {value!r}")
    return value
