"""The analysis of a record set: one row per identified test and the fitted laws (eq 19-22).

MODEL.md section 3. :func:`analyse` takes identified records and returns an
:class:`Analysis`: the tests as rows (SI, units in the column names), eq 19 for each
structure and side, Fig. 9's normalised coefficients, eq 20 for each jointed structure
against the structure without clearance, eq 21 for each joint and frequency and eq 22
over all jointed tests (with the power-law alternative). A law that cannot be fitted
says why in ``not_fitted``. No rendering here: report.py draws and writes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from clearjoint import fit
from clearjoint.identify import Identification
from clearjoint.records import Record


@dataclass
class Analysis:
    """Identified tests, the fitted laws, and the reasons for any law not fitted."""

    rows: list[dict[str, Any]]
    identifications: list[tuple[Record, Identification]]
    failures: list[str]
    stiffness_laws: dict[str, fit.LinearFit] = field(default_factory=dict)
    normalised: dict[str, tuple[float, float]] = field(default_factory=dict)
    joint_stiffness: dict[str, fit.JointStiffness] = field(default_factory=dict)
    exponential_laws: dict[str, fit.LinearFit] = field(default_factory=dict)
    dissipation_law: fit.LinearFit | None = None
    alternative_law: fit.LinearFit | None = None
    not_fitted: list[str] = field(default_factory=list)


def _group(record: Record, ident: Identification) -> str:
    """A structure's name: its joint id (and nominal clearance), or 'beam' when it has none."""
    if ident.model == "line":
        return record.joint_id or "no clearance"
    return record.joint_id or f"c = {ident.summary['clearance_m'] * 1e3:.3f} mm"


def _study_rows(results: list[tuple[Record, Identification]]) -> list[dict[str, Any]]:
    rows = []
    for record, ident in results:
        row = ident.row()
        c_nominal = record.clearance if record.clearance else row["clearance_m"]
        nominal = record.frequency_hz or float(f"{row['frequency_hz']:.4g}")
        row.update(
            test_frequency_hz=nominal,
            structure=_group(record, ident),
            jointed=ident.model != "line",
            nominal_clearance_m=c_nominal,
            omega=2.0 * math.pi * nominal,
            mean_amplitude_m=row["amplitude_m"] - 0.5 * row["clearance_m"],
            force_amplitude_n=record.force_amplitude,
        )
        rows.append(row)
    return rows


def tests_of(rows: list[dict[str, Any]], name: str) -> list[dict[str, Any]]:
    """A structure's tests; for a jointed one, only those whose loop showed its clearance.

    A test of a jointed structure identified as a straight line (its stages not found)
    carries no contact stiffness of the joint, so it stays out of its laws.
    """
    tests = [r for r in rows if r["structure"] == name]
    jointed = [r for r in tests if r["jointed"]]
    return jointed or tests


def _attempt(
    analysis: Analysis, title: str, law: Callable[..., fit.LinearFit], *args: Any, **kwargs: Any
) -> fit.LinearFit | None:
    """Fit one law, or note why it could not be fitted."""
    try:
        return law(*args, **kwargs)
    except fit.FitError as exc:
        text = str(exc)
        analysis.not_fitted.append(text if text.startswith(title) else f"{title}: {text}")
        return None


def analyse(results: list[tuple[Record, Identification]], failures: list[str]) -> Analysis:
    """Fit eq 19-22 to identified tests (each law that cannot be fitted says why)."""
    rows = _study_rows(results)
    analysis = Analysis(rows=rows, identifications=results, failures=failures)
    structures = sorted({r["structure"] for r in rows})
    beams = [s for s in structures if not any(r["jointed"] for r in rows if r["structure"] == s)]
    for name in structures:
        sel = tests_of(rows, name)
        for side, key_a in (
            ("compression", "compression_penetration_m"),
            ("tension", "tension_penetration_m"),
        ):
            w = np.array([r["omega"] for r in sel])
            a = np.array([r[key_a] if r["jointed"] else r["amplitude_m"] for r in sel])
            k = np.array([r[f"{side}_stiffness_n_per_m"] for r in sel])
            label = f"{name}, {side}"
            law = _attempt(
                analysis, f"eq 19 {label}", fit.stiffness_law, w, a, k, what=f"eq 19 {label}"
            )
            if law is not None:
                analysis.stiffness_laws[label] = law
                analysis.normalised[label] = fit.normalised_coefficients(law, w, a, k)
    for name in structures:
        if name in beams:
            continue
        for side in ("compression", "tension"):
            label = f"{name}, {side}"
            beam_label = f"{beams[0]}, {side}" if beams else None
            if label not in analysis.stiffness_laws or beam_label not in analysis.stiffness_laws:
                analysis.not_fitted.append(
                    f"eq 20 {label}: needs eq 19 for it and for a structure without clearance"
                )
                continue
            sel = tests_of(rows, name)
            key_a = f"{side}_penetration_m"
            analysis.joint_stiffness[label] = fit.joint_stiffness(
                analysis.stiffness_laws[label],
                analysis.stiffness_laws[beam_label],
                [r["omega"] for r in sel],
                [r[key_a] for r in sel],
            )
    jointed = [r for r in rows if r["jointed"]]
    for name in sorted({r["structure"] for r in jointed}):
        for f in sorted({r["test_frequency_hz"] for r in jointed if r["structure"] == name}):
            sel = [r for r in jointed if r["structure"] == name and r["test_frequency_hz"] == f]
            label = f"{name}, {f:g} Hz"
            law = _attempt(
                analysis,
                f"eq 21 {label}",
                fit.exponential_law,
                [r["mean_amplitude_m"] for r in sel],
                [r["energy_per_cycle_j"] for r in sel],
                what=f"eq 21 {label}",
            )
            if law is not None:
                analysis.exponential_laws[label] = law
    if jointed:
        args = (
            [r["omega"] for r in jointed],
            [r["nominal_clearance_m"] for r in jointed],
            [r["mean_amplitude_m"] for r in jointed],
            [r["energy_per_cycle_j"] for r in jointed],
        )
        analysis.dissipation_law = _attempt(analysis, "eq 22", fit.dissipation_law, *args)
        analysis.alternative_law = _attempt(analysis, "power law", fit.power_law, *args)
    return analysis
