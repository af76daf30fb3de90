"""The period-doubling cascade of a one-link clearance oscillator, by exact shooting.

One 0.5 kg mass on a clearance joint (+-0.1 mm, contact 4e5 N/m, free-play spring 2e4 N/m,
2 N s/m), 20 N at the mass, frequency stepped down from 54.87 Hz. The period-1 orbit is
followed down in frequency with ``clearjoint.structure.periodic_orbit`` until a Floquet
multiplier leaves the unit circle through -1; the crossing is closed in on with Brent's
method (to 1e-10 Hz). Just below it the orbit of twice the period is reached by a transient
from the unstable orbit pushed along the multiplier's eigenvector, and followed in turn.

Prints each period doubling, the intervals between them and their ratios. Feigenbaum's
constant (Feigenbaum 1978, J. Stat. Phys. 19, 25-52) is the limit 4.6692... of those ratios
for a cascade of a smooth map; this cascade's first ratios are 6.4 and 7.9, and one step
(3e-4 Hz) below where the period-16 orbit is last stable, the orbit Newton closes has a
multiplier of modulus 1.8, not near -1: the script does not follow the cascade further, and
does not claim that it converges to Feigenbaum's ratio. Run:
``python examples/one_link_cascade.py`` (about 10 s).
"""

import math

import numpy as np
from scipy.optimize import brentq

import clearjoint as cj
from clearjoint.structure import chain, periodic_orbit, stepped_sine, time_response

LAW = cj.ClearanceJoint(0.2e-3, 4e5, gap_stiffness=2e4)
STRUCTURE = chain([0.5], [math.inf], [LAW], [2.0])
FORCE = np.array([20.0])


def omega(hz: float) -> float:
    return 2.0 * math.pi * hz


def lowest_real_multiplier(orbit) -> float:
    m = np.asarray(orbit.multipliers)
    real = m[np.abs(m.imag) < 1e-9].real
    return float(real.min()) if real.size else 1.0


def orbit_at(period: int, hz: float, state):
    return periodic_orbit(STRUCTURE, FORCE, omega(hz), period_multiple=period, initial=state)


def period_doubling(period: int, hz: float, orbit, step: float):
    """Follow a stable orbit down in frequency; the frequency where it loses stability."""
    while True:
        below = orbit_at(period, hz + step, orbit.initial_state)
        if not below.stable:
            break
        hz, orbit = hz + step, below
    known = {hz: orbit, hz + step: below}
    if lowest_real_multiplier(below) > -1.0:
        return None, known, below

    def distance_to_minus_one(x: float) -> float:
        near = known[min(known, key=lambda k: abs(k - x))]
        known[x] = orbit_at(period, x, near.initial_state)
        return lowest_real_multiplier(known[x]) + 1.0

    return brentq(distance_to_minus_one, hz + step, hz, xtol=1e-10), known, below


def doubled(period: int, hz: float, known):
    """The stable orbit of twice the period just below a period doubling, by a transient."""
    near = known[min(known, key=lambda k: abs(k - hz))]
    orbit = orbit_at(period, hz, near.initial_state)
    values, vectors = np.linalg.eig(orbit.monodromy)
    direction = vectors[:, np.argmin(values.real)].real
    z = np.concatenate(orbit.initial_state)
    z = z + 1e-3 * np.linalg.norm(z) * direction / np.linalg.norm(direction)
    n = len(orbit.initial_state[0])
    motion = time_response(
        STRUCTURE, FORCE, omega(hz), 600 * period / hz, initial=(z[:n], z[n:]), samples_per_period=8
    )
    return orbit_at(2 * period, hz, motion.final_state)


def main() -> None:
    start = 54.87
    warm = stepped_sine(
        STRUCTURE,
        FORCE,
        omega(np.linspace(start, start + 0.6, 13)),
        direction="down",
        settle_periods=300,
        record_periods=4,
    )
    z = warm.poincare[0, 0, 0]
    orbit = orbit_at(1, start, (z[:1], z[1:]))
    period, hz, step, found = 1, start, -0.01, []
    while period <= 16:
        pd, known, lost = period_doubling(period, hz, orbit, step)
        if pd is None:
            print(
                f"period {period}: stable down to {max(known):.6f} Hz; one step below, the orbit "
                f"Newton closes has a multiplier of modulus {np.abs(lost.multipliers).max():.3f}, "
                "not near -1: not followed further"
            )
            break
        found.append(pd)
        print(f"period {period:2d} -> {2 * period:2d}: period doubling at {pd:.7f} Hz")
        gap = found[-2] - found[-1] if len(found) > 1 else 0.5
        hz = pd - 0.05 * gap
        orbit = doubled(period, hz, known)
        period, step = 2 * period, -gap / 150
    intervals = -np.diff(found)
    print("intervals (Hz):", np.array2string(intervals, precision=5))
    print(
        "ratios:",
        np.array2string(intervals[:-1] / intervals[1:], precision=3),
        "(Feigenbaum's limit for a smooth cascade: 4.669)",
    )


if __name__ == "__main__":
    main()
