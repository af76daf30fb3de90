"""Render a study to files: report.html, results.json, results.csv and fits.csv.

No analysis and no physics here: :func:`write_report` takes a :class:`Study` (the
analysis, the findings table, the figures, and for the virtual rig the checks against
its truth) and writes one self-contained HTML file (figures embedded, no external
resources), ``results.json`` with every number, ``results.csv`` (one row per
identified record) and ``fits.csv`` (every fitted coefficient with its standard error).
The page opens with a summary: what was run, the findings table, the identification
against the truth, and what to distrust; long tables fold away in ``<details>`` and
speak engineering units (um, MN/m, mJ) with the unit in the header. Files keep SI with
the unit in each column's name. Record paths are relative to the records folder.
MODEL.md section 4.
"""

from __future__ import annotations

import base64
import csv
import html
import io
import json
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from clearjoint import fit
from clearjoint.analysis import Analysis
from clearjoint.checks import refuse_to_overwrite
from clearjoint.findings import Finding, Timing, testable

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
    "Figs. 8-10 and eq 19-20 use the per-side dynamic stiffness k_d,s = m (pi / tau_s)^2 of"
    " MODEL.md section 3 (contact time of side s plus one free-play crossing, section 1's exact"
    " times from the identified slopes, A_s and c; gap centred); the contact slopes have their"
    " own eq 19 and figure.",
    "Eq 21 and 22 are fitted on ln E with A = Abar = X - c/2; eq 22 also with A = X, and is"
    " compared with a power law by AIC. With only two clearances the law's linearity in c"
    " cannot be tested.",
    "Sliding friction acts over the whole path; contact friction on the pin is evaluated along"
    " the motion without feedback on it.",
    "The virtual rig's dimensions (the paper's Fig. 6 was lost) are in docs/rig.md.",
)


@dataclass
class Study:
    """What a report shows: the analysis, its findings and figures, and the rig's checks.

    ``accuracy``, ``worst`` and ``comparisons`` are the identification against the
    virtual rig's truth and section 2's closed form against the exact cycle (None for
    a user's records); ``truth_figures`` are drawn in the summary.
    """

    title: str
    what_was_run: list[str]
    analysis: Analysis
    findings: list[Finding]
    figures: dict[str, Figure]
    records_folder: Path
    truth_figures: dict[str, Figure] = field(default_factory=dict)
    accuracy: list[dict[str, Any]] | None = None
    worst: dict[str, float] | None = None
    comparisons: list[dict[str, Any]] | None = None
    control: str = ""
    control_analysis: Analysis | None = None
    timing: Timing | None = None
    #: warnings of the identification (a force-controlled record without a mass, ...)
    warnings: list[str] = field(default_factory=list)


def _png(fig: Figure) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    return buffer.getvalue()


# ---- tables -----------------------------------------------------------------------------------


