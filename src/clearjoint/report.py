"""The paper's study from records to a report: identification, fitted laws, figures, HTML.

``reproduce`` runs the whole study on the virtual rig's default campaign;
``report_records`` runs the same analysis on a folder of a user's own records.
Both write one self-contained HTML file (figures embedded, no external
resources), ``results.json`` with every number, ``results.csv`` (one row per
identified record) and ``fits.csv`` (every fitted coefficient with its standard
error). MODEL.md section 3 and 4.
"""

from __future__ import annotations

import base64
import csv
import html
import io
import json
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from clearjoint import fit, stiffness
from clearjoint._checks import refuse_to_overwrite
from clearjoint.contact import HertzValidityWarning
from clearjoint.dissipation import compare, energies
from clearjoint.figures import (
    Curve,
    EnergyLawPanel,
    StiffnessPanel,
    coefficient_bars_figure,
    displacement_stages_figure,
    energy_law_figure,
    law_versus_measured_figure,
    stiffness_coefficient_figure,
    stiffness_panels_figure,
)
from clearjoint.identify import Identification, identify_files
from clearjoint.joint import Friction, Joint
from clearjoint.records import Record
from clearjoint.simulate import SteadyState, steady_state

Progress = Callable[[str], None]

#: The paper's two joints (c = 0.106 mm and 0.196 mm).
PAPER_CLEARANCES: tuple[float, ...] = (0.106e-3, 0.196e-3)

#: What the study assumes, stated in every report.
ASSUMPTIONS: tuple[str, ...] = (
    "Equations as rebuilt in MODEL.md from the paper's surviving text (its equations were lost).",
    "Eq 7 uses the dynamic stiffness k_d(A) as the paper's 'static stiffness' k, with the viscous"
    " coefficient held fixed.",
    "Eq 19 is linear in frequency and displacement amplitude A (the amplitude beyond the gap edge"
    " on that side), as the paper's coefficient names say; Fig. 9's normalisation is"
    " a1 mean(w)/mean(k) and a2 mean(A)/mean(k).",
    "Eq 20 puts the non-jointed structure and the joint in series, k_dj = k_d k_dn/(k_dn - k_d),"
    " with k_dn from the non-jointed eq 19 law at the same w and A.",
    "Eq 21 and 22 use Abar = X - c/2 and are fitted on ln E; eq 22 is compared with a power law"
    " by AIC. With only two clearances the law's linearity in c cannot be tested.",
    "Sliding friction acts over the whole path; contact friction on the pin is evaluated along"
    " the motion without feedback on it.",
    "The virtual rig's dimensions (the paper's Fig. 6 was lost) are in docs/rig.md.",
)


# ---- the analysis -------------------------------------------------------------------------


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


def _tests_of(rows: list[dict[str, Any]], name: str) -> list[dict[str, Any]]:
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
        sel = _tests_of(rows, name)
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
            sel = _tests_of(rows, name)
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


# ---- figures ------------------------------------------------------------------------------


def _png(fig: Figure) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    return buffer.getvalue()


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
        damping_ratio=0.01,
        restitution=0.8,
        friction=Friction(0.2, 300.0),
        samples_per_period=512,
    )


