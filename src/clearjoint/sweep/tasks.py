"""What a sweep computes at each point: the task registry and the joint tasks.

A :class:`Task` names its base (a ``study`` file of ``clearjoint simulate``, a
``structure`` study of ``clearjoint structure``, a rig ``campaign`` or ``records``), the
parameters a sweep may vary or fix, its outputs with their units, and ``evaluate(base,
values, seed)``: a pure, module-level function of frozen values that returns one float
per output (it runs on Dask workers). The physics is the library's; this module only
maps a point's values onto it:

* ``steady_state``: the exact steady cycle of the forced joint (clearjoint.simulate,
  MODEL.md sec. 2): amplitude, extremes, penetrations and the energy ledger per period;
* ``energies``: every energy per free cycle at penetration ``task.amplitude``
  (clearjoint.dissipation.energies, MODEL.md eq 10-18);
* ``free_cycle``: the joint's amplitude-dependent natural frequency, dynamic stiffness,
  c_d (MODEL.md eq 5-9) and equivalent damping ratio on the free cycle at ``task.amplitude``;
* ``stepped_sine``: the frequency-response curve by a stepped sine up and down
  (clearjoint.simulate.frequency_sweep), reduced to its peak and its up/down jump;
* ``identify``: the identification of each record of a set (base: a glob of files),
  one point per file along the ``record`` axis;
* ``rig_test``: one test of the virtual rig (clearjoint.rig), measured with the
  point's own noise seed, then identified (clearjoint.identify): truth beside estimate;
* ``periodic_orbit``: one exact periodic orbit, stable or unstable, by Newton on the
  exact map (clearjoint.periodic, MODEL.md 5.1), with its Floquet stability;
* ``frequency_response``: the whole curve of exact periodic orbits by continuation
  (clearjoint.periodic, MODEL.md 5.1), reduced to its peak, folds and unstable points; a
  curve the continuation cut short is a failed point (NaN, with where and why);
* ``nonlinear_mode``: the joint's first nonlinear mode at one modal amplitude by harmonic
  balance (clearjoint.harmonic, MODEL.md 5.4): frequency, damping ratio, energy per cycle;
* ``structure_mode``: a nonlinear mode of a structure study (a mast with a clearance
  joint in every longeron, MODEL.md 5.2 and 5.4) at one modal amplitude: frequency and
  damping ratio. Its joints may be varied all at once (``joint.clearance``) or one by
  one (``joint.clearance[3]``, what a per-joint draw gives each point).

Other tasks register themselves the same way with :func:`register_task`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from clearjoint.dissipation import ENERGY_KEYS
from clearjoint.errors import ParameterError
from clearjoint.identify import QUANTITIES
from clearjoint.studies.overrides import structure_at, study_at
from clearjoint.units import unit_of_name

__all__ = [
    "FORCING_PARAMETERS",
    "JOINT_PARAMETERS",
    "STRUCTURE_JOINT_PARAMETERS",
    "TASKS",
    "Parameter",
    "RecordSet",
    "Task",
    "register_task",
    "structure_at",
    "study_at",
]


@dataclass(frozen=True)
class Parameter:
    """A value a sweep may vary: its kind of quantity, SI unit (as shown) and valid range."""

    kind: str
    unit: str
    lower: float = 0.0
    upper: float = math.inf
    open_lower: bool = False  # True: the value must be > lower (a mass), not >= lower


@dataclass(frozen=True)
class Task:
    """One kind of computation a sweep can run at each point (see the module docstring).

    ``options`` are task parameters with a default (None: must be given in [task] or
    as an axis); ``evaluate(base, values, seed)`` gets every parameter the sweep names
    plus every option, in SI (frequencies in Hz), and returns one float per output.
    """

    name: str
    base: str
    parameters: Mapping[str, Parameter]
    options: Mapping[str, tuple[float | None, Parameter]]
    outputs: Mapping[str, str]
    evaluate: Callable[[Any, Mapping[str, float], np.random.SeedSequence], Mapping[str, float]]
    description: str


#: Every task a sweep file may name, by name.
TASKS: dict[str, Task] = {}


def register_task(task: Task) -> None:
    """Add ``task`` to :data:`TASKS` (a name is registered once)."""
    if task.name in TASKS and TASKS[task.name] is not task:
        raise ParameterError(f"a sweep task named {task.name!r} is already registered")
    TASKS[task.name] = task


Evaluate = Callable[[Any, Mapping[str, float], np.random.SeedSequence], dict[str, float]]


def _task(
    name: str,
    base: str,
    parameters: Mapping[str, Parameter],
    options: Mapping[str, tuple[float | None, Parameter]],
    outputs: Mapping[str, str],
    description: str,
) -> Callable[[Evaluate], Evaluate]:
    """Register the decorated ``evaluate`` as the task ``name`` (see :class:`Task`)."""

    def register(evaluate: Evaluate) -> Evaluate:
        register_task(Task(name, base, parameters, options, outputs, evaluate, description))
        return evaluate

    return register


def _outputs(*names: str) -> dict[str, str]:
    """Each output name with its unit, read from the name's ending (units.unit_of_name)."""
    return {name: unit_of_name(name) for name in names}


