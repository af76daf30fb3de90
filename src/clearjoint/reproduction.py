"""The paper's study from records to a report: ``reproduce`` and ``report_records``.

``reproduce`` runs the whole study on the virtual rig's default campaign;
``report_records`` runs the same analysis on a folder of a user's own records. Each
only calls the layers below in order: records (rig or files) -> identify ->
analysis (eq 19-22) -> verification -> figures -> report (rendering). MODEL.md
sections 3 and 4.
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from pathlib import Path

from clearjoint._checks import refuse_to_overwrite
from clearjoint.analysis import analyse
from clearjoint.figures import report_figures
from clearjoint.identify import identify_files
from clearjoint.report import html_table, write_report
from clearjoint.rig import load_campaign, run_campaign
from clearjoint.verification import identification_accuracy, model_checks, stiffness_study

Progress = Callable[[str], None]


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
    figures = report_figures(analysis, None, stiffness_study())
    return write_report(
        Path(out_dir), analysis, figures, {}, {}, f"clearjoint report: {folder.name}", force
    )


def reproduce(
    out_dir: Path,
    *,
    force: bool = False,
    progress: Progress | None = None,
    campaign_path: Path | None = None,
    jobs: int | None = None,
) -> list[Path]:
    """Run the paper's whole study on the virtual rig and write the report into ``out_dir``.

    The default campaign (or ``campaign_path``) is simulated into ``out_dir/records``;
    every record is identified; eq 19-22 are fitted; the figures and the report follow,
    with the identification checked against the rig's truth and the dissipation model
    of section 2 set against the exact cycles.
    """
    say = progress or (lambda _m: None)
    out_dir = Path(out_dir)
    refuse_to_overwrite([out_dir / n for n in ("report.html", "results.json")], force=force)
    campaign = load_campaign(campaign_path)
    say(f"virtual rig: {len(campaign.tests)} tests")
    manifest = run_campaign(campaign, out_dir / "records", jobs=jobs, force=force)
    with manifest.open() as handle:
        truth = {row["file"]: row for row in csv.DictReader(handle)}
    say("identifying the records")
    files = [str(manifest.parent / name) for name in truth]
    results, failures = identify_files(files)
    say("fitting the laws")
    analysis = analyse(results, failures)
    accuracy, worst = identification_accuracy(analysis, truth)
    say("the section-2 model against the exact cycles")
    model_energy, comparisons = model_checks(campaign, analysis)
    say("drawing the figures")
    figures = report_figures(analysis, model_energy, stiffness_study())
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
            + html_table(
                comparisons, ("file", "penetration_m", "closed_total_j", "exact_total_j", "gap")
            )
        ),
    }
    return write_report(
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
