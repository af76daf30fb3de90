"""The test record: time, force and displacement in SI with their metadata, and its rules.

A :class:`Record` is validated when it is made (strictly increasing, uniformly
sampled, finite, long enough for three cycles); everything inside is SI with the
frequencies in Hz, as in files. This module also holds what every file format shares
(the channels and their SI units, the factors that take a file's units to them, the
record made from a file's columns) and the one steady-cycle rule, :data:`STEADY_RULE`
(MODEL.md section 3): a record too short for it is refused here, and every
identification path applies it and quotes it (:mod:`clearjoint.identify.cycles`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from clearjoint.errors import ClearjointError, ParameterError
from clearjoint.units import is_quantity, registry, to_si

__all__ = [
    "CHANNELS",
    "CLOSURE",
    "FAST_FACTORS",
    "GRAVITY_UNITS",
    "MIN_CYCLES",
    "MIN_SAMPLES",
    "MIN_STEADY",
    "PLATEAU",
    "SI",
    "STANDARD_GRAVITY",
    "STEADY_RULE",
    "UNIFORM_TOLERANCE",
    "Record",
    "RecordError",
    "RecordWarning",
    "resample",
    "steady_rule",
]

FloatArray = NDArray[np.float64]

CHANNELS = ("force", "displacement", "velocity", "acceleration")
SI = {"time": "s", "force": "N", "displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}
#: Relative spread of the time step allowed in a "uniformly sampled" record.
UNIFORM_TOLERANCE = 1e-4
#: Cycles a record must span when its frequency is known.
MIN_CYCLES = 3
MIN_SAMPLES = 16
#: The SI unit of each metadata quantity (a pint Quantity or "0.1mm" is converted to it).
_META_SI = {
    "clearance": "m",
    "force_amplitude": "N",
    "displacement_amplitude": "m",
    "frequency_hz": "Hz",
    "mass": "kg",
}


# ---- the steady-cycle rule ----------------------------------------------------------------

#: Steady cycles a record needs.
MIN_STEADY = 3
#: A steady cycle's first and last displacement differ by at most this part of its
#: amplitude: a cycle that starts on the ramp is not steady even if it ends on the plateau.
CLOSURE = 0.15
#: The plateau: the cycles whose amplitude is at least this part of the largest one.
PLATEAU = 0.9


def _percent(part: float) -> str:
    return f"{100 * part:.3g} %"


def steady_rule(tolerance: float) -> str:
    """The steady-cycle rule in words, for the docs and every error message."""
    return (
        f"a cycle (minimum to minimum of the fundamental) is steady when its amplitude is "
        f"within {_percent(tolerance)} of the plateau amplitude A, its mean position within "
        f"{_percent(tolerance)} of A from the plateau mean, and its first and last displacement "
        f"differ by at most {_percent(CLOSURE)} of A (A and the plateau mean are the medians "
        f"over the cycles whose amplitude is at least {_percent(PLATEAU)} of the largest); "
        f"a record needs at least {MIN_STEADY} steady cycles, and all of them are used"
    )


STEADY_RULE = steady_rule(0.03)


class RecordError(ClearjointError, ValueError):
    """A record or a record file is unusable; the message names the file and the fix."""


class RecordWarning(UserWarning):
    """A record file was read, but part of it was left out (the message says which)."""


@dataclass(frozen=True)
class Record:
    """One test record in SI units (frequencies in Hz, as in files).

    Attributes
    ----------
    time : (N,) ndarray
        s, strictly increasing and uniformly sampled.
    force, displacement : (N,) ndarray
        N and m: the force on, and the displacement of, the jointed end.
    velocity, acceleration : (N,) ndarray or None
        m/s and m/s^2, when measured.
    control : {"force", "displacement"}
        What the test controlled: a force-controlled test's restoring force is
        force - m x''; a displacement-controlled test measures it directly.
    joint_id : str
    clearance : float or None
        Nominal clearance, m.
    force_amplitude, displacement_amplitude : float or None
        Nominal excitation amplitude, N or m.
    frequency_hz : float or None
        Nominal excitation frequency, Hz.
    mass : float or None
        Moving mass behind the force sensor, kg (for the inertia correction).
    units : dict
        The units each channel had in its file.
    notes, source : str
        Free-form notes; the file it came from.
    """

    time: FloatArray
    force: FloatArray
    displacement: FloatArray
    velocity: FloatArray | None = None
    acceleration: FloatArray | None = None
    control: str = "force"
    joint_id: str = ""
    clearance: float | None = None
    force_amplitude: float | None = None
    displacement_amplitude: float | None = None
    frequency_hz: float | None = None
    mass: float | None = None
    units: dict[str, str] = field(default_factory=dict)
    notes: str = ""
    source: str = ""

    def __post_init__(self) -> None:
        where = self.source or "record"
        set_ = object.__setattr__
        time = _channel(where, "time", self.time)
        n = time.size
        if n < MIN_SAMPLES:
            raise RecordError(f"{where}: only {n} samples; a record needs at least {MIN_SAMPLES}")
        set_(self, "time", time)
        for name in CHANNELS:
            value = getattr(self, name)
            if value is None:
                continue
            array = _channel(where, name, value)
            if array.size != n:
                raise RecordError(
                    f"{where}: {name} has {array.size} samples but time has {n}; "
                    "every channel must have one sample per time"
                )
            set_(self, name, array)
        step = np.diff(time)
        if np.any(step <= 0.0):
            i = int(np.argmax(step <= 0.0))
            raise RecordError(
                f"{where}: time is not strictly increasing (sample {i + 1}: "
                f"{time[i]!r} -> {time[i + 1]!r} s); sort the record or remove repeated samples"
            )
        spread = float(np.ptp(step) / np.mean(step))
        if spread > UNIFORM_TOLERANCE:
            raise RecordError(
                f"{where}: not uniformly sampled (time step from {step.min():.6g} to "
                f"{step.max():.6g} s); read it with resample=True (--resample) to interpolate "
                "onto a uniform grid"
            )
        if self.control not in ("force", "displacement"):
            raise RecordError(
                f"{where}: control must be 'force' or 'displacement', got {self.control!r}"
            )
        for name in (
            "clearance",
            "force_amplitude",
            "displacement_amplitude",
            "frequency_hz",
            "mass",
        ):
            value = getattr(self, name)
            if value is None:
                continue
            try:
                number = float(to_si(value, _META_SI[name], name=f"{where}: {name}"))
            except ParameterError as exc:  # a unit string without or with the wrong unit
                raise RecordError(str(exc)) from None
            except (TypeError, ValueError) as exc:
                raise RecordError(f"{where}: {name} must be a number, got {value!r}") from exc
            if not math.isfinite(number) or number < 0.0:
                raise RecordError(f"{where}: {name} must be finite and >= 0, got {value!r}")
            set_(self, name, number)
        if self.frequency_hz:
            cycles = (time[-1] - time[0]) * self.frequency_hz
            if cycles < MIN_CYCLES:
                # the one steady-cycle rule, word for word as every identification path states it
                raise RecordError(
                    f"{where}: spans {cycles:.2f} cycles at {self.frequency_hz:g} Hz; {STEADY_RULE}"
                )

    @property
    def sampling_rate(self) -> float:
        """Samples per second, Hz."""
        return float((self.time.size - 1) / (self.time[-1] - self.time[0]))

    def metadata(self) -> dict[str, Any]:
        """The metadata fields (everything but the arrays) as a plain dict."""
        return {
            f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("time", *CHANNELS)
        }


def _channel(where: str, name: str, value: ArrayLike) -> FloatArray:
    if is_quantity(value):  # np.asarray would drop the unit: a time in ms read as s
        try:
            value = to_si(value, SI[name], name=f"{where}: {name}")
        except ParameterError as exc:
            raise RecordError(str(exc)) from None
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise RecordError(f"{where}: {name} is not numeric") from None
    if array.ndim != 1:
        raise RecordError(f"{where}: {name} must be one-dimensional, got shape {array.shape}")
    bad = ~np.isfinite(array)
    if bad.any():
        i = int(np.argmax(bad))
        raise RecordError(
            f"{where}: {name} has {int(bad.sum())} NaN or infinite values (first at sample {i}); "
            "remove or repair them before loading"
        )
    return array


def resample(
    time: ArrayLike, channels: dict[str, ArrayLike], rate: float | None = None
) -> tuple[FloatArray, dict[str, FloatArray]]:
    """Interpolate channels sampled at increasing ``time`` onto a uniform grid (linear).

    ``rate`` defaults to the median sampling rate. Returns (time, channels).
    """
    t = np.asarray(time, dtype=np.float64)
    order = np.argsort(t, kind="stable")
    t = t[order]
    keep = np.concatenate(([True], np.diff(t) > 0.0))
    t = t[keep]
    step = 1.0 / rate if rate else float(np.median(np.diff(t)))
    grid = np.arange(t[0], t[-1] + 0.5 * step, step)
    grid = grid[grid <= t[-1]]
    out = {
        name: np.interp(grid, t, np.asarray(values, dtype=np.float64)[order][keep])
        for name, values in channels.items()
    }
    return grid, out


#: Exact factors of the units most files use, so that reading them does not build pint's
#: registry (a second or two); tests/test_records.py checks each against pint.
FAST_FACTORS = {
    ("time", "s"): 1.0,
    ("force", "N"): 1.0,
    ("force", "kN"): 1e3,
    ("force", "kip"): 4448.2216152605,
    ("displacement", "m"): 1.0,
    ("displacement", "mm"): 1e-3,
    ("displacement", "um"): 1e-6,
    ("displacement", "in"): 0.0254,
    ("velocity", "m/s"): 1.0,
    ("velocity", "in/s"): 0.0254,
    ("acceleration", "m/s^2"): 1.0,
}


#: Standard gravity, m/s^2: accelerometers speak g, where pint's "g" is the gram.
STANDARD_GRAVITY = 9.80665
#: Spellings of standard gravity taken for an acceleration column (and for no other).
GRAVITY_UNITS = ("g", "gn", "g0")


def _factor(where: str, channel: str, unit: str) -> float:
    """The factor that takes ``channel`` in ``unit`` to SI; errors name the file and channel."""
    fast = FAST_FACTORS.get((channel, unit.strip()))
    if fast is not None:
        return fast
    if channel == "acceleration" and unit.strip() in GRAVITY_UNITS:
        return STANDARD_GRAVITY
    import pint

    target = SI[channel]
    try:
        return float(registry().Quantity(1.0, unit.strip()).to(target).magnitude)
    except pint.errors.DimensionalityError:
        raise RecordError(
            f"{where}: {channel} is in {unit!r}, which is not a unit of {target}; "
            "fix the unit in the file"
        ) from None
    except Exception:  # pint's parser raises many types on odd text ("(", "[")
        raise RecordError(
            f"{where}: unknown unit {unit!r} for {channel}; write a unit such as {target}"
        ) from None


# ---- CSV ----------------------------------------------------------------------------------


def _assemble(
    where: str,
    columns: dict[str, Any],
    units: dict[str, str],
    meta: dict[str, Any],
    resample_: bool,
) -> Record:
    """The Record of a file's columns (SI) and metadata, every reader's last step.

    ``resample_`` interpolates a record that is not uniformly sampled onto a uniform grid
    (:func:`resample`); ``where`` names the file in the errors.
    """
    for required in ("time", "force", "displacement"):
        if required not in columns:
            raise RecordError(
                f"{where}: no {required} channel; a record needs time, force and displacement"
            )
    time = columns.pop("time")
    if resample_:
        step = np.diff(time)
        if step.size and (np.any(step <= 0) or np.ptp(step) > UNIFORM_TOLERANCE * np.mean(step)):
            time, columns = resample(time, columns)
    return Record(time=time, units=units, source=where, **columns, **meta)