def _count(lower: float) -> Parameter:
    """A whole-number option (a count of steps, periods, harmonics) of at least ``lower``."""
    return Parameter("dimensionless", "", lower=lower)


# ---- the joint of a study file ---------------------------------------------------------------

_POSITIVE = {"open_lower": True}
JOINT_PARAMETERS: dict[str, Parameter] = {
    "joint.mass": Parameter("mass", "kg", **_POSITIVE),
    "joint.clearance": Parameter("length", "m"),
    "joint.compression_stiffness": Parameter("stiffness", "N/m", **_POSITIVE),
    "joint.tension_stiffness": Parameter("stiffness", "N/m", **_POSITIVE),
    "joint.gap_stiffness": Parameter("stiffness", "N/m"),
    "joint.gap_offset": Parameter("length", "m", lower=-math.inf),
    "losses.damping_ratio": Parameter("dimensionless", ""),
    "losses.restitution": Parameter("dimensionless", "", upper=1.0),
    "losses.friction_coefficient": Parameter("dimensionless", ""),
    "losses.lateral_load": Parameter("force", "N"),
    "losses.contact_friction_coefficient": Parameter("dimensionless", ""),
}
FORCING_PARAMETERS: dict[str, Parameter] = {
    "excitation.force_amplitude": Parameter("force", "N", **_POSITIVE),
    "excitation.frequency": Parameter("frequency", "Hz", **_POSITIVE),
}
#: A task that sweeps the frequency itself: the joint and the force amplitude, and its range.
_SWEPT_FREQUENCY_PARAMETERS: dict[str, Parameter] = {
    **JOINT_PARAMETERS,
    "excitation.force_amplitude": FORCING_PARAMETERS["excitation.force_amplitude"],
}
_FREQUENCY_RANGE: dict[str, tuple[float | None, Parameter]] = {
    "task.frequency_start": (None, Parameter("frequency", "Hz", open_lower=True)),
    "task.frequency_stop": (None, Parameter("frequency", "Hz", open_lower=True)),
}


def _frequency_range(values: Mapping[str, float]) -> tuple[float, float]:
    """The point's (task.frequency_start, task.frequency_stop) in Hz, checked in order."""
    low, high = values["task.frequency_start"], values["task.frequency_stop"]
    if not high > low:
        raise ParameterError(f"task.frequency_stop must exceed frequency_start, got {low}, {high}")
    return low, high