def _figures(analysis: Analysis, model_energy: Sequence[float] | None) -> dict[str, bytes]:
    rows = analysis.rows
    out: dict[str, bytes] = {}
    # Fig. 7: the first jointed record with its stages
    for record, ident in analysis.identifications:
        if ident.model != "line":
            first = ident.cycles[-3] if len(ident.cycles) >= 3 else ident.cycles[0]
            span = slice(first.start, ident.cycles[-1].stop)
            runs = [
                r
                for r in ident.stage_runs(record.time)
                if r[2] >= record.time[span.start] and r[1] <= record.time[span.stop - 1]
            ]
            out[f"Fig. 7: stages of {Path(ident.source).name}"] = _png(
                displacement_stages_figure(record.time[span], record.displacement[span], runs)
            )
            break
    panels = []
    for label, law in analysis.stiffness_laws.items():
        name, side = label.rsplit(", ", 1)
        sel = _tests_of(rows, name)
        key_a = f"{side}_penetration_m" if sel and sel[0]["jointed"] else "amplitude_m"
        freq = np.array([r["test_frequency_hz"] for r in sel])
        amp = np.array([r[key_a] for r in sel])
        k = np.array([r[f"{side}_stiffness_n_per_m"] for r in sel])
        grid = np.linspace(amp.min(), amp.max(), 20)
        lines = {
            f: (grid, fit.predict(law, 2 * math.pi * f * np.ones_like(grid), grid))
            for f in sorted(set(freq.tolist()))
        }
        panels.append(StiffnessPanel(label, freq, amp, k, lines))
    if panels:
        out["Fig. 8: stiffness with the eq 19 planes"] = _png(
            stiffness_panels_figure(panels, ylabel="stiffness (MN/m)")
        )
    if analysis.normalised:
        labels = list(analysis.normalised)
        out["Fig. 9: normalised eq 19 coefficients"] = _png(
            coefficient_bars_figure(
                labels,
                [v[0] for v in analysis.normalised.values()],
                [v[1] for v in analysis.normalised.values()],
            )
        )
    panels = []
    for label, js in analysis.joint_stiffness.items():
        freq = js.omega / (2 * math.pi)
        panels.append(StiffnessPanel(label, freq, js.amplitude, js.value, {}, js.error))
    if panels:
        out["Fig. 10: the joint's own stiffness, eq 20"] = _png(
            stiffness_panels_figure(panels, ylabel="joint stiffness k_dj (MN/m)")
        )
    energy_panels = []
    for name in sorted({r["structure"] for r in rows if r["jointed"]}):
        sel = _tests_of(rows, name)
        freq = np.array([r["test_frequency_hz"] for r in sel])
        amp = np.array([r["mean_amplitude_m"] for r in sel])
        energy = np.array([r["energy_per_cycle_j"] for r in sel])
        curves = {}
        for f in sorted(set(freq.tolist())):
            exponential = analysis.exponential_laws.get(f"{name}, {f:g} Hz")
            if exponential is not None:
                grid = np.linspace(amp[freq == f].min(), amp[freq == f].max(), 20)
                curves[f] = (grid, np.exp(exponential.values[0] + exponential.values[1] * grid))
        energy_panels.append(EnergyLawPanel(name, freq, amp, energy, curves))
    if energy_panels:
        out["Fig. 11: energy per cycle with the eq 21 laws"] = _png(
            energy_law_figure(energy_panels)
        )
    out["Fig. 12: stiffness coefficient c_d against amplitude"] = _png(
        stiffness_coefficient_figure(stiffness_study())
    )
    general = analysis.dissipation_law
    if general is not None:
        jointed = [r for r in rows if r["jointed"]]
        measured = np.array([r["energy_per_cycle_j"] for r in jointed])
        predicted = fit.evaluate_dissipation_law(
            general,
            [r["omega"] for r in jointed],
            [r["nominal_clearance_m"] for r in jointed],
            [r["mean_amplitude_m"] for r in jointed],
        )
        model = np.array(model_energy) if model_energy is not None else None
        out["Fig. 13: eq 22 and the section-2 model against the measured energy"] = _png(
            law_versus_measured_figure(
                measured, predicted, model, np.array([r["structure"] for r in jointed])
            )
        )
    return out


# ---- writing ------------------------------------------------------------------------------


def _fit_rows(analysis: Analysis) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    groups: list[tuple[str, dict[str, fit.LinearFit]]] = [
        ("eq 19", analysis.stiffness_laws),
        ("eq 21", analysis.exponential_laws),
    ]
    for law_name, single in (
        ("eq 22", analysis.dissipation_law),
        ("power law", analysis.alternative_law),
    ):
        if single is not None:
            groups.append((law_name, {"all jointed tests": single}))
    for law_name, laws in groups:
        for label, law in laws.items():
            for row in law.table():
                out.append(
                    {
                        "law": law_name,
                        "group": label,
                        **row,
                        "r_squared": law.r_squared,
                        "n": law.n,
                        "aic": law.aic,
                    }
                )
    return out


def _html_table(rows: list[dict[str, Any]], columns: Sequence[str]) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in columns)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(_fmt(row.get(c)))}</td>" for c in columns) + "</tr>"
        for row in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _items(values: Sequence[str]) -> str:
    return "".join(f"<li>{html.escape(v)}</li>" for v in values)


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.4g}"
    return "" if value is None else str(value)


