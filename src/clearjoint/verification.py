"""What the study checks against something it did not fit: the rig's truth and the model.

* the identification against the virtual rig's truth (``manifest.csv``);
* section 2's closed-form energy (MODEL.md eq 10-17) against the exact steady cycle;
* the paper's Fig. 12 curves, eq 9 and the exact c_d (MODEL.md section 1), set beside
  the measured stiffness as the paper's Discussion does;
* the example steady cycle of examples/study.toml (docs figures).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint import stiffness
from clearjoint.analysis import Analysis
from clearjoint.contact import HertzValidityWarning
from clearjoint.dissipation import compare, energies
from clearjoint.figures import Curve
from clearjoint.joint import Friction, Joint, Losses
from clearjoint.rig import Campaign, structure_under_test
from clearjoint.simulate import SteadyState, steady_state

#: The paper's two joints (c = 0.106 mm and 0.196 mm).
PAPER_CLEARANCES: tuple[float, ...] = (0.106e-3, 0.196e-3)


def identification_accuracy(
    analysis: Analysis, truth: dict[str, dict[str, str]]
) -> tuple[list[dict[str, Any]], dict[str, float]]:
    """Return each test's relative errors against the rig's truth, and the largest of each.

    Contact stiffness is compared with k0 + k_s, the slope a record shows. ``truth``
    maps a record's file name to its row of the rig's ``manifest.csv``.
    """
    accuracy = []
    for row in analysis.rows:
        t = truth[Path(row["file"]).name]
        k0 = float(t["gap_stiffness_n_per_m"])
        entry: dict[str, Any] = {
            "file": Path(row["file"]).name,
            "energy_error": row["energy_per_cycle_j"] / float(t["energy_per_cycle_j"]) - 1,
        }
        if row["jointed"]:
            entry["clearance_error"] = row["clearance_m"] / float(t["clearance_m"]) - 1
            entry["compression_stiffness_error"] = (
                row["compression_stiffness_n_per_m"]
                / (float(t["compression_stiffness_n_per_m"]) + k0)
                - 1
            )
            entry["tension_stiffness_error"] = (
                row["tension_stiffness_n_per_m"] / (float(t["tension_stiffness_n_per_m"]) + k0) - 1
            )
        accuracy.append(entry)
    worst = {
        key: max((abs(a[key]) for a in accuracy if key in a), default=math.nan)
        for key in (
            "clearance_error",
            "compression_stiffness_error",
            "tension_stiffness_error",
            "energy_error",
        )
    }
    return accuracy, worst


def stiffness_study(
    clearances: Sequence[float] = PAPER_CLEARANCES,
    *,
    gap_stiffness_ratio: float = 0.05,
    tension_ratio: float = 0.7,
    max_amplitude: float = 0.5e-3,
    points: int = 300,
) -> list[Curve]:
    """Fig. 12's curves: eq 9 (k0 = 0) and the exact c_d for k0 > 0, k_t < k_c, per clearance."""
    a = np.linspace(0.0, max_amplitude, points)
    curves = []
    for c in clearances:
        joint = Joint(mass=2.0, clearance=c, compression_stiffness=8e7)
        curves.append(
            Curve(
                a, stiffness.stiffness_coefficient(joint, a), f"c = {c * 1e3:.3f} mm, eq 9 (k0 = 0)"
            )
        )
    for c in clearances:
        joint = Joint(
            mass=2.0,
            clearance=c,
            compression_stiffness=8e7,
            tension_stiffness=tension_ratio * 8e7,
            gap_stiffness=gap_stiffness_ratio * 8e7,
        )
        curves.append(
            Curve(
                a,
                stiffness.stiffness_coefficient(joint, a),
                f"c = {c * 1e3:.3f} mm, exact, k0 = {gap_stiffness_ratio:g} k_c, "
                f"k_t = {tension_ratio:g} k_c",
            )
        )
    return curves


def example_cycle() -> SteadyState:
    """The exact steady cycle of the c = 0.106 mm joint at 1 kN, 400 Hz (examples/study.toml)."""
    joint = Joint(mass=2.0, clearance=0.106e-3, compression_stiffness=8e7, tension_stiffness=5e7)
    return steady_state(
        joint,
        1000.0,
        2.0 * np.pi * 400.0,
        losses=Losses(damping_ratio=0.01, restitution=0.8, friction=Friction(0.2, 300.0)),
        samples_per_period=512,
    )


def model_checks(
    campaign: Campaign, analysis: Analysis
) -> tuple[list[float], list[dict[str, Any]]]:
    """Return section 2's closed-form energy at each jointed test, and compare() on every tenth.

    The closed form (MODEL.md eq 10-17 on the free cycle) is evaluated at each jointed
    test's identified penetration with the rig's losses; on every tenth jointed test it
    is set against the exact steady cycle (``dissipation.compare``), and the rig's own
    losses are integrated over the exact steady cycle, timed (``integration_s``,
    ``integrated_j``), so the paper's speed claim is measured, not asserted.
    """
    rig = campaign.rig
    specs = {spec.file_stem: spec for spec in campaign.tests}
    model: list[float] = []
    comparisons: list[dict[str, Any]] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HertzValidityWarning)
        jointed = [r for r in analysis.rows if r["jointed"]]
        for n, row in enumerate(jointed):
            spec = specs[Path(row["file"]).stem]
            joint, pin, _ = structure_under_test(rig, spec)
            losses = rig.losses(pin)
            a = max(row["compression_penetration_m"], 0.0)
            model.append(float(energies(joint, a, losses=losses)["total_j"]))
            if n % 10 == 0:
                omega = 2 * math.pi * spec.frequency_hz
                result = compare(
                    joint, spec.force_amplitude, omega, samples_per_period=256, losses=losses
                )
                # the paper's "numerical integration": the rig's own losses over the exact
                # steady cycle, as benchmarks/bench_laws.py times it
                start = time.perf_counter()
                cycle = steady_state(
                    joint,
                    spec.force_amplitude,
                    omega,
                    losses=rig.losses(),
                    samples_per_period=16,
                )
                elapsed = time.perf_counter() - start
                comparisons.append(
                    {
                        "file": Path(row["file"]).name,
                        "penetration_m": result.penetration,
                        "closed_total_j": result.closed["total_j"],
                        "exact_total_j": result.exact["total_j"],
                        "gap": result.gap["total_j"],
                        "integrated_j": cycle.energy.input / cycle.period_multiple,
                        "integration_s": elapsed,
                    }
                )
    return model, comparisons
