"""The paper's claim: the fitted law (eq 22) is faster than integrating the dissipation.

Run on demand: ``python benchmarks/bench_laws.py``. Eq 22 is fitted on the default
campaign's identified tests; then the energy per cycle at the same 60 jointed tests is
obtained twice: by evaluating eq 22, and by numerical integration over the exact steady
cycle (the simulator's ledger, the paper's "numerical analysis"). Both times per test
and their ratio are printed, with eq 22's error against the integration.
"""

from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np

from clearjoint import Losses, fit
from clearjoint.analysis import analyse
from clearjoint.identify import identify_files
from clearjoint.rig import load_campaign, run_campaign, structure_under_test
from clearjoint.simulate import steady_state


def main() -> None:
    campaign = load_campaign()
    with tempfile.TemporaryDirectory() as folder:
        manifest = run_campaign(campaign, Path(folder), jobs=2)
        files = sorted(str(p) for p in manifest.parent.glob("*.nc"))
        analysis = analyse(*identify_files(files))
    law = analysis.dissipation_law
    assert law is not None
    rows = [r for r in analysis.rows if r["jointed"]]
    omega = np.array([r["omega"] for r in rows])
    clearance = np.array([r["nominal_clearance_m"] for r in rows])
    amplitude = np.array([r["mean_amplitude_m"] for r in rows])
    repeats = 1000
    start = time.perf_counter()
    for _ in range(repeats):
        predicted = fit.evaluate_dissipation_law(law, omega, clearance, amplitude)
    t_law = (time.perf_counter() - start) / repeats / len(rows)
    specs = {spec.file_stem: spec for spec in campaign.tests}
    rig = campaign.rig
    start = time.perf_counter()
    integrated = []
    for row in rows:
        spec = specs[Path(row["file"]).stem]
        joint, _, _ = structure_under_test(rig, spec)
        cycle = steady_state(
            joint,
            spec.force_amplitude,
            2 * math.pi * spec.frequency_hz,
            losses=Losses(
                damping_ratio=rig.damping_ratio,
                friction=rig.bearing_friction,
                restitution=rig.restitution,
            ),
            samples_per_period=16,
        )
        integrated.append(cycle.energy.input / cycle.period_multiple)
    t_integration = (time.perf_counter() - start) / len(rows)
    error = np.abs(predicted / np.array(integrated) - 1)
    print(f"eq 22 on {len(rows)} tests: {t_law * 1e9:.0f} ns per test")
    print(f"exact-cycle integration:   {t_integration * 1e3:.2f} ms per test")
    print(
        f"ratio: the law is {t_integration / t_law:.3g} times faster; "
        f"its error against the integration: median {np.median(error):.1%}, "
        f"max {error.max():.1%}"
    )


if __name__ == "__main__":
    main()