def _html(analysis: Analysis, figures: dict[str, bytes], extra: dict[str, str], title: str) -> str:
    images = "".join(
        f'<figure><img alt="{html.escape(name)}" src="data:image/png;base64,'
        f'{base64.b64encode(data).decode("ascii")}"><figcaption>{html.escape(name)}'
        "</figcaption></figure>"
        for name, data in figures.items()
    )
    fits = _html_table(
        _fit_rows(analysis),
        ("law", "group", "name", "value", "std_error", "unit", "r_squared", "n"),
    )
    tests = _html_table(
        analysis.rows,
        (
            "file",
            "structure",
            "frequency_hz",
            "amplitude_m",
            "clearance_m",
            "clearance_m_std",
            "compression_stiffness_n_per_m",
            "tension_stiffness_n_per_m",
            "friction_force_n",
            "energy_per_cycle_j",
            "energy_per_cycle_j_std",
            "cycles_used",
            "model",
        ),
    )
    comparison = ""
    if analysis.dissipation_law is not None and analysis.alternative_law is not None:
        better = (
            "Eq 22"
            if analysis.dissipation_law.aic <= analysis.alternative_law.aic
            else "The power law"
        )
        comparison = (
            f"<p>By AIC (lower is better), eq 22: {analysis.dissipation_law.aic:.1f} "
            f"(R<sup>2</sup> {analysis.dissipation_law.r_squared:.4f}); the power law "
            f"ln E = g0 + g1 ln w + g2 ln A + g3 c: {analysis.alternative_law.aic:.1f} "
            f"(R<sup>2</sup> {analysis.alternative_law.r_squared:.4f}). {better} is preferred."
            "</p>"
        )
    joint_rows = []
    for label, js in analysis.joint_stiffness.items():
        for w, a, v, e in zip(js.omega, js.amplitude, js.value, js.error, strict=True):
            joint_rows.append(
                {
                    "group": label,
                    "frequency_hz": w / (2 * math.pi),
                    "amplitude_m": a,
                    "k_dj_n_per_m": v,
                    "std_error": e,
                }
            )
    joint = _html_table(
        joint_rows, ("group", "frequency_hz", "amplitude_m", "k_dj_n_per_m", "std_error")
    )
    sections = "".join(f"<h2>{html.escape(k)}</h2>{v}" for k, v in extra.items())
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>body{{font-family:sans-serif;max-width:70em;margin:2em auto;line-height:1.4}}
table{{border-collapse:collapse;font-size:0.85em;margin:1em 0;display:block;overflow-x:auto}}
td,th{{border:1px solid #999;padding:0.15em 0.4em}}img{{max-width:100%}}</style>
</head><body>
<h1>{html.escape(title)}</h1>
<p>Li et al., Shock and Vibration (2013), doi:10.1155/2013/583030, reproduced with clearjoint;
equations as rebuilt in MODEL.md.</p>
<h2>Figures</h2>{images}
<h2>Fitted coefficients (eq 19, 21, 22) with standard errors</h2>{fits}{comparison}
<h2>The joint's own stiffness (eq 20)</h2>{joint}
<h2>Laws not fitted</h2><ul>{_items(analysis.not_fitted) or "<li>none</li>"}</ul>
{sections}
<h2>Identified tests</h2>{tests}
<h2>Records not used</h2><ul>{_items(analysis.failures) or "<li>none</li>"}</ul>
<h2>What was assumed</h2><ul>{_items(ASSUMPTIONS)}</ul>
</body></html>
"""


def _write(
    out_dir: Path,
    analysis: Analysis,
    figures: dict[str, bytes],
    extra_html: dict[str, str],
    extra_json: dict[str, Any],
    title: str,
    force: bool,
) -> list[Path]:
    targets = {
        name: out_dir / name for name in ("report.html", "results.json", "results.csv", "fits.csv")
    }
    refuse_to_overwrite(targets.values(), force=force)
    out_dir.mkdir(parents=True, exist_ok=True)
    targets["report.html"].write_text(_html(analysis, figures, extra_html, title), encoding="utf-8")
    fits_rows = _fit_rows(analysis)
    payload = {
        "tests": analysis.rows,
        "fits": fits_rows,
        "joint_stiffness": {
            label: {
                "frequency_hz": (js.omega / (2 * math.pi)).tolist(),
                "amplitude_m": js.amplitude.tolist(),
                "k_dj_n_per_m": js.value.tolist(),
                "std_error": js.error.tolist(),
            }
            for label, js in analysis.joint_stiffness.items()
        },
        "normalised_coefficients": {k: list(v) for k, v in analysis.normalised.items()},
        "not_fitted": analysis.not_fitted,
        "records_not_used": analysis.failures,
        "assumptions": list(ASSUMPTIONS),
        **extra_json,
    }
    targets["results.json"].write_text(
        json.dumps(payload, indent=1, default=_json_default), encoding="utf-8"
    )
    for name, rows in (("results.csv", analysis.rows), ("fits.csv", fits_rows)):
        with targets[name].open("w", newline="", encoding="utf-8") as handle:
            if rows:
                writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
                writer.writeheader()
                writer.writerows(rows)
    return list(targets.values())


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON: {value!r}")


# ---- the two entry points -----------------------------------------------------------------


def report_records(
    folder: Path, out_dir: Path, *, force: bool = False, progress: Progress | None = None
) -> list[Path]:
    """Identify every record in ``folder``, fit the laws and write the report to ``out_dir``."""
    say = progress or (lambda _m: None)
    folder = Path(folder)
    files = sorted(
        str(p)
        for p in folder.iterdir()
        if p.is_file()
        and p.suffix.lower() in (".nc", ".csv", ".json", ".h5")
        and p.name != "manifest.csv"
    )
    if not files:
        from clearjoint.records import RecordError

        raise RecordError(f"{folder}: no record files (.nc, .csv, .json) in it")
    say(f"identifying {len(files)} records")
    results, failures = identify_files(files)
    if not results:
        from clearjoint.identify import IdentificationError

        raise IdentificationError(f"{folder}: no record could be identified")
    say("fitting the laws")
    analysis = analyse(results, failures)
    say("drawing the figures")
    figures = _figures(analysis, None)
    return _write(
        Path(out_dir), analysis, figures, {}, {}, f"clearjoint report: {folder.name}", force
    )


def reproduce(
    out_dir: Path,
    *,
    force: bool = False,
    progress: Progress | None = None,
    campaign_path: Path | None = None,
    jobs: int | None = None,
    executor: Any = None,
) -> list[Path]:
    """Run the paper's whole study on the virtual rig and write the report into ``out_dir``.

    The default campaign (or ``campaign_path``) is simulated into ``out_dir/records``;
    every record is identified; eq 19-22 are fitted; the figures and the report follow,
    with the identification checked against the rig's truth and the dissipation model
    of section 2 set against the exact cycles. The rig's tests run over ``jobs``
    processes, or on ``executor`` (an Executor or a Dask client: clearjoint.parallel).
    """
    from clearjoint.rig import load_campaign, run_campaign, structure_under_test

    say = progress or (lambda _m: None)
    out_dir = Path(out_dir)
    refuse_to_overwrite([out_dir / n for n in ("report.html", "results.json")], force=force)
    campaign = load_campaign(campaign_path)
    say(f"virtual rig: {len(campaign.tests)} tests")
    manifest = run_campaign(
        campaign, out_dir / "records", jobs=jobs, force=force, executor=executor
    )
    with manifest.open() as handle:
        truth = {row["file"]: row for row in csv.DictReader(handle)}
    say("identifying the records")
    files = [str(manifest.parent / name) for name in truth]
    results, failures = identify_files(files)
    say("fitting the laws")
    analysis = analyse(results, failures)
    # identification against the truth
    accuracy = []
    for row in analysis.rows:
        t = truth[Path(row["file"]).name]
        k0 = float(t["gap_stiffness_n_per_m"])
        entry = {
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
    say("the section-2 model against the exact cycles")
    model_energy, comparisons = _model_checks(campaign, analysis, structure_under_test)
    say("drawing the figures")
    figures = _figures(analysis, model_energy)
    worst = {
        key: max(abs(a[key]) for a in accuracy if key in a)
        for key in (
            "clearance_error",
            "compression_stiffness_error",
            "tension_stiffness_error",
            "energy_error",
        )
    }
    extra_html = {
        "Identification against the rig's truth": (
            "<p>Largest relative errors over all tests: "
            + ", ".join(f"{k.replace('_', ' ')} {v:.2%}" for k, v in worst.items())
            + ". Contact stiffness is compared with k0 + k_s, the slope a record shows.</p>"
        ),
        "Dissipation: closed form (section 2) against the exact cycle": (
            "<p>The closed forms on the free cycle at each test's penetration, against the "
            "energy integrated over the exact steady cycle (the simulator's ledger); "
            "see docs/dissipation.md for where the closed form holds.</p>"
            + _html_table(
                comparisons, ("file", "penetration_m", "closed_total_j", "exact_total_j", "gap")
            )
        ),
    }
    return _write(
        out_dir,
        analysis,
        figures,
        extra_html,
        {
            "identification_accuracy": accuracy,
            "worst_errors": worst,
            "model_comparison": comparisons,
        },
        "clearjoint: reproduction of the clearance-joint study",
        force,
    )


def _model_checks(
    campaign: Any, analysis: Analysis, structure_under_test: Any
) -> tuple[list[float], list[dict[str, Any]]]:
    """Section 2's closed-form energy at each jointed test, and compare() on a few tests."""
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
            losses = {
                "friction": rig.bearing_friction,
                "restitution": rig.restitution,
                "damping_ratio": rig.damping_ratio,
                "pin": pin,
                "contact_friction_coefficient": rig.contact_friction_coefficient,
            }
            a = max(row["compression_penetration_m"], 0.0)
            model.append(float(energies(joint, a, **losses)["total_j"]))
            if n % 10 == 0:
                result = compare(
                    joint,
                    spec.force_amplitude,
                    2 * math.pi * spec.frequency_hz,
                    samples_per_period=256,
                    **losses,
                )
                comparisons.append(
                    {
                        "file": Path(row["file"]).name,
                        "penetration_m": result.penetration,
                        "closed_total_j": result.closed["total_j"],
                        "exact_total_j": result.exact["total_j"],
                        "gap": result.gap["total_j"],
                    }
                )
    return model, comparisons
