"""The tasks of a structure study: its modes, its exact forced response, its free decay.

``modes``: the linear modes with every joint closed and open (MODEL.md 5.2);
``respond``: the exact forced response over the study's periods; ``decay``: the exact
free decay from a deflection along a closed mode, with its backbone (amplitude,
frequency and damping ratio per cycle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint.errors import ParameterError
from clearjoint.structure.model import Structure, system_modes
from clearjoint.structure.study import StructureStudy

__all__ = [
    "STRUCTURE_TASKS",
    "StructureTaskResult",
    "marched_periods",
    "run_structure_task",
    "stepped_sine_of",
    "write_structure_result",
]

#: The tasks :func:`run_structure_task` runs.
STRUCTURE_TASKS = ("modes", "respond", "decay")


@dataclass(frozen=True)
class StructureTaskResult:
    """What a structure task gives: its Dataset, a JSON-ready summary, what to draw.

    ``drawn`` is a result with ``.plot(ax)``, a matplotlib Figure already drawn, or None.
    """

    data: Any
    summary: dict[str, Any]
    drawn: Any


def marched_periods(
    study: StructureStudy,
    task: str,
    *,
    points: int = 100,
    settle_periods: int = 200,
    record_periods: int = 100,
) -> float:
    """The periods of exact motion ``task`` will march, for an estimate of its time.

    ``respond``: the study's [excitation] periods; ``decay``: its [decay] duration in
    periods of the lowest closed mode (the fewest the duration can hold: an estimate rather
    short than long); ``stepped-sine``: ``points`` x (``settle_periods`` +
    ``record_periods``), one direction; 0 for ``modes`` and for a task whose section is
    missing (the task itself then says so).
    """
    if task == "respond" and study.omega is not None:
        return float(study.periods)
    if task == "decay" and study.decay_duration is not None:
        s = study.structure
        modes = s.modes("closed", 1) if isinstance(s, Structure) else system_modes(s, "closed", 1)
        return study.decay_duration * float(modes.omega[0]) / (2.0 * math.pi)
    if task == "stepped-sine":
        return float(points) * (settle_periods + record_periods)
    return 0.0


def run_structure_task(
    study: StructureStudy, task: str, *, figure: bool = False
) -> StructureTaskResult:
    """Return the StructureTaskResult of ``task`` ("modes", "respond", "decay") on the study.

    Parameters
    ----------
    study : StructureStudy
    task : str
        One of :data:`STRUCTURE_TASKS`.
    figure : bool
        Draw the modes figure (the other tasks' results draw themselves).

    Raises
    ------
    ParameterError
        The study lacks the section the task needs ([excitation] or [decay]).
    """
    import xarray as xr

    from clearjoint.structure import decay_backbone, free_decay, time_response

    s = study.structure
    summary: dict[str, Any] = {"structure": repr(s)}
    drawn: Any = None
    if task == "modes":
        if isinstance(s, Structure):
            closed, opened = s.modes("closed"), s.modes("open")
        else:  # a [model]'s system (reduced: its modal coordinates q1, q2, ...)
            closed, opened = system_modes(s, "closed"), system_modes(s, "open")
        data = xr.concat(
            [closed.to_xarray(), opened.to_xarray()],
            dim=xr.DataArray(["closed", "open"], dims="pattern"),
        )
        summary["closed_hz"] = closed.frequency_hz[:6].tolist()
        summary["open_hz"] = opened.frequency_hz[:6].tolist()
        if figure:
            from clearjoint.figures import structure_modes

            drawn = structure_modes(closed, opened)
    elif task == "respond":
        if study.omega is None or study.force is None:
            raise ParameterError(
                f"{study.source}: respond needs an [excitation] section (frequency, force_dof, "
                "force_amplitude); put it in the study file"
            )
        duration = study.periods * 2.0 * math.pi / study.omega
        motion = time_response(
            s, study.force, study.omega, duration, samples_per_period=study.samples_per_period
        )
        data = motion.to_xarray()
        summary |= {
            "events": motion.events,
            "patterns": motion.patterns_visited,
            "energy_j": motion.energy.as_dict(),
            "balance_error": motion.balance_error,
            "max_displacement_m": float(np.abs(motion.u).max()),
        }
        drawn = motion
    elif task == "decay":
        if study.decay_initial is None or study.decay_duration is None:
            raise ParameterError(
                f"{study.source}: decay needs a [decay] section (dof, initial_amplitude, "
                "duration); put it in the study file"
            )
        motion = free_decay(
            s,
            (study.decay_initial, np.zeros(s.n_dof)),
            study.decay_duration,
            samples_per_period=max(study.samples_per_period, 64),
        )
        backbone = decay_backbone(motion, int(study.decay_dof or 0), mode=study.decay_mode)
        data = xr.merge([motion.to_xarray(), backbone.to_xarray()], combine_attrs="drop_conflicts")
        summary |= {
            "events": motion.events,
            "balance_error": motion.balance_error,
            "amplitude_m": backbone.amplitude.tolist(),
            "frequency_hz": (backbone.omega / (2.0 * math.pi)).tolist(),
            "damping_ratio": [None if math.isnan(z) else float(z) for z in backbone.damping_ratio],
        }
        drawn = backbone
    else:
        raise ParameterError(f"task must be one of {', '.join(STRUCTURE_TASKS)}, got {task!r}")
    return StructureTaskResult(data, summary, drawn)


def stepped_sine_of(
    study: StructureStudy,
    start: float,
    stop: float,
    *,
    points: int = 100,
    direction: str = "up",
    settle_periods: int = 200,
    record_periods: int = 100,
    runner: Any = None,
) -> StructureTaskResult:
    """The study's stepped-sine test, run exactly, from ``start`` to ``stop`` Hz (MODEL.md 5.2).

    ``points`` frequencies evenly spaced (both ends included) at the study's force
    (``clearjoint.structure.stepped_sine``).

    Raises
    ------
    ParameterError
        No [excitation] section, a range that is not increasing and positive, fewer than
        2 points.
    """
    from clearjoint.structure import stepped_sine

    if study.force is None:
        raise ParameterError(
            f"{study.source}: stepped-sine needs an [excitation] section (force_dof, "
            "force_amplitude); put it in the study file"
        )
    for name, value in (("--from", start), ("--to", stop)):
        if not (math.isfinite(value) and value > 0.0):
            raise ParameterError(f"{name} must be a frequency > 0, got {value!r} Hz")
    if not stop > start:
        raise ParameterError(
            f"--to ({stop:g} Hz) must be above --from ({start:g} Hz); the direction of the "
            "steps is --direction"
        )
    if isinstance(points, bool) or not isinstance(points, int) or points < 2:
        raise ParameterError(f"--points must be an integer >= 2, got {points!r}")
    hz = np.linspace(start, stop, points)
    diagram = stepped_sine(
        study.structure,
        study.force,
        2.0 * math.pi * hz,
        direction=direction,  # type: ignore[arg-type]
        settle_periods=settle_periods,
        record_periods=record_periods,
        runner=runner,
    )
    kinds = {str(k): int(np.sum(diagram.kind == k)) for k in np.unique(diagram.kind)}
    summary: dict[str, Any] = {
        "structure": repr(study.structure),
        "frequencies": points,
        "directions": list(diagram.directions),
        "kinds": kinds,
        "max_amplitude_m": float(np.max(diagram.amplitude)),
        "jumps": diagram.jumps,
    }
    return StructureTaskResult(diagram.to_xarray(), summary, diagram)


def write_structure_result(result: StructureTaskResult, path: str | Path) -> Path:
    """Write a structure task's Dataset (``result.data``) to the netCDF file ``path``.

    The folder must exist (the command line checks ``--out`` before the run); returns
    the path written.
    """
    path = Path(path)
    result.data.to_netcdf(path, engine="h5netcdf")
    return path
