"""Render a study to files: report.html, results.json, results.csv and fits.csv.

No analysis and no physics here: :func:`write_report` takes an
:class:`~clearjoint.analysis.Analysis`, the figures (``figures.report_figures``) and
any extra sections, and writes one self-contained HTML file (figures embedded, no
external resources), ``results.json`` with every number, ``results.csv`` (one row per
identified record) and ``fits.csv`` (every fitted coefficient with its standard error).
Files keep SI with the unit in each column's name. MODEL.md section 4.
"""

from __future__ import annotations

import base64
import csv
import html
import io
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from clearjoint import fit
from clearjoint._checks import refuse_to_overwrite
from clearjoint.analysis import Analysis

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


def _png(fig: Figure) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    return buffer.getvalue()


# ---- writing ------------------------------------------------------------------------------


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


def html_table(rows: list[dict[str, Any]], columns: Sequence[str]) -> str:
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
    fits = html_table(
        _fit_rows(analysis),
        ("law", "group", "name", "value", "std_error", "unit", "r_squared", "n"),
    )
    tests = html_table(
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
    joint = html_table(
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


def write_report(
    out_dir: Path,
    analysis: Analysis,
    figures: dict[str, Figure],
    extra_html: dict[str, str],
    extra_json: dict[str, Any],
    title: str,
    force: bool,
) -> list[Path]:
    """Write report.html, results.json, results.csv and fits.csv into ``out_dir``; return them.

    ``extra_html`` maps a section title to its HTML, ``extra_json`` adds keys to
    results.json. Nothing is overwritten unless ``force``.
    """
    targets = {
        name: out_dir / name for name in ("report.html", "results.json", "results.csv", "fits.csv")
    }
    refuse_to_overwrite(targets.values(), force=force)
    out_dir.mkdir(parents=True, exist_ok=True)
    images = {caption: _png(fig) for caption, fig in figures.items()}
    targets["report.html"].write_text(_html(analysis, images, extra_html, title), encoding="utf-8")
    fits_rows = _fit_rows(analysis)
    payload = {
        "tests": analysis.rows,
        "fits": fits_rows,
        "joint_stiffness": _joint_json(analysis.joint_stiffness),
        "contact_joint_stiffness": _joint_json(analysis.contact_joint_stiffness),
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
