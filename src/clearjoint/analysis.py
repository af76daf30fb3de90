"""The analysis of a record set: one row per identified test and the fitted laws (eq 19-22).

MODEL.md section 3. :func:`analyse` takes identified records and returns an
:class:`Analysis`: the tests as rows (SI, units in the column names), each with the
per-side dynamic stiffness k_d,s of MODEL.md section 3 (:func:`side_dynamic_stiffness`,
from the identified contact slopes, penetrations and clearance with section 1's exact
times); eq 19 on k_d,s for each structure and side (and, apart, on the contact slopes),
Fig. 9's normalised coefficients, eq 20 for each jointed structure against the
structure without clearance, eq 21 for each joint and frequency, and eq 22 over all
jointed tests twice: with A = Abar = X - c/2 and with A = X (with the power-law
alternative). A law that cannot be fitted says why in ``not_fitted``. No rendering
here: report.py draws and writes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from clearjoint import fit
from clearjoint.errors import ParameterError
from clearjoint.identify import Identification
from clearjoint.joint import Joint
from clearjoint.records import Record
from clearjoint.stiffness import free_orbit

FloatArray = NDArray[np.float64]

#: The two sides of a joint and the row keys of their contact slope and penetration.
SIDES = ("compression", "tension")


@dataclass
class Analysis:
    """Identified tests, the fitted laws, and the reasons for any law not fitted."""

    rows: list[dict[str, Any]]
    identifications: list[tuple[Record, Identification]]
    failures: list[str]
    stiffness_laws: dict[str, fit.LinearFit] = field(default_factory=dict)
    normalised: dict[str, tuple[float, float]] = field(default_factory=dict)
    joint_stiffness: dict[str, fit.JointStiffness] = field(default_factory=dict)
    contact_laws: dict[str, fit.LinearFit] = field(default_factory=dict)
    contact_joint_stiffness: dict[str, fit.JointStiffness] = field(default_factory=dict)
    exponential_laws: dict[str, fit.LinearFit] = field(default_factory=dict)
    dissipation_law: fit.LinearFit | None = None
    dissipation_law_total: fit.LinearFit | None = None
    alternative_law: fit.LinearFit | None = None
    not_fitted: list[str] = field(default_factory=list)


def side_dynamic_stiffness(
    mass: float | None,
    clearance: float,
    compression_slope: float,
    tension_slope: float,
    gap_stiffness: float,
    compression_penetration: float,
    tension_penetration: float,
) -> tuple[float, float]:
    """Return the per-side dynamic stiffness (k_d,c, k_d,t), N/m (MODEL.md section 3).

    k_d,s = m (pi / tau_s)^2 with tau_s = t_contact,s + t_cross: side s's contact time
    and one free-play crossing of the free orbit whose penetration on side s is A_s
    (section 1's exact times; for k0 = 0, k_d,s = k_s (pi A_s / (pi A_s + c))^2). The
    gap is taken as centred on the k0 spring's rest position. The mass cancels (every
    time scales as sqrt(m)), so a record without it is computed with m = 1 kg.

    Parameters
    ----------
    mass : float or None
        Moving mass, kg.
    clearance : float
        Identified clearance c, m (0 for a structure without clearance).
    compression_slope, tension_slope : float
        The measured contact slopes k0 + k_c and k0 + k_t, N/m.
    gap_stiffness : float
        k0, N/m.
    compression_penetration, tension_penetration : float
        A_c and A_t, m.

    Returns
    -------
    (float, float)
        k_d,c and k_d,t; NaN for a side whose slope is not above k0 or whose
        penetration is not positive.
    """
    m = mass if mass else 1.0
    c = max(clearance, 0.0)
    k0 = max(gap_stiffness, 0.0)
    out = []
    for own, other, a in (
        (compression_slope, tension_slope, compression_penetration),
        (tension_slope, compression_slope, tension_penetration),
    ):
        if not (math.isfinite(a) and a > 0.0 and own > k0 and other > k0):
            out.append(math.nan)
            continue
        try:
            # side s as the compression side of a mirrored joint: its orbit at A = A_s
            joint = Joint(
                mass=m,
                clearance=c,
                compression_stiffness=own - k0,
                tension_stiffness=other - k0,
                gap_stiffness=k0,
            )
        except ParameterError:
            out.append(math.nan)
            continue
        orbit = free_orbit(joint, np.array([a]))
        tau = float(orbit.compression_time[0]) + 0.5 * float(orbit.free_play_time[0])
        out.append(m * (math.pi / tau) ** 2)
    return out[0], out[1]


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
            mass_kg=record.mass,
        )
        rows.append(row)
    return rows


def _majority_kind(
    rows: list[dict[str, Any]],
    results: list[tuple[Record, Identification]],
    failures: list[str],
) -> tuple[list[dict[str, Any]], list[tuple[Record, Identification]], list[str]]:
    """Leave out a test identified unlike most tests of its structure (a damper loop among
    straight lines, say): it is a failed identification, not a measurement of that
    structure, and it would make a structure without clearance look jointed."""
    kinds: dict[str, list[bool]] = {}
    for row in rows:
        kinds.setdefault(row["structure"], []).append(row["jointed"])
    majority = {name: 2 * sum(v) > len(v) for name, v in kinds.items()}
    keep_rows, keep_results, dropped = [], [], list(failures)
    for row, result in zip(rows, results, strict=True):
        if row["jointed"] == majority[row["structure"]] or len(kinds[row["structure"]]) < 3:
            keep_rows.append(row)
            keep_results.append(result)
        else:
            dropped.append(
                f"{row['file']}: identified as a {row['model']} loop while most tests of "
                f"{row['structure']} are {'jointed' if majority[row['structure']] else 'not'}; "
                "left out of the laws"
            )
    return keep_rows, keep_results, dropped


def _add_dynamic_stiffness(rows: list[dict[str, Any]], *, frozen_slopes: bool) -> None:
    """Add k_d,s and c_d,s = k_d,s / k_s,meas to each row (with frozen slopes: each side's
    slope is its structure's median, so k_d,s changes only through A_s and c)."""
    slopes: dict[tuple[str, str], float] = {}
    if frozen_slopes:
        for name in {r["structure"] for r in rows}:
            for side in SIDES:
                values = [r[f"{side}_stiffness_n_per_m"] for r in tests_of(rows, name)]
                slopes[name, side] = float(np.nanmedian(values))
    for row in rows:
        jointed = row["jointed"]
        k_c, k_t = (
            slopes.get((row["structure"], side), row[f"{side}_stiffness_n_per_m"]) for side in SIDES
        )
        k_dc, k_dt = side_dynamic_stiffness(
            row["mass_kg"],
            row["clearance_m"] if jointed else 0.0,
            k_c,
            k_t,
            row["gap_stiffness_n_per_m"],
            row["compression_penetration_m"] if jointed else row["amplitude_m"],
            row["tension_penetration_m"] if jointed else row["amplitude_m"],
        )
        for side, value, slope in zip(SIDES, (k_dc, k_dt), (k_c, k_t), strict=True):
            row[f"{side}_dynamic_stiffness_n_per_m"] = value
            row[f"{side}_stiffness_coefficient"] = value / slope


def tests_of(rows: list[dict[str, Any]], name: str) -> list[dict[str, Any]]:
    """A structure's tests; for a jointed one, only those whose loop showed its clearance.

    A test of a jointed structure identified as a straight line (its stages not found)
    carries no contact stiffness of the joint, so it stays out of its laws.
    """
    tests = [r for r in rows if r["structure"] == name]
    jointed = [r for r in tests if r["jointed"]]
    return jointed or tests


def side_data(
    tests: list[dict[str, Any]], side: str, column: str = "dynamic_stiffness_n_per_m"
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Return (w rad/s, A_s m, k N/m) of one side over ``tests``, where k is finite.

    ``column`` is ``"dynamic_stiffness_n_per_m"`` (k_d,s) or ``"stiffness_n_per_m"``
    (the contact slope); A_s is the penetration on that side, or X for a structure
    without clearance.
    """
    w = np.array([r["omega"] for r in tests], dtype=np.float64)
    a = np.array(
        [r[f"{side}_penetration_m"] if r["jointed"] else r["amplitude_m"] for r in tests],
        dtype=np.float64,
    )
    k = np.array([r[f"{side}_{column}"] for r in tests], dtype=np.float64)
    keep = np.isfinite(k)
    return w[keep], a[keep], k[keep]


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


def analyse(
    results: list[tuple[Record, Identification]],
    failures: list[str],
    *,
    frozen_slopes: bool = False,
) -> Analysis:
    """Return eq 19-22 fitted to identified tests (each law that cannot be fitted says why).

    With ``frozen_slopes``, k_d,s is computed with each side's contact slope held at
    its structure's median: what the clearance alone makes of the stiffness, the
    control used on records where no rig can be re-run without its installation effects.
    """
    rows = _study_rows(results)
    rows, results, failures = _majority_kind(rows, results, failures)
    _add_dynamic_stiffness(rows, frozen_slopes=frozen_slopes)
    analysis = Analysis(rows=rows, identifications=results, failures=failures)
    structures = sorted({r["structure"] for r in rows})
    beams = [s for s in structures if not any(r["jointed"] for r in rows if r["structure"] == s)]
    for column, laws, joint, tag in (
        ("dynamic_stiffness_n_per_m", analysis.stiffness_laws, analysis.joint_stiffness, ""),
        ("stiffness_n_per_m", analysis.contact_laws, analysis.contact_joint_stiffness, " slopes"),
    ):
        for name in structures:
            for side in SIDES:
                w, a, k = side_data(tests_of(rows, name), side, column)
                label = f"{name}, {side}"
                what = f"eq 19{tag} {label}"
                law = _attempt(analysis, what, fit.stiffness_law, w, a, k, what=what)
                if law is not None:
                    laws[label] = law
                    if not tag:
                        analysis.normalised[label] = fit.normalised_coefficients(law, w, a, k)
        for name in structures:
            if name in beams:
                continue
            for side in SIDES:
                label = f"{name}, {side}"
                beam_label = f"{beams[0]}, {side}" if beams else ""
                if label not in laws or beam_label not in laws:
                    analysis.not_fitted.append(
                        f"eq 20{tag} {label}: needs eq 19 for it and for a structure without "
                        "clearance"
                    )
                    continue
                w, a, _ = side_data(tests_of(rows, name), side, column)
                joint[label] = fit.joint_stiffness(laws[label], laws[beam_label], w, a)
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
        analysis.dissipation_law_total = _attempt(
            analysis,
            "eq 22 (A = X)",
            fit.dissipation_law,
            *args[:2],
            [r["amplitude_m"] for r in jointed],
            args[3],
            what="eq 22 (A = X)",
        )
    return analysis
