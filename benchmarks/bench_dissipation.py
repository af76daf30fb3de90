"""Closed-form dissipation against exact-cycle integration over the same 10^4 amplitudes.

Run on demand: ``python benchmarks/bench_dissipation.py [N]`` (default N = 10^4).
The exact route simulates N forced steady cycles (400 Hz, F0 stepped upward from
the last steady state, as a shaker would) and integrates each mechanism over
them; the closed-form route evaluates the same mechanisms on the free cycle at
the N penetrations those cycles reached. Both times and their ratio are printed.
"""

from __future__ import annotations

import math
import sys
import time
import warnings

import numpy as np

from clearjoint import Friction, Joint, Losses, Pin
from clearjoint import dissipation as ds
from clearjoint.contact import HertzValidityWarning
from clearjoint.simulate import SimulationError

JOINT = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, tension_stiffness=5e7)
PIN = Pin.for_clearance(radius=5e-3, clearance=0.106e-3, length=25e-3)
LOSSES = {
    "damping_ratio": 0.01,
    "restitution": 0.8,
    "friction": Friction(0.2, 300.0),
    "contact_friction_coefficient": 0.15,
    "pin": PIN,
}


def main(n: int = 10_000) -> None:
    warnings.simplefilter("ignore", HertzValidityWarning)
    omega = 2 * math.pi * 400.0
    ds.compare(JOINT, 1000.0, omega, losses=Losses(**LOSSES))  # type: ignore[arg-type]  # compile first
    amplitudes = []
    initial = None
    start = time.perf_counter()
    for force in np.linspace(700.0, 2500.0, n):
        try:
            result = ds.compare(
                JOINT,
                float(force),
                omega,
                initial=initial,
                samples_per_period=64,
                max_periods=4000,
                losses=Losses(**LOSSES),
            )  # type: ignore[arg-type]
        except SimulationError:
            continue
        initial = result.cycle.initial_state
        amplitudes.append(result.penetration)
    t_exact = time.perf_counter() - start
    a = np.array(amplitudes)
    best = math.inf
    for _ in range(5):
        start = time.perf_counter()
        ds.energies(JOINT, a, losses=Losses(**LOSSES))  # type: ignore[arg-type]
        best = min(best, time.perf_counter() - start)
    print(
        f"{a.size} amplitudes ({n - a.size} forces gave no periodic orbit), "
        f"A from {a.min() * 1e6:.1f} to {a.max() * 1e6:.1f} um"
    )
    print(
        f"exact cycles (simulate + integrate): {t_exact:.2f} s "
        f"({t_exact / a.size * 1e3:.2f} ms each)"
    )
    print(f"closed form on the free cycle:        {best * 1e3:.2f} ms")
    print(f"ratio: {t_exact / best:.3g}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000)