def _fit_rows(analysis: Analysis) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    groups: list[tuple[str, dict[str, fit.LinearFit]]] = [
        ("eq 19", analysis.stiffness_laws),
        ("eq 19 slopes", analysis.contact_laws),
        ("eq 21", analysis.exponential_laws),
    ]
    for law_name, single in (
        ("eq 22", analysis.dissipation_law),
        ("eq 22 (A = X)", analysis.dissipation_law_total),
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


#: The identified tests as the page shows them: (header with unit, row key, scale).
TEST_COLUMNS: tuple[tuple[str, str, float], ...] = (
    ("file", "file", 1.0),
    ("structure", "structure", 1.0),
    ("f (Hz)", "frequency_hz", 1.0),
    ("X (µm)", "amplitude_m", 1e6),
    ("c (µm)", "clearance_m", 1e6),
    ("A_c (µm)", "compression_penetration_m", 1e6),
    ("A_t (µm)", "tension_penetration_m", 1e6),
    ("k_c,meas (MN/m)", "compression_stiffness_n_per_m", 1e-6),
    ("k_t,meas (MN/m)", "tension_stiffness_n_per_m", 1e-6),
    ("k_d,c (MN/m)", "compression_dynamic_stiffness_n_per_m", 1e-6),
    ("k_d,t (MN/m)", "tension_dynamic_stiffness_n_per_m", 1e-6),
    ("friction (N)", "friction_force_n", 1.0),
    ("E per cycle (mJ)", "energy_per_cycle_j", 1e3),
    ("cycles used", "cycles_used", 1.0),
    ("model", "model", 1.0),
    ("flag", "flag", 1.0),
    ("flag reason", "flag_reason", 1.0),
)


def html_table(
    rows: Sequence[dict[str, Any]], columns: Sequence[str | tuple[str, str, float]]
) -> str:
    """An HTML table; a column is a row key, or (header, row key, scale to the header's unit)."""
    spec = [(c, c, 1.0) if isinstance(c, str) else c for c in columns]
    head = "".join(f"<th>{html.escape(h)}</th>" for h, _, _ in spec)
    body = "".join(
        "<tr>"
        + "".join(f"<td>{html.escape(_fmt(_scaled(row.get(k), f)))}</td>" for _, k, f in spec)
        + "</tr>"
        for row in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _scaled(value: Any, factor: float) -> Any:
    if factor != 1.0 and isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value) * factor
    return value


def _items(values: Sequence[str]) -> str:
    return "".join(f"<li>{html.escape(v)}</li>" for v in values)


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.4g}"
    return "" if value is None else str(value)


def _details(summary: str, content: str, *, open_: bool = False) -> str:
    flag = " open" if open_ else ""
    return f"<details{flag}><summary>{html.escape(summary)}</summary>{content}</details>"


def _figure(caption: str, data: bytes) -> str:
    return (
        f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,'
        f'{base64.b64encode(data).decode("ascii")}"><figcaption>{html.escape(caption)}'
        "</figcaption></figure>"
    )


def _relative(path: str, folder: Path) -> str:
    try:
        return os.path.relpath(path, folder)
    except ValueError:  # another drive
        return Path(path).name


# ---- the page ---------------------------------------------------------------------------------


_CLASS = {"yes": "yes", "NO": "no", "n/a": "na"}


def _mark(f: Finding) -> str:
    """yes, NO (the data say otherwise or not clearly) or n/a (the data cannot test it)."""
    return f.verdict


def _evidence_html(evidence: str) -> str:
    """The evidence as a list: one item per run (this one, the control, the contact
    slopes), each joint and side of it on its own line."""
    runs = [run for run in re.split(r"\. (?=[A-Za-z])", evidence) if run]
    return (
        "<ul>"
        + "".join(
            "<li>" + "<br>".join(html.escape(part) for part in run.split("; ")) + "</li>"
            for run in runs
        )
        + "</ul>"
    )


def findings_html(findings: Sequence[Finding]) -> str:
    """The findings table at a glance: one line per paper finding (its verdict, the number
    it rests on with the quantity and joint named, its source); the paper's words, every
    number and the why one click away in a ``<details>``."""
    head = (
        "<tr><th>paper finding</th><th>verdict</th><th>the number it rests on</th>"
        "<th>source</th><th>details</th></tr>"
    )
    body = "".join(
        f'<tr class="{_CLASS[_mark(f)]}"><td class="finding"><b>{html.escape(f.finding)}</b></td>'
        f'<td>{_mark(f)}</td><td class="headline">{html.escape(f.headline)}</td>'
        f'<td>{html.escape(f.source)}</td><td class="more"><details><summary>why, numbers'
        f"</summary><p>Paper: {html.escape(f.paper)}.</p>"
        f"<p><i>{html.escape(f.why)}</i></p>{_evidence_html(f.evidence)}</details></td></tr>"
        for f in findings
    )
    return f'<table id="findings">{head}{body}</table>'


