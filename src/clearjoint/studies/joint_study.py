"""A simulation study in one TOML file, with documented defaults, and its netCDF output.

A study names the joint, the excitation and the losses; every dimensional value
carries its unit (``"0.106mm"``, ``"8e7N/m"``, ``"400Hz"``, ``"2513rad/s"``), or
its key names the SI unit (``frequency_hz = 400``); dimensionless values
(``damping_ratio = 0.01``) are bare numbers. The file is read by
:mod:`clearjoint.io_toml`. Anything left out takes the default in
``DEFAULT_STUDY``; an unknown key is an error (it is almost always a typo). The
file format is documented in docs/simulate.md, with an example in
examples/study.toml.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint.checks import refuse_to_overwrite
from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.io_toml import read_table, read_toml
from clearjoint.joint import Friction, Joint, Losses, Pin
from clearjoint.simulate.core import Motion, SteadyState, steady_state, time_response
from clearjoint.studies.rules import hole_radius

__all__ = [
    "DEFAULT_STUDY",
    "Study",
    "StudyError",
    "load_study",
    "run_study",
    "summary",
    "write_netcdf",
]

#: Every key a study may give, with its default (None: required) and the kind of quantity.
DEFAULT_STUDY: dict[str, dict[str, tuple[Any, str]]] = {
    "joint": {
        "mass": (None, "mass"),
        "clearance": (None, "length"),
        "compression_stiffness": (None, "stiffness"),
        "tension_stiffness": ("same as compression_stiffness", "stiffness"),
        "gap_stiffness": (0.0, "stiffness"),
        "gap_offset": (0.0, "length"),
    },
    "excitation": {
        "force_amplitude": (None, "force"),
        "frequency": (None, "frequency"),
        "mode": ("steady", "text"),  # "steady" or "transient"
        "duration": ("ten forcing periods", "time"),  # transient only
        "initial_displacement": (0.0, "length"),
        "initial_velocity": (0.0, "velocity"),
    },
    "losses": {
        "damping_ratio": (0.0, "dimensionless"),
        "restitution": (1.0, "dimensionless"),
        "friction_coefficient": (0.0, "dimensionless"),
        "lateral_load": (0.0, "force"),
        "friction_region": ("everywhere", "text"),
        "contact_friction_coefficient": (0.0, "dimensionless"),
    },
    "pin": {
        "radius": (None, "length"),
        "hole_radius": ("pin radius + clearance / 2", "length"),
        "length": (None, "length"),
        "youngs_modulus": (2.06e11, "pressure"),
        "poisson_ratio": (0.3, "dimensionless"),
    },
    "output": {
        "samples_per_period": (256, "count"),
        "periods": (8, "count"),  # forcing periods a steady state writes to --out
    },
}


class StudyError(ClearjointError, ValueError):
    """A study file is missing, unreadable or holds a bad value."""


@dataclass(frozen=True)
class Study:
    """A parsed study: everything needed to run one simulation (SI, omega in rad/s)."""

    joint: Joint
    force_amplitude: float
    omega: float
    mode: str
    duration: float
    initial: tuple[float, float]
    damping_ratio: float
    restitution: float
    friction: Friction | None
    pin: Pin | None
    contact_friction_coefficient: float
    samples_per_period: int
    source: str
    periods: int = 8

    @property
    def losses(self) -> Losses:
        """The study's five losses as one value, for the functions that take ``losses=``."""
        return Losses(
            damping_ratio=self.damping_ratio,
            friction=self.friction,
            restitution=self.restitution,
            pin=self.pin,
            contact_friction_coefficient=self.contact_friction_coefficient,
        )

    @property
    def motion_losses(self) -> Losses:
        """The losses that shape the motion, without the pin: for curves and orbits.

        The pin's contact friction is evaluated along one cycle without feedback on the
        motion (MODEL.md sec. 2); a curve or an orbit task reports no ledger, so it is
        left out there (it would only cost time and warn where Hertz does not hold).
        """
        return replace(self.losses, pin=None, contact_friction_coefficient=0.0)


