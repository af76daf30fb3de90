"""Curves of a study: its frequency response (frf) and its nonlinear modes, run and written.

The method is chosen here: a joint study's curve by exact shooting (MODEL.md 5.1) or
harmonic balance (MODEL.md 5.3), a structure study's always by harmonic balance; a
nonlinear mode by EPMC (MODEL.md 5.4). What harmonic balance cannot carry is refused
first (:mod:`clearjoint.studies.harmonic`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint.errors import ParameterError
from clearjoint.io_toml import read_toml
from clearjoint.structure.study import StructureStudy, load_structure_study
from clearjoint.studies.harmonic import (
    checked_samples,
    no_orbit,
    refuse_harmonic_losses,
    refuse_harmonic_structure,
)
from clearjoint.studies.joint_study import Study, StudyError, load_study
from clearjoint.studies.rules import DEFAULT_HARMONICS

__all__ = [
    "curve_summary",
    "frequency_response_of",
    "load_any_study",
    "mode_summary",
    "name_dofs",
    "nonlinear_modes_of",
    "write_curve",
]

AnyStudy = Study | StructureStudy


def load_any_study(path: str | Path, *, optional: Sequence[str] = ()) -> AnyStudy:
    """Return the study in ``path``: a structure study if it has [structure] or [model]
    (a finite-element model's matrix files), else a joint's.

    ``optional`` is passed to :func:`load_study` for a joint study.
    """
    sections = read_toml(path, what="study", error=StudyError)
    if "structure" in sections or "model" in sections:
        return load_structure_study(path)
    return load_study(path, optional=optional)


def frequency_response_of(
    study: AnyStudy,
    start: float,
    stop: float,
    *,
    parameter: str = "frequency",
    frequency: float | None = None,
    method: str = "shooting",
    harmonics: int | None = None,
    samples: int | None = None,
    max_points: int = 2000,
    names: Mapping[str, str] | None = None,
) -> Any:
    """Return the study's frequency-response curve (MODEL.md 5.1 or 5.3) as FrequencyResponse.

    Parameters
    ----------
    study : Study or StructureStudy
    start, stop : float
        The range: frequencies in Hz, or forces in N with ``parameter="force"``.
    parameter : {"frequency", "force"}
    frequency : float, optional
        The fixed frequency (Hz) of a force curve; default: the study's.
    method : {"shooting", "harmonic"}
        A structure study by shooting (``clearjoint.structure.frequency_response``)
        follows the frequency only.
    harmonics, samples : int, optional
        H (default :data:`DEFAULT_HARMONICS`) and samples per period of harmonic balance.
    max_points : int
    names : mapping of str to str, optional
        How the caller spells "samples" and "harmonics" in errors.

    Raises
    ------
    ParameterError
        A structure study's force curve by shooting, a study without the force the curve needs,
        losses harmonic balance cannot carry, too few samples, or no orbit at the start.
    """
    if isinstance(study, StructureStudy):
        return _structure_curve(
            study, start, stop, parameter, frequency, method, harmonics, samples, max_points, names
        )
    solver: Any
    if method == "harmonic":
        from clearjoint import harmonic

        refuse_harmonic_losses(study, "frf")
        h = DEFAULT_HARMONICS if harmonics is None else harmonics
        solver = functools.partial(
            harmonic.frequency_response, harmonics=h, samples=checked_samples(samples, h, names)
        )
    else:
        from clearjoint.periodic import frequency_response as solver
    if parameter == "force":
        hz = frequency if frequency is not None else study.omega / (2.0 * math.pi)
        return solver(
            study.joint,
            start,
            2.0 * math.pi * hz,
            None,
            parameter="force",
            force_stop=stop,
            max_points=max_points,
            losses=study.motion_losses,
        )
    if not (math.isfinite(study.force_amplitude) and study.force_amplitude > 0.0):
        raise ParameterError(
            f"{study.source}: [excitation] force_amplitude must be finite and > 0, got "
            f"{study.force_amplitude!r} N; give the force the curve is followed at, e.g. 100N"
        )
    return solver(
        study.joint,
        study.force_amplitude,
        2.0 * math.pi * start,
        2.0 * math.pi * stop,
        max_points=max_points,
        losses=study.motion_losses,
    )


def _structure_curve(
    study: StructureStudy,
    start: float,
    stop: float,
    parameter: str,
    frequency: float | None,
    method: str,
    harmonics: int | None,
    samples: int | None,
    max_points: int,
    names: Mapping[str, str] | None,
) -> Any:
    """The frequency response of a structure study, exact by shooting (MODEL.md 5.1 on 5.2)
    or by harmonic balance (MODEL.md 5.3)."""
    from clearjoint import harmonic
    from clearjoint.harmonic.response import NoPeriodicResponse

    if study.force is None or study.omega is None:
        raise ParameterError(
            f"{study.source}: frf needs the [excitation] section (force_dof, force_amplitude; "
            "frequency for --parameter forcing); put it in the study file"
        )
    if method != "harmonic":
        from clearjoint import structure

        if parameter == "force":
            raise ParameterError(
                f"{study.source} is a structure study: its exact curve by shooting follows the "
                "frequency only; drop --parameter forcing, or add --method harmonic"
            )
        return structure.frequency_response(
            study.structure,
            study.force,
            2.0 * math.pi * start,
            2.0 * math.pi * stop,
            max_points=max_points,
        )
    refuse_harmonic_structure(study, "frf")
    h = DEFAULT_HARMONICS if harmonics is None else harmonics
    samples = checked_samples(samples, h, names)
    if parameter == "force":
        hz = frequency if frequency is not None else study.omega / (2.0 * math.pi)
        pattern = study.force * (start / float(np.max(np.abs(study.force))))
        try:
            return harmonic.frequency_response(
                study.structure,
                pattern,
                2.0 * math.pi * hz,
                None,
                harmonics=h,
                samples=samples,
                parameter="force",
                force_stop=stop,
                max_points=max_points,
            )
        except NoPeriodicResponse as exc:
            raise no_orbit(exc, study.source, start) from None
    try:
        return harmonic.frequency_response(
            study.structure,
            study.force,
            2.0 * math.pi * start,
            2.0 * math.pi * stop,
            harmonics=h,
            samples=samples,
            max_points=max_points,
        )
    except NoPeriodicResponse as exc:
        raise no_orbit(exc, study.source, float(np.max(np.abs(study.force)))) from None


def nonlinear_modes_of(
    study: AnyStudy,
    mode: int,
    amplitudes: Any,
    *,
    harmonics: int | None = None,
    samples: int | None = None,
    names: Mapping[str, str] | None = None,
) -> Any:
    """Return the study's nonlinear mode against amplitude by EPMC (MODEL.md 5.4).

    ``harmonics`` defaults to :data:`DEFAULT_HARMONICS`.

    Raises
    ------
    ParameterError
        H below 1, too few samples, or what harmonic balance cannot carry.
    """
    if harmonics is None:
        harmonics = DEFAULT_HARMONICS
    if harmonics < 1:
        name = (names or {}).get("harmonics", "harmonics")
        raise ParameterError(f"{name} must be an integer >= 1, got {harmonics}")
    samples = checked_samples(samples, harmonics, names)
    from clearjoint.harmonic import nonlinear_modes

    if isinstance(study, StructureStudy):
        refuse_harmonic_structure(study, "modes")
        return nonlinear_modes(
            study.structure, mode, amplitudes, harmonics=harmonics, samples=samples
        )
    refuse_harmonic_losses(study, "modes")
    return nonlinear_modes(
        study.joint,
        mode,
        amplitudes,
        harmonics=harmonics,
        samples=samples,
        losses=study.motion_losses,
    )


def name_dofs(data: Any, curve: Any) -> Any:
    """Return the curve's Dataset with its DOFs named, for a structure's curve (else as it is).

    A structure's per-DOF curve does not carry its DOF names yet; drop this when it does.
    """
    names = getattr(curve.settings.get("system"), "dof_names", None)
    if names is not None and "dof" in data.dims:
        data = data.assign_coords(dof=("dof", [str(name) for name in names]))
    return data


def write_curve(result: Any, path: str | Path, source: str) -> None:
    """Write a curve or mode (``result.to_xarray()``) to netCDF, with its study's name."""
    data = result.to_xarray()
    data.attrs["study"] = source
    if hasattr(result, "settings"):
        data = name_dofs(data, result)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    data.to_netcdf(path, engine="h5netcdf")


def curve_summary(curve: Any) -> dict[str, Any]:
    """Return a frequency-response curve as JSON-ready values (Hz, N, m)."""
    free = getattr(curve, "free_play", None)
    system = curve.settings.get("system")
    per_dof = curve.x_max.ndim == 2 and hasattr(system, "dof_names")
    return {
        "frequency_hz": (curve.omega / (2 * math.pi)).tolist(),
        "force_n": curve.force_amplitude.tolist(),
        "amplitude_m": curve.amplitude.tolist(),
        "x_max_m": curve.x_max.tolist(),
        "x_min_m": curve.x_min.tolist(),
        "stable": curve.stable.tolist(),
        **({"dofs": list(system.dof_names)} if per_dof else {}),
        "events": [
            {
                "kind": e.kind,
                "frequency_hz": e.omega / (2 * math.pi),
                "force_n": e.force_amplitude,
                "amplitude_m": e.amplitude,
            }
            for e in curve.events
        ],
        **({"free_play": free.tolist()} if free is not None else {}),
        "stop_reason": curve.stop_reason,
    }


def mode_summary(mode: Any) -> dict[str, Any]:
    """Return a nonlinear mode as JSON-ready values (m, Hz, J; None where not finite)."""

    def finite(values: Any) -> list[float | None]:
        return [float(v) if math.isfinite(v) else None for v in values]

    return {
        "amplitude_m": mode.amplitude.tolist(),
        "frequency_hz": finite(mode.frequency / (2 * math.pi)),
        "damping_ratio": finite(mode.damping_ratio),
        "energy_per_cycle_j": finite(mode.energy_per_cycle),
        "epmc_damping_ratio": finite(mode.epmc_damping_ratio),
    }
