"""An independent simulator of a forced joint with clearance, for the identification tests.

Not the rig and not clearjoint.simulate: a scipy ``solve_ivp`` (DOP853) model written
here, with another friction law than theirs, a smoothed Coulomb friction
F_f tanh(x' / v_s), and no restitution (the contact is a spring, the impacts are
not instantaneous):

    m x'' + c_v x' + F_f tanh(x' / v_s) + k0 x + k_c (x - c/2)^+ - k_t (-c/2 - x)^+ = F0 sin(w t)

Integration stops at every gap edge (event location), so each smooth piece is
integrated on its own. The motion is integrated from rest until two successive
cycles agree, then the last cycle, which is periodic, is sampled at ``rate`` over
``cycles`` periods and written in clearjoint's CSV format with Gaussian noise of
``noise`` times each channel's standard deviation on every channel.

The truth returned with a record comes from the simulator alone: the slopes the
structure shows in contact (k0 + k_c, k0 + k_t), the clearance, F_f, and the energy
dissipated per cycle, integral of (c_v x'^2 + F_f tanh(x'/v_s) x') dt over the cycle.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from clearjoint.records import CSV_MAGIC

Array = np.ndarray


@dataclass(frozen=True)
class TrueJoint:
    """The simulated joint and its excitation (SI)."""

    mass: float = 1.5
    clearance: float = 0.106e-3
    compression_stiffness: float = 6e7  # contact spring, beside k0
    tension_stiffness: float = 4e7
    gap_stiffness: float = 2e5
    viscous: float = 400.0  # N s/m
    friction: float = 60.0  # N, the Coulomb level of the tanh law
    slip_velocity: float = 1e-4  # m/s, v_s of the tanh law
    force_amplitude: float = 1500.0
    frequency_hz: float = 40.0

    def restoring(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The joint's force on the mass, N (everything but inertia and excitation)."""
        half = 0.5 * self.clearance
        contact = self.compression_stiffness * np.maximum(
            x - half, 0.0
        ) - self.tension_stiffness * np.maximum(-half - x, 0.0)
        return (
            self.gap_stiffness * x
            + contact
            + self.viscous * v
            + self.friction * np.tanh(v / self.slip_velocity)
        )


@functools.lru_cache(maxsize=8)
def _periodic_cycle(joint: TrueJoint, settle: int = 80) -> tuple[Callable[[Array], Array], float]:
    """Dense output (x, x') of one steady cycle starting at the returned time t0.

    Each smooth piece (tension contact, free play, compression contact) is integrated
    with its own force law, up to the gap edge where it ends (a terminal event whose
    direction is the one leaving the region, so it does not fire at the piece's start).
    """
    w = 2 * math.pi * joint.frequency_hz
    period = 1.0 / joint.frequency_hz
    half = 0.5 * joint.clearance

    def rhs_for(region: int) -> Callable[[float, Array], Array]:
        def rhs(t: float, y: Array) -> Array:
            x, v = y
            contact = 0.0
            if region == 1:
                contact = joint.compression_stiffness * (x - half)
            elif region == -1:
                contact = joint.tension_stiffness * (x + half)
            r = (
                joint.gap_stiffness * x
                + contact
                + joint.viscous * v
                + joint.friction * math.tanh(v / joint.slip_velocity)
            )
            return np.array([v, (joint.force_amplitude * math.sin(w * t) - r) / joint.mass])

        return rhs

    def edge(level: float, direction: float) -> Callable[[float, Array], float]:
        def event(t: float, y: Array) -> float:
            return float(y[0] - level)

        event.terminal = True  # type: ignore[attr-defined]
        event.direction = direction  # type: ignore[attr-defined]
        return event

    events = {
        1: [edge(half, -1.0)],
        0: [edge(half, 1.0), edge(-half, -1.0)],
        -1: [edge(-half, 1.0)],
    }

    def region_of(y: Array) -> int:
        x, v = y
        if x > half or (x == half and v > 0):
            return 1
        if x < -half or (x == -half and v < 0):
            return -1
        return 0

    def one_cycle(t0: float, y0: Array) -> tuple[list[tuple[float, float, Any]], Array]:
        pieces: list[tuple[float, float, Any]] = []
        t, y = t0, y0
        region = region_of(y)
        while t < t0 + period:
            sol = solve_ivp(
                rhs_for(region),
                (t, t0 + period),
                y,
                method="DOP853",
                rtol=1e-11,
                atol=[1e-15, 1e-11],
                events=events[region],
                dense_output=True,
            )
            if sol.status == -1:
                raise RuntimeError(sol.message)
            pieces.append((t, float(sol.t[-1]), sol.sol))
            t, y = float(sol.t[-1]), sol.y[:, -1]
            if sol.status == 1:
                # the edge: the next region is the one the velocity points into
                region = region + (1 if y[1] > 0 else -1)
        return pieces, np.asarray(y, dtype=float)

    y = np.zeros(2)
    for n in range(settle):
        pieces, y_end = one_cycle(n * period, y)
        if np.allclose(y_end, y, rtol=1e-8, atol=1e-13):
            break
        y = y_end
    else:
        raise RuntimeError("the simulated joint did not settle to a periodic motion")

    starts = np.array([a for a, _, _ in pieces])

    def dense(t: Array) -> Array:
        out = np.empty((2, t.size))
        which = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(pieces) - 1)
        for k, (_, _, piece) in enumerate(pieces):
            mask = which == k
            if mask.any():
                out[:, mask] = piece(t[mask])
        return out

    return dense, n * period