@_task(
    "steady_state",
    "study",
    {**JOINT_PARAMETERS, **FORCING_PARAMETERS},
    {"task.samples_per_period": (64.0, _count(8.0)), "task.max_periods": (20_000.0, _count(10.0))},
    _outputs(
        "amplitude_m",
        "x_max_m",
        "x_min_m",
        "compression_penetration_m",
        "tension_penetration_m",
        "period_multiple",
        "periods_to_converge",
        "energy_input_j",
        "viscous_j",
        "sliding_friction_j",
        "impact_j",
        "contact_friction_j",
        "balance_error",
    ),
    "exact steady cycle of the forced joint (energies per forcing period)",
)
def _steady_state(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.simulate import steady_state

    study = study_at(base, values)
    cycle = steady_state(
        study.joint,
        study.force_amplitude,
        study.omega,
        losses=study.losses,
        samples_per_period=int(values.get("task.samples_per_period", 64)),
        max_periods=int(values.get("task.max_periods", 20_000)),
    )
    per = 1.0 / cycle.period_multiple  # per forcing period
    ledger = cycle.energy
    return {
        "amplitude_m": cycle.amplitude,
        "x_max_m": cycle.x_max,
        "x_min_m": cycle.x_min,
        "compression_penetration_m": cycle.compression_penetration,
        "tension_penetration_m": cycle.tension_penetration,
        "period_multiple": float(cycle.period_multiple),
        "periods_to_converge": float(cycle.periods_to_converge),
        "energy_input_j": ledger.input * per,
        "viscous_j": ledger.viscous * per,
        "sliding_friction_j": ledger.sliding_friction * per,
        "impact_j": ledger.impact * per,
        "contact_friction_j": ledger.contact_friction * per,
        "balance_error": ledger.balance_error,
    }


@_task(
    "energies",
    "study",
    JOINT_PARAMETERS,
    {"task.amplitude": (None, Parameter("length", "m"))},
    _outputs(*ENERGY_KEYS),
    "energies per free cycle at penetration task.amplitude (MODEL.md eq 10-18)",
)
def _energies(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.dissipation import energies

    study = study_at(base, values)
    result = energies(
        study.joint,
        values["task.amplitude"],
        losses=study.losses,
    )
    return {key: float(value) for key, value in result.items()}


@_task(
    "free_cycle",
    "study",
    JOINT_PARAMETERS,
    {"task.amplitude": (None, Parameter("length", "m"))},
    _outputs(
        "natural_frequency_hz",
        "dynamic_stiffness_n_per_m",
        "stiffness_coefficient",
        "equivalent_damping_ratio",
    ),
    "the joint's amplitude-dependent modal properties on the free cycle at "
    "penetration task.amplitude: f_n (MODEL.md eq 5-6), k_d, c_d (eq 8-9), and the "
    "equivalent damping ratio of every loss (eq 10-18)",
)
def _free_cycle(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint import stiffness
    from clearjoint.dissipation import energies

    study = study_at(base, values)
    amplitude = values["task.amplitude"]
    period = float(stiffness.period(study.joint, amplitude))
    damping = energies(
        study.joint,
        amplitude,
        losses=study.losses,
    )
    return {
        "natural_frequency_hz": 1.0 / period,
        "dynamic_stiffness_n_per_m": float(stiffness.dynamic_stiffness(study.joint, amplitude)),
        "stiffness_coefficient": float(stiffness.stiffness_coefficient(study.joint, amplitude)),
        "equivalent_damping_ratio": float(damping["equivalent_damping_ratio"]),
    }


@_task(
    "stepped_sine",
    "study",
    _SWEPT_FREQUENCY_PARAMETERS,
    {
        **_FREQUENCY_RANGE,
        "task.frequency_steps": (40.0, _count(2.0)),
        "task.max_periods": (20_000.0, _count(10.0)),
    },
    _outputs(
        "peak_amplitude_m",
        "peak_frequency_hz",
        "peak_amplitude_up_m",
        "peak_amplitude_down_m",
        "jump_m",
        "steps_failed",
    ),
    "frequency-response curve by a stepped sine up and down (simulate.frequency_sweep; "
    "no pin contact friction): its peak, where, and the up/down jump",
)
def _stepped_sine(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    import warnings

    from clearjoint.simulate import frequency_sweep

    study = study_at(base, values)
    low, high = _frequency_range(values)
    steps = int(values["task.frequency_steps"])
    hz = np.linspace(low, high, steps)
    curve = frequency_sweep(
        study.joint,
        study.force_amplitude,
        2.0 * math.pi * hz,
        losses=study.motion_losses,
        max_periods=int(values["task.max_periods"]),
    )
    both = np.vstack([curve.amplitude_up, curve.amplitude_down])
    failed = int(np.count_nonzero(np.isnan(both)))
    if failed == both.size:
        raise ParameterError("no step of the stepped sine found a steady state")
    if failed:
        warnings.warn(
            f"{failed} of {both.size} steps found no steady state (NaN there)",
            RuntimeWarning,
            stacklevel=2,
        )
    peak = int(np.nanargmax(np.nanmax(both, axis=0)))
    return {
        "peak_amplitude_m": float(np.nanmax(both)),
        "peak_frequency_hz": float(hz[peak]),
        "peak_amplitude_up_m": float(np.nanmax(curve.amplitude_up)),
        "peak_amplitude_down_m": float(np.nanmax(curve.amplitude_down)),
        "jump_m": float(np.nanmax(np.abs(curve.amplitude_up - curve.amplitude_down))),
        "steps_failed": float(failed),
    }


@_task(
    "periodic_orbit",
    "study",
    {**JOINT_PARAMETERS, **FORCING_PARAMETERS},
    {"task.period_multiple": (1.0, _count(1.0))},
    _outputs(
        "amplitude_m",
        "x_max_m",
        "x_min_m",
        "stable",
        "largest_multiplier",
        "energy_input_j",
        "balance_error",
    ),
    "exact periodic orbit by Newton on the exact map (clearjoint.periodic, MODEL.md "
    "5.1), stable or not: extremes, stability (Floquet multipliers), input per period",
)
def _periodic_orbit(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.periodic import periodic_orbit

    study = study_at(base, values)
    orbit = periodic_orbit(
        study.joint,
        study.force_amplitude,
        study.omega,
        losses=study.motion_losses,
        period_multiple=int(values["task.period_multiple"]),
    )
    per = 1.0 / int(values["task.period_multiple"])  # per forcing period
    ledger = orbit.cycle.energy
    return {
        "amplitude_m": orbit.amplitude,
        "x_max_m": orbit.x_max,
        "x_min_m": orbit.x_min,
        "stable": float(orbit.stable),
        "largest_multiplier": float(np.max(np.abs(orbit.multipliers))),
        "energy_input_j": ledger.input * per,
        "balance_error": ledger.balance_error,
    }


@_task(
    "frequency_response",
    "study",
    _SWEPT_FREQUENCY_PARAMETERS,
    {**_FREQUENCY_RANGE, "task.max_points": (2000.0, _count(10.0))},
    _outputs(
        "peak_amplitude_m",
        "peak_frequency_hz",
        "peak_x_max_m",
        "folds",
        "period_doublings",
        "unstable_points",
        "points",
    ),
    "whole frequency-response curve of exact periodic orbits by continuation "
    "(clearjoint.periodic, MODEL.md 5.1): its peak, folds, doublings, unstable points",
)
def _frequency_response(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.periodic import frequency_response
    from clearjoint.simulate import SimulationError

    study = study_at(base, values)
    low, high = _frequency_range(values)
    curve = frequency_response(
        study.joint,
        study.force_amplitude,
        2.0 * math.pi * low,
        2.0 * math.pi * high,
        losses=study.motion_losses,
        max_points=int(values["task.max_points"]),
    )
    if curve.stop_reason != "reached":
        # a curve cut short has no honest peak: the point is NaN with this reason
        last = curve.omega[-1] / (2.0 * math.pi) if curve.omega.size else low
        raise SimulationError(f"the continuation stopped at {last:.6g} Hz ({curve.stop_reason})")
    peak = int(np.argmax(curve.amplitude))
    kinds = [event.kind for event in curve.events]
    return {
        "peak_amplitude_m": float(curve.amplitude[peak]),
        "peak_frequency_hz": float(curve.omega[peak] / (2.0 * math.pi)),
        "peak_x_max_m": float(curve.x_max[peak]),
        "folds": float(kinds.count("fold")),
        "period_doublings": float(kinds.count("period_doubling")),
        "unstable_points": float(np.count_nonzero(~curve.stable)),
        "points": float(curve.omega.size),
    }


@_task(
    "nonlinear_mode",
    "study",
    JOINT_PARAMETERS,
    {
        "task.amplitude": (None, Parameter("length", "m", open_lower=True)),
        "task.harmonics": (7.0, _count(1.0)),
    },
    _outputs("frequency_hz", "damping_ratio", "energy_per_cycle_j", "x_max_m", "x_min_m"),
    "the joint's nonlinear mode at modal amplitude task.amplitude by harmonic "
    "balance (EPMC, clearjoint.harmonic, MODEL.md 5.4): frequency and damping",
)
def _nonlinear_mode(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.harmonic import nonlinear_modes
    from clearjoint.simulate import SimulationError

    study = study_at(base, values)
    mode = nonlinear_modes(
        study.joint,
        1,
        [values["task.amplitude"]],
        harmonics=int(values["task.harmonics"]),
        losses=study.motion_losses,
    )
    if not bool(mode.converged[0]):
        raise SimulationError("the nonlinear mode did not converge at this amplitude")
    return {
        "frequency_hz": float(mode.frequency[0] / (2.0 * math.pi)),
        "damping_ratio": float(mode.damping_ratio[0]),
        "energy_per_cycle_j": float(mode.energy_per_cycle[0]),
        "x_max_m": float(mode.x_max[0]),
        "x_min_m": float(mode.x_min[0]),
    }


# ---- a structure study: its joints one by one ---------------------------------------------

#: What a structure sweep may vary of its joints (keys as in the study's [joint] section).
STRUCTURE_JOINT_PARAMETERS: dict[str, Parameter] = {
    key: JOINT_PARAMETERS[key]
    for key in (
        "joint.clearance",
        "joint.compression_stiffness",
        "joint.tension_stiffness",
        "joint.gap_stiffness",
        "joint.gap_offset",
    )
}


@_task(
    "structure_mode",
    "structure",
    STRUCTURE_JOINT_PARAMETERS,
    {
        "task.amplitude": (None, Parameter("length", "m", open_lower=True)),
        "task.mode": (1.0, _count(1.0)),
        "task.harmonics": (7.0, _count(1.0)),
        "task.start_amplitude": (0.0, Parameter("length", "m")),
        "task.ladder_steps": (4.0, _count(1.0)),
    },
    _outputs(
        "frequency_hz", "damping_ratio", "energy_per_cycle_j", "x_max_m", "closed_frequency_hz"
    ),
    "a nonlinear mode of a structure study (EPMC, clearjoint.harmonic, MODEL.md 5.4) "
    "at modal amplitude task.amplitude on its reference DOF: frequency, damping "
    "ratio, energy per cycle, the reference DOF's largest displacement, and the "
    "closed-pattern linear frequency",
)
def _structure_mode(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.harmonic import nonlinear_modes
    from clearjoint.simulate import SimulationError
    from clearjoint.structure.model import Structure

    structure = structure_at(base, values).structure
    assert isinstance(structure, Structure)  # structure_at refuses a [model] study
    amplitude = values["task.amplitude"]
    start = values.get("task.start_amplitude", 0.0)
    steps = int(values["task.ladder_steps"])
    number, harmonics = int(values["task.mode"]), int(values["task.harmonics"])
    # from a large amplitude, where the closed-pattern mode is a good first guess, down
    # to the one asked, each solve starting from the one before (nonlinear_modes does so)
    ladder = (
        np.geomspace(amplitude, start, steps + 1) if start > amplitude else np.array([amplitude])
    )
    key = (tuple(sorted((k, v) for k, v in values.items() if k.startswith("joint."))), number)
    mode, at = _LAST_LADDER.find(base, (*key, harmonics), ladder)
    if mode is None:
        mode, at = nonlinear_modes(structure, number, ladder, harmonics=harmonics), 0
        _LAST_LADDER.keep(base, (*key, harmonics), mode)
    if not bool(mode.converged[at]):
        raise SimulationError(
            f"the nonlinear mode did not converge at {amplitude:.4g} m (ladder from {start:.4g} m)"
        )
    closed = structure.modes("closed").frequency_hz[number - 1]
    ref = structure.dof_names.index(mode.reference_dof)
    return {
        "frequency_hz": float(mode.frequency[at] / (2.0 * math.pi)),
        "damping_ratio": float(mode.damping_ratio[at]),
        "energy_per_cycle_j": float(mode.energy_per_cycle[at]),
        "x_max_m": float(mode.x_max[at, ref]),
        "closed_frequency_hz": float(closed),
    }


class _LastLadder:
    """The last ladder of amplitudes this process solved, to serve a point it already holds.

    ``nonlinear_modes`` solves the amplitudes from the largest down, each from the one
    before, so its value at amplitude a depends only on the structure, the mode, H and
    the amplitudes above a. A point whose own ladder has exactly the amplitudes above a
    that the kept ladder had (the top of a ladder: nothing above) gets the very numbers
    a new call would give, bit for bit; anything else is solved afresh. It halves the
    cost of a tolerance study at two amplitudes (the larger is the smaller's start).
    """

    def __init__(self) -> None:
        # one tuple, replaced whole: threads of one worker never see half of another's
        self._kept: tuple[Any, tuple[Any, ...], Any] = (None, (), None)

    def find(self, base: Any, key: tuple[Any, ...], ladder: Any) -> tuple[Any, int]:
        """Return (the kept NonlinearMode, the index of ``ladder[0]`` in it), or (None, 0)."""
        kept_base, kept_key, mode = self._kept
        if mode is None or base is not kept_base or key != kept_key:
            return None, 0
        kept = mode.amplitude
        hits = np.flatnonzero(kept == ladder[0])
        if hits.size != 1:
            return None, 0
        above = kept[kept > ladder[0]]
        if above.shape != ladder[1:].shape or not np.array_equal(above, ladder[1:]):
            return None, 0
        return mode, int(hits[0])

    def keep(self, base: Any, key: tuple[Any, ...], mode: Any) -> None:
        """Keep ``mode`` (holding ``base`` so that its identity stays unique)."""
        self._kept = (base, key, mode)


_LAST_LADDER = _LastLadder()


# ---- a test of the virtual rig ---------------------------------------------------------------


@_task(
    "rig_test",
    "campaign",
    {
        "test.clearance": Parameter("length", "m", **_POSITIVE),
        "test.frequency": Parameter("frequency", "Hz", **_POSITIVE),
        "test.force_amplitude": Parameter("force", "N", **_POSITIVE),
    },
    {},
    _outputs(
        "clearance_m",
        "energy_per_cycle_j",
        "amplitude_m",
        "identified_clearance_m",
        "identified_energy_per_cycle_j",
    ),
    "one virtual-rig test (the campaign's first jointed structure, frequency and "
    "force unless varied), measured with the point's own noise, then identified",
)
def _rig_test(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.identify import identify
    from clearjoint.rig import Structure, TestSpec, simulate_test

    clearance = values.get("test.clearance", base.structures[0].clearance)
    spec = TestSpec(
        index=0,
        structure=Structure("joint", True, clearance),
        frequency_hz=values.get("test.frequency", base.frequencies[0]),
        force_amplitude=values.get("test.force_amplitude", base.force_amplitudes[0]),
    )
    record, truth = simulate_test(base.rig, spec, base.periods, seed)
    found = identify(record)
    return {
        "clearance_m": truth["clearance_m"],
        "energy_per_cycle_j": truth["energy_per_cycle_j"],
        "amplitude_m": truth["amplitude_m"],
        "identified_clearance_m": float(found.summary["clearance_m"]),
        "identified_energy_per_cycle_j": float(found.summary["energy_per_cycle_j"]),
    }


# ---- identification of a record set ----------------------------------------------------------


@dataclass(frozen=True)
class RecordSet:
    """The record files a sweep identifies: one point per file along the ``record`` axis."""

    files: tuple[str, ...]
    source: str = ""


#: What ``identify`` reports of a record: the per-cycle quantities of a clearance joint.
_IDENTIFIED = _outputs(*QUANTITIES[: QUANTITIES.index("dynamic_stiffness_n_per_m") + 1])


@_task(
    "identify",
    "records",
    {},
    {"task.tolerance": (0.03, Parameter("dimensionless", "", open_lower=True, upper=1.0))},
    {**_IDENTIFIED, "frequency_hz": "Hz", "cycles_used": ""},
    "identification of each record of a set (clearjoint.identify): the mean over its "
    "steady cycles of each quantity; a record that cannot be identified says why",
)
def _identify(
    base: Any, values: Mapping[str, float], seed: np.random.SeedSequence
) -> dict[str, float]:
    from clearjoint.identify import identify
    from clearjoint.records import read_record

    record = read_record(base.files[int(values["record"])])
    found = identify(record, tolerance=values["task.tolerance"])
    out = {key: float(found.summary[key]) for key in _IDENTIFIED}
    out["frequency_hz"] = float(found.frequency_hz)
    out["cycles_used"] = float(found.cycles_used)
    return out