def distrust(study: Study) -> list[str]:
    """What a reader should not take at face value, from the study's own numbers."""
    out = []
    analysis = study.analysis
    given = [f.finding for f in study.findings if f.reproduced and f.source == "rig input"]
    if given:
        out.append(
            "Reproduced only because the test article was given it (rig input): "
            + "; ".join(given)
            + "."
        )
    missing = [f.finding for f in study.findings if not f.reproduced and testable(f)]
    if missing:
        out.append("Not reproduced (see the evidence): " + "; ".join(missing) + ".")
    untested = [f.finding for f in study.findings if not testable(f)]
    if untested:
        out.append("Not testable with these records (n/a): " + "; ".join(untested) + ".")
    poor = sorted(
        {
            f"{r['law']} {r['group']} (R^2 = {r['r_squared']:.2f})"
            for r in _fit_rows(analysis)
            if r["r_squared"] < 0.5
        }
    )
    if poor:
        out.append("Laws with R^2 below 0.5, which do not describe their data: " + "; ".join(poor))
    if analysis.not_fitted:
        out.append(f"{len(analysis.not_fitted)} law(s) could not be fitted (listed below).")
    if analysis.failures:
        out.append(f"{len(analysis.failures)} record(s) were not used (listed below).")
    if study.comparisons:
        gaps = [abs(c["gap"]) for c in study.comparisons if math.isfinite(c["gap"])]
        if gaps and max(gaps) > 0.1:
            out.append(
                f"Section 2's closed form is up to {max(gaps):.0%} off the exact cycle on these"
                " forced tests (Fig. 13's grey points): use it for trends, not for numbers."
            )
    clearances = {r["nominal_clearance_m"] for r in analysis.rows if r["jointed"]}
    if len(clearances) == 2:
        out.append(
            "With two clearances eq 22's dependence on c is a straight line through two points:"
            " its linearity in c cannot be tested."
        )
    return out