def steady_truth(joint: TrueJoint) -> dict[str, float]:
    """The quantities identification should find, from the simulator alone."""
    dense, t0 = _periodic_cycle(joint)
    period = 1.0 / joint.frequency_hz
    t = t0 + np.linspace(0.0, period, 200_001)
    x, v = dense(t)
    power = joint.viscous * v * v + joint.friction * np.tanh(v / joint.slip_velocity) * v
    energy = float(np.trapezoid(power, t))
    w = 2 * math.pi * joint.frequency_hz
    work = float(np.trapezoid(joint.force_amplitude * np.sin(w * t) * v, t))
    return {
        "clearance_m": joint.clearance,
        "compression_stiffness_n_per_m": joint.gap_stiffness + joint.compression_stiffness,
        "tension_stiffness_n_per_m": joint.gap_stiffness + joint.tension_stiffness,
        "friction_force_n": joint.friction,
        "energy_per_cycle_j": energy,
        "amplitude_m": 0.5 * float(np.ptp(x)),
        "external_work_j": work,
    }


def write_record(
    joint: TrueJoint,
    path: Path,
    *,
    rate: float = 12_000.0,
    cycles: int = 24,
    noise: float = 0.01,
    acceleration: bool = True,
    velocity: bool = False,
    mass_in_metadata: bool = True,
    seed: int = 7,
) -> Path:
    """Sample the periodic motion and write a clearjoint CSV record with noisy channels."""
    dense, t0 = _periodic_cycle(joint)
    period = 1.0 / joint.frequency_hz
    time = np.arange(round(cycles * period * rate)) / rate
    phase = np.mod(time, period)
    x, v = dense(t0 + phase)
    w = 2 * math.pi * joint.frequency_hz
    force = joint.force_amplitude * np.sin(w * (t0 + phase))
    a = (force - joint.restoring(x, v)) / joint.mass
    rng = np.random.default_rng(seed)
    channels = {"force": force, "displacement": x}
    if velocity:
        channels["velocity"] = v
    if acceleration:
        channels["acceleration"] = a
    noisy = {
        name: values + rng.normal(0.0, noise * float(np.std(values)), values.size)
        for name, values in channels.items()
    }
    units = {"force": "N", "displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}
    header = [
        CSV_MAGIC,
        '# control = "force"',
        f'# frequency = "{joint.frequency_hz!r} Hz"',
        f'# force_amplitude = "{joint.force_amplitude!r} N"',
        '# notes = "independent solve_ivp simulator (tests/independent_joint.py)"',
    ]
    if mass_in_metadata:
        header.append(f'# mass = "{joint.mass!r} kg"')
    names = ["time", *noisy]
    header.append(",".join(f"{n} [{units.get(n, 's')}]" for n in names))
    data = np.column_stack([time, *noisy.values()])
    with path.open("w", encoding="utf-8") as handle:
        handle.write("\n".join(header) + "\n")
        np.savetxt(handle, data, delimiter=",", fmt="%.10g")
    return path