def load_study(path: str | Path, *, optional: Collection[str] = ()) -> Study:
    """Read a study TOML file, merge the defaults and validate every value.

    Parameters
    ----------
    path : str or Path
    optional : collection of str
        Required keys, as "section.key", that the caller does not need (e.g.
        "excitation.force_amplitude" for a force curve, whose forces the command
        line gives); left out, they are NaN.

    Raises
    ------
    StudyError
        The file is missing or not TOML, a section or key is unknown, a required
        key is absent, or a value is invalid; the message names the file and key.
    """
    where = str(path)
    raw = read_toml(path, what="study", error=StudyError)
    unknown = sorted(set(raw) - set(DEFAULT_STUDY))
    if unknown:
        raise StudyError(f"{where}: unknown section(s) {unknown}; known: {sorted(DEFAULT_STUDY)}")
    values: dict[str, dict[str, Any]] = {}
    stated: set[str] = set()  # "section.key" of every key the file gives
    for section, spec in DEFAULT_STUDY.items():
        given = read_table(
            raw.get(section, {}),
            {key: kind for key, (_, kind) in spec.items()},
            where=where,
            section=f"[{section}]",
            error=StudyError,
        )
        stated.update(f"{section}.{key}" for key in given)
        values[section] = {}
        for key, (default, _kind) in spec.items():
            if key in given:
                values[section][key] = given[key]
            elif default is None and f"{section}.{key}" in optional:
                values[section][key] = math.nan
            elif default is None and (section != "pin" or "pin" in raw):
                raise StudyError(f"{where}: [{section}] {key} is required")
            else:
                values[section][key] = default
    try:
        return _build(values, raw, where, stated)
    except ParameterError as exc:
        raise StudyError(f"{where}: {exc}") from None


def _friction(losses: dict[str, Any], stated: set[str], where: str) -> Friction | None:
    """Sliding friction from [losses]; one of mu_s and P without the other is an error.

    A coefficient with no lateral load (or a load with no coefficient) would give no
    friction force at all, silently: the file must state the other (0 to switch it off).
    """
    pairs = (("friction_coefficient", "lateral_load", '"300N"'),
             ("lateral_load", "friction_coefficient", "0.2"))  # fmt: skip
    for key, other, example in pairs:
        if losses[key] != 0.0 and f"losses.{other}" not in stated:
            raise StudyError(
                f"{where}: [losses] {key} is given without {other}, so there would be no "
                f"sliding friction; give {other} too (e.g. {other} = {example})"
            )
    if losses["friction_coefficient"] == 0.0 and losses["lateral_load"] == 0.0:
        return None
    friction = Friction(  # validates the signs and the region
        losses["friction_coefficient"], losses["lateral_load"], losses["friction_region"]
    )
    return friction if friction.force > 0.0 else None


def _build(
    values: dict[str, dict[str, Any]], raw: dict[str, Any], where: str, stated: set[str]
) -> Study:
    j = values["joint"]
    k_c = j["compression_stiffness"]
    tension = j["tension_stiffness"]
    joint = Joint(
        mass=j["mass"],
        clearance=j["clearance"],
        compression_stiffness=k_c,
        tension_stiffness=k_c if isinstance(tension, str) else tension,
        gap_stiffness=j["gap_stiffness"],
        gap_offset=j["gap_offset"],
    )
    ex = values["excitation"]
    frequency = ex["frequency"]
    if not frequency > 0.0:
        raise StudyError(f"{where}: [excitation] frequency must be > 0 Hz, got {frequency!r}")
    omega = 2.0 * math.pi * frequency
    force = ex["force_amplitude"]  # NaN when left out as optional (load_study)
    if "excitation.force_amplitude" in stated and not (math.isfinite(force) and force >= 0.0):
        raise StudyError(
            f"{where}: [excitation] force_amplitude must be a finite force >= 0 N, got {force!r}"
        )
    mode = ex["mode"]
    if mode not in ("steady", "transient"):
        raise StudyError(
            f"{where}: [excitation] mode must be 'steady' or 'transient', got {mode!r}"
        )
    duration = ex["duration"]
    if isinstance(duration, str):
        duration = 10.0 * 2.0 * math.pi / omega
    losses = values["losses"]
    friction = _friction(losses, stated, where)
    pin = None
    if "pin" in raw:
        pv = values["pin"]
        hole = pv["hole_radius"]
        pin = Pin(
            radius=pv["radius"],
            hole_radius=(
                hole_radius(pv["radius"], joint.clearance) if isinstance(hole, str) else hole
            ),
            length=pv["length"],
            youngs_modulus=pv["youngs_modulus"],
            poisson_ratio=pv["poisson_ratio"],
        )
    if losses["contact_friction_coefficient"] > 0.0 and pin is None:
        raise StudyError(
            f"{where}: [losses] contact_friction_coefficient acts on the pin, and the study "
            "has none: add a [pin] table (radius, length) or remove the coefficient"
        )
    samples = values["output"]["samples_per_period"]
    periods = values["output"]["periods"]
    if periods < 1:
        raise StudyError(f"{where}: [output] periods must be >= 1, got {periods}")
    return Study(
        joint=joint,
        force_amplitude=ex["force_amplitude"],
        omega=omega,
        mode=mode,
        duration=duration,
        initial=(ex["initial_displacement"], ex["initial_velocity"]),
        damping_ratio=losses["damping_ratio"],
        restitution=losses["restitution"],
        friction=friction,
        pin=pin,
        contact_friction_coefficient=losses["contact_friction_coefficient"],
        samples_per_period=samples,
        source=where,
        periods=periods,
    )