def _html(study: Study) -> str:
    analysis = study.analysis
    rows = _display_rows(analysis.rows, study.records_folder)
    figures = "".join(_figure(c, _png(f)) for c, f in study.figures.items())
    truth = ""
    if study.worst is not None:
        truth = (
            "<h3>Identification against the virtual rig's truth</h3><p>Largest relative errors "
            "over all tests: "
            + html.escape(
                ", ".join(f"{k.replace('_', ' ')} {v:.2%}" for k, v in study.worst.items())
            )
            + ". Contact stiffness is compared with k0 + k_s, the slope a record shows.</p>"
            + "".join(_figure(c, _png(f)) for c, f in study.truth_figures.items())
        )
    fits = html_table(
        _fit_rows(analysis),
        ("law", "group", "name", "value", "std_error", "unit", "r_squared", "n"),
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
    joint_rows = _joint_rows(analysis.joint_stiffness)
    joint = html_table(
        joint_rows,
        (
            "group",
            ("f (Hz)", "frequency_hz", 1.0),
            ("A_s (µm)", "amplitude_m", 1e6),
            ("k_dj (MN/m)", "k_dj_n_per_m", 1e-6),
            ("std error (MN/m)", "k_dj_std_error_n_per_m", 1e-6),
        ),
    )
    sections = [
        _details(
            f"Fitted coefficients (eq 19, 21, 22), SI units as listed ({len(_fit_rows(analysis))}"
            " rows)",
            fits + comparison,
        ),
        _details(f"The joint's own dynamic stiffness, eq 20 ({len(joint_rows)} rows)", joint),
        _details(f"Identified tests ({len(rows)})", html_table(rows, TEST_COLUMNS)),
    ]
    if study.comparisons:
        sections.append(
            _details(
                f"Dissipation: closed form (section 2) against the exact cycle "
                f"({len(study.comparisons)} tests)",
                "<p>The closed forms on the free cycle at each test's penetration, against the "
                "energy integrated over the exact steady cycle (the simulator's ledger); "
                "see docs/dissipation.md for where the closed form holds.</p>"
                + html_table(
                    study.comparisons,
                    (
                        "file",
                        ("A (µm)", "penetration_m", 1e6),
                        ("closed form (mJ)", "closed_total_j", 1e3),
                        ("exact cycle (mJ)", "exact_total_j", 1e3),
                        ("relative gap", "gap", 1.0),
                        ("integration (ms)", "integration_s", 1e3),
                    ),
                ),
            )
        )
    sections += [
        _details(
            f"Laws not fitted ({len(analysis.not_fitted)})",
            f"<ul>{_items(analysis.not_fitted) or '<li>none</li>'}</ul>",
        ),
        _details(
            f"Records not used ({len(analysis.failures)})",
            "<ul>"
            + (
                _items(
                    [f.replace(f"{study.records_folder}{os.sep}", "") for f in analysis.failures]
                )
                or "<li>none</li>"
            )
            + "</ul>",
        ),
        _details("What was assumed", f"<ul>{_items(ASSUMPTIONS)}</ul>"),
    ]
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(study.title)}</title>
<style>body{{font-family:sans-serif;max-width:72em;margin:1em auto;line-height:1.35}}
h1{{font-size:1.4em;margin:0.3em 0}}
table{{border-collapse:collapse;font-size:0.85em;margin:0.5em 0;display:block;overflow-x:auto}}
td,th{{border:1px solid #999;padding:0.15em 0.4em;vertical-align:top}}img{{max-width:100%}}
#findings{{font-size:0.8em}}#findings tr.no td:nth-child(2){{font-weight:bold}}
#findings td.finding,#findings td:nth-child(2){{white-space:nowrap}}
#findings td.more{{max-width:36em}}
#findings td.more summary{{font-weight:normal;white-space:nowrap}}
#findings ul{{margin:0.2em 0;padding-left:1.2em}}#findings p{{margin:0.2em 0}}
details{{margin:0.4em 0}}summary{{cursor:pointer;font-weight:bold}}</style>
</head><body>
<h1>{html.escape(study.title)}</h1>
<p>{_items_inline(study.what_was_run)} Paper: Li et al., Shock and Vibration (2013),
doi:10.1155/2013/583030; equations as rebuilt in MODEL.md.</p>
{_warnings_html(study.warnings)}<h2>Findings of the paper, against these data</h2>
{findings_html(study.findings)}
<p><small>Reproduced: the fitted slope has the paper's sign by more than two standard errors
(s.e.) for every joint and side; the number shown is the weakest of them, and for NO how far
it is from a trend. "details" gives the paper's words, why, and every number. Source "model":
it also holds in the control ({
        html.escape(study.control)
    }); "rig input": it was given to the test article. Every number is in
results.json (key <code>findings</code>).</small></p>
<h2>What to distrust</h2><ul>{_items(distrust(study))}</ul>
{truth}
<h2>Figures</h2>
<p>Figs. 8-10 and eq 19-20 show the per-side dynamic stiffness k_d,s of MODEL.md section 3
(contact time plus one free-play crossing, from the identified slopes, A_s and c), which
includes the clearance's softening; the contact slopes, which earlier reports showed there,
have their own figure and their own eq 19 and 20 (law "eq 19 slopes", key
<code>contact_joint_stiffness</code>).</p>{figures}
<h2>Tables</h2>{"".join(sections)}
</body></html>
"""


def _warnings_html(warnings: Sequence[str]) -> str:
    """The identification's warnings as a list under their heading (empty if none)."""
    if not warnings:
        return ""
    items = "".join(f"<li>{html.escape(w)}</li>" for w in warnings)
    return f'<h2>Warnings</h2>\n<ul class="warnings">{items}</ul>\n'


def _items_inline(values: Sequence[str]) -> str:
    return " ".join(html.escape(v) for v in values)


def _display_rows(rows: Sequence[dict[str, Any]], folder: Path) -> list[dict[str, Any]]:
    return [{**row, "file": _relative(row["file"], folder)} for row in rows]


def _joint_rows(laws: dict[str, fit.JointStiffness]) -> list[dict[str, Any]]:
    out = []
    for label, js in laws.items():
        for w, a, v, e in zip(js.omega, js.amplitude, js.value, js.error, strict=True):
            out.append(
                {
                    "group": label,
                    "frequency_hz": w / (2 * math.pi),
                    "amplitude_m": a,
                    "k_dj_n_per_m": v,
                    "k_dj_std_error_n_per_m": e,
                }
            )
    return out


# ---- writing ------------------------------------------------------------------------------


def write_report(out_dir: Path, study: Study, *, force: bool = False) -> list[Path]:
    """Write report.html, results.json, results.csv and fits.csv into ``out_dir``; return them.

    Nothing is overwritten unless ``force``.
    """
    analysis = study.analysis
    targets = {
        name: out_dir / name for name in ("report.html", "results.json", "results.csv", "fits.csv")
    }
    refuse_to_overwrite(targets.values(), force=force)
    out_dir.mkdir(parents=True, exist_ok=True)
    targets["report.html"].write_text(_html(study), encoding="utf-8")
    fits_rows = _fit_rows(analysis)
    rows = _display_rows(analysis.rows, study.records_folder)
    folder = f"{study.records_folder}{os.sep}"
    failures = [line.replace(folder, "") for line in analysis.failures]
    payload: dict[str, Any] = {
        "what_was_run": study.what_was_run,
        "warnings": study.warnings,
        "findings": [f.as_dict() for f in study.findings],
        "at_a_glance": [f.glance() for f in study.findings],
        "control": study.control,
        "tests": rows,
        "fits": fits_rows,
        "joint_stiffness": _joint_json(analysis.joint_stiffness),
        "contact_joint_stiffness": _joint_json(analysis.contact_joint_stiffness),
        "normalised_coefficients": {k: list(v) for k, v in analysis.normalised.items()},
        "not_fitted": analysis.not_fitted,
        "records_not_used": failures,
        "assumptions": list(ASSUMPTIONS),
        "distrust": distrust(study),
    }
    if study.control_analysis is not None:
        control = study.control_analysis
        payload["control_tests"] = _display_rows(control.rows, study.records_folder)
        payload["control_fits"] = _fit_rows(control)
        payload["control_joint_stiffness"] = _joint_json(control.joint_stiffness)
    if study.timing is not None:
        payload["timing"] = {
            "law_s_per_test": study.timing.law_s,
            "integration_s_per_test": study.timing.integration_s,
            "law_median_error": study.timing.median_error,
        }
    if study.accuracy is not None:
        payload["identification_accuracy"] = study.accuracy
        payload["worst_errors"] = study.worst
        payload["model_comparison"] = study.comparisons
    targets["results.json"].write_text(
        json.dumps(payload, indent=1, default=_json_default), encoding="utf-8"
    )
    for name, table in (("results.csv", rows), ("fits.csv", fits_rows)):
        with targets[name].open("w", newline="", encoding="utf-8") as handle:
            if table:
                writer = csv.DictWriter(handle, fieldnames=list(table[0]))
                writer.writeheader()
                writer.writerows(table)
    return list(targets.values())


def _joint_json(laws: dict[str, fit.JointStiffness]) -> dict[str, dict[str, list[float]]]:
    return {
        label: {
            "frequency_hz": (js.omega / (2 * math.pi)).tolist(),
            "amplitude_m": js.amplitude.tolist(),
            "k_dj_n_per_m": js.value.tolist(),
            "k_dj_std_error_n_per_m": js.error.tolist(),
        }
        for label, js in laws.items()
    }


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"not JSON: {value!r}")


#: Names that lived here before report.py was split, and where they live now.
_MOVED = {
    "reproduce": "clearjoint.reproduction",
    "report_records": "clearjoint.reproduction",
    "analyse": "clearjoint.analysis",
    "stiffness_study": "clearjoint.verification",
    "example_cycle": "clearjoint.verification",
    "PAPER_CLEARANCES": "clearjoint.verification",
}


def __getattr__(name: str) -> Any:
    """Keep ``from clearjoint.report import reproduce`` (and the other moved names) working."""
    if name in _MOVED:
        import importlib

        return getattr(importlib.import_module(_MOVED[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