def run_study(study: Study) -> Motion:
    """Run the study: the steady state (default) or the transient response."""
    common: dict[str, Any] = {
        "losses": study.losses,
        "samples_per_period": study.samples_per_period,
        "initial": study.initial,
    }
    if study.mode == "transient":
        return time_response(
            study.joint, study.force_amplitude, study.omega, study.duration, **common
        )
    return steady_state(study.joint, study.force_amplitude, study.omega, **common)


def summary(study: Study, motion: Motion) -> dict[str, Any]:
    """The result's summary as JSON-ready values (SI units in the key names, Hz)."""
    energy = motion.energy
    out: dict[str, Any] = {
        "mode": study.mode,
        "frequency_hz": study.omega / (2.0 * math.pi),
        "force_amplitude_n": study.force_amplitude,
        "amplitude_m": motion.amplitude,
        "x_max_m": motion.x_max,
        "x_min_m": motion.x_min,
        "events": motion.events,
        "impacts": int(motion.impact_velocities.size),
        "stick_time_s": motion.stick_time,
        "energy_j": {key: float(val) for key, val in energy.as_dict().items()},
        "balance_error": energy.balance_error,
    }
    if isinstance(motion, SteadyState):
        out["period_multiple"] = motion.period_multiple
        out["period_s"] = motion.period
        out["periods_to_converge"] = motion.periods_to_converge
        out["compression_penetration_m"] = motion.compression_penetration
        out["tension_penetration_m"] = motion.tension_penetration
    return out


def write_netcdf(study: Study, motion: Motion, path: str | Path, *, force: bool = False) -> Path:
    """Write the motion as a test record (the one netCDF layout of ``clearjoint.records``).

    The record's ``force`` is the excitation F0 sin(w t) on the mass, its control is
    force and its metadata (mass, clearance, force amplitude, frequency) are the
    study's, so ``read_record`` and ``clearjoint identify`` read the file. A steady
    state is periodic: its exact orbit is repeated to cover ``study.periods`` forcing
    periods. Beside the record: ``restoring_force`` on ``time``, the first orbit's
    stages on ``stage`` and impacts on ``impact``, and the study, losses and energy
    ledger as attributes.

    Raises
    ------
    OutputExistsError (a ClearjointError)
        ``path`` exists and ``force`` is False.
    StudyError
        ``path`` does not end in .nc.
    """
    from clearjoint.records import record_dataset

    path = Path(path)
    if path.suffix.lower() != ".nc":
        raise StudyError(f"{path}: a simulation is written as netCDF; name the file .nc")
    refuse_to_overwrite([path], force=force)
    joint = study.joint
    time = motion.time
    series = {
        "displacement": motion.displacement,
        "velocity": motion.velocity,
        "acceleration": motion.acceleration,
        "force": motion.excitation,
        "restoring_force": motion.restoring_force,
    }
    if isinstance(motion, SteadyState):
        orbit = motion.period  # the whole orbit: period_multiple forcing periods
        repeats = max(1, math.ceil(study.periods / motion.period_multiple))
        time = np.concatenate([time + k * orbit for k in range(repeats)])
        series = {name: np.tile(values, repeats) for name, values in series.items()}
    restoring = series.pop("restoring_force")
    data = record_dataset(
        time,
        series,
        {
            "joint_id": "simulation",
            "control": "force",
            "notes": f"clearjoint simulate {study.source} ({study.mode})",
            "clearance": joint.clearance,
            "force_amplitude": study.force_amplitude,
            "frequency_hz": study.omega / (2.0 * math.pi),
            "mass": joint.mass,
        },
    )
    stage_names = np.array([s.name for s in motion.stages], dtype=object)
    data["restoring_force"] = ("time", restoring, {"units": "N"})
    data["stage_name"] = ("stage", stage_names.astype(str))
    data["stage_start"] = ("stage", np.array([s.start for s in motion.stages]), {"units": "s"})
    data["stage_end"] = ("stage", np.array([s.end for s in motion.stages]), {"units": "s"})
    data["impact_time"] = ("impact", motion.impact_times, {"units": "s"})
    data["impact_velocity"] = ("impact", motion.impact_velocities, {"units": "m/s"})
    data.attrs.update(
        {
            "title": "clearjoint simulation",
            "study": study.source,
            "compression_stiffness_n_per_m": joint.compression_stiffness,
            "tension_stiffness_n_per_m": joint.tension_stiffness,
            "gap_stiffness_n_per_m": joint.gap_stiffness,
            "gap_offset_m": joint.gap_offset,
            "damping_ratio": study.damping_ratio,
            "restitution": study.restitution,
            "friction_force_n": study.friction.force if study.friction else 0.0,
            **{f"energy_{key}_j": float(val) for key, val in motion.energy.as_dict().items()},
            **{
                key: val
                for key, val in summary(study, motion).items()
                if isinstance(val, int | float) and not isinstance(val, bool)
            },
        }
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    data.to_netcdf(path, engine="h5netcdf")
    return path
