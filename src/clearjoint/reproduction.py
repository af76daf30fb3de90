"""The paper's study from records to a report: ``reproduce`` and ``report_records``.

``reproduce`` runs the whole study on the virtual rig's default campaign, and a control
run of the same campaign with the rig's installation sensitivity off, so the findings
table can tell what the model explains from what the rig was given; ``report_records``
runs the same analysis on a folder of a user's own records (its control: the same
records with each side's contact slope frozen). Each only calls the layers below in
order: records (rig or files) -> identify -> analysis (eq 19-22) -> verification ->
findings -> figures -> report (rendering). MODEL.md sections 3 and 4.
"""

from __future__ import annotations

import csv
import tempfile
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from clearjoint.analysis import Analysis, analyse
from clearjoint.checks import refuse_to_overwrite
from clearjoint.figures import identification_accuracy_figure, report_figures
from clearjoint.findings import findings_table, law_timing
from clearjoint.identify import identify_files
from clearjoint.records import RecordError, is_record_file, record_suffixes
from clearjoint.report import Study, write_report
from clearjoint.rig import JOURNAL_NAME, Campaign, load_campaign, run_campaign
from clearjoint.verification import identification_accuracy, model_checks, stiffness_study

Progress = Callable[[str], None]


def _record_files(folder: Path) -> list[str]:
    return sorted(
        str(p)
        for p in folder.iterdir()
        if p.is_file() and is_record_file(p) and p.name != "manifest.csv"
    )


def _identified_clearances(analysis: Analysis) -> list[float]:
    """Each jointed structure's median identified clearance, m."""
    jointed = sorted({r["structure"] for r in analysis.rows if r["jointed"]})
    return [
        float(np.median([r["clearance_m"] for r in analysis.rows if r["structure"] == name]))
        for name in jointed
    ]


def report_records(
    folder: Path,
    out_dir: Path,
    *,
    force: bool = False,
    progress: Progress | None = None,
    warn: Progress | None = None,
    jobs: int = 1,
    files_done: Callable[[int, int], Any] | None = None,
) -> list[Path]:
    """Identify every record in ``folder``, fit the laws and write the report to ``out_dir``.

    The records are identified by ``jobs`` processes (:func:`clearjoint.identify.identify_files`,
    the same results as one), which call ``files_done(done, total)`` after each file.

    The identification's warnings (a force-controlled record without a mass, with how to
    add it) go to ``warn`` one line each, and onto the report's page and results.json.

    The findings' control is the same analysis with each side's contact slope frozen at
    its structure's median (no rig can be re-run without its installation effects).
    Fig. 12 is drawn for the identified clearances.
    """
    say = progress or (lambda _m: None)
    folder = Path(folder)
    files = _record_files(folder)
    if not files:
        endings = ", ".join(record_suffixes())
        raise RecordError(f"{folder}: no record files ({endings}) in it")
    refuse_to_overwrite([Path(out_dir) / n for n in ("report.html", "results.json")], force=force)
    say(f"identifying {len(files)} records")
    results, failures = identify_files(files, jobs=jobs, progress=files_done)
    if not results:
        from clearjoint.identify import IdentificationError

        raise IdentificationError(f"{folder}: no record could be identified")
    notes = [w for _, ident in results for w in ident.warnings]
    for note in notes:
        (warn or (lambda _m: None))(note)
    say("fitting the laws")
    analysis = analyse(results, failures)
    control = analyse(results, failures, frozen_slopes=True)
    findings = findings_table(analysis, control, control_name="frozen contact slopes")
    say("drawing the figures")
    clearances = _identified_clearances(analysis)
    curves = stiffness_study(clearances, max_amplitude=5.0 * max(clearances)) if clearances else []
    figures = report_figures(analysis, None, curves, measured=True)
    study = Study(
        title=f"clearjoint report: {folder.name}",
        what_was_run=[
            f"clearjoint report --records {folder.name}: {len(files)} record files, "
            f"{len(analysis.rows)} identified and used, {len(analysis.failures)} not used.",
        ],
        analysis=analysis,
        findings=findings,
        figures=figures,
        records_folder=folder,
        control="the same records with each side's contact slope frozen at its median",
        control_analysis=control,
        warnings=notes,
    )
    return write_report(Path(out_dir), study, force=force)


def without_installation_sensitivity(campaign: Campaign) -> Campaign:
    """The same campaign with the rig's beam frequency and amplitude sensitivity set to 0."""
    rig = replace(campaign.rig, frequency_sensitivity=0.0, amplitude_sensitivity=0.0)
    return replace(campaign, rig=rig)


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
    every record is identified; eq 19-22 are fitted; a control run of the same campaign
    without the rig's installation sensitivity (in a temporary folder; the same records
    when the sensitivity is already off) decides each finding's source; the figures and
    the report follow, with the identification checked against the rig's truth and the
    dissipation model of section 2 set against the exact cycles. The rig's tests run
    over ``jobs`` processes, or on ``executor`` (an Executor or a Dask client whose
    workers see ``out_dir``: clearjoint.parallel; the control run's records then go to
    a temporary folder inside ``out_dir``, removed after). A run interrupted before the
    report is written leaves its finished records: the next run into ``out_dir`` keeps
    them and simulates only the rest (``rig.run_campaign``).
    """
    say = progress or (lambda _m: None)
    out_dir = Path(out_dir)
    refuse_to_overwrite([out_dir / n for n in ("report.html", "results.json")], force=force)
    campaign = load_campaign(campaign_path)
    say(f"virtual rig: {len(campaign.tests)} tests")
    # an interrupted run's records are kept (resumed, not refused) until the report is written
    manifest = run_campaign(
        campaign, out_dir / "records", jobs=jobs, force=force, executor=executor, keep_journal=True
    )
    with manifest.open() as handle:
        truth = {row["file"]: row for row in csv.DictReader(handle)}
    say("identifying the records")
    files = [str(manifest.parent / name) for name in truth]
    results, failures = identify_files(files)
    say("fitting the laws")
    analysis = analyse(results, failures)
    rig = campaign.rig
    if rig.frequency_sensitivity == 0.0 and rig.amplitude_sensitivity == 0.0:
        control, control_text = analysis, "the same records: the sensitivity is already off"
    else:
        say("control run: the same campaign without the installation sensitivity")
        # on an executor the workers write the records: in out_dir, which they see
        where = out_dir if executor is not None else None
        with tempfile.TemporaryDirectory(prefix="clearjoint-control-", dir=where) as folder:
            control_manifest = run_campaign(
                without_installation_sensitivity(campaign),
                Path(folder),
                jobs=jobs,
                executor=executor,
            )
            with control_manifest.open() as handle:
                names = [row["file"] for row in csv.DictReader(handle)]
            control = analyse(*identify_files([str(Path(folder) / n) for n in names]))
        control_text = (
            "the same campaign re-run with the rig's beam frequency and amplitude sensitivity "
            f"set to 0 (it was {rig.frequency_sensitivity:g} per 100 Hz and "
            f"{rig.amplitude_sensitivity:g} per 50 µm)"
        )
    accuracy, worst = identification_accuracy(analysis, truth)
    say("the section-2 model against the exact cycles")
    model_energy, comparisons = model_checks(campaign, analysis)
    timing = law_timing(
        analysis,
        [c["integration_s"] for c in comparisons],
        [c["integrated_j"] for c in comparisons],
        [c["file"] for c in comparisons],
    )
    findings = findings_table(analysis, control, control_name="control run", timing=timing)
    say("drawing the figures")
    figures = report_figures(analysis, model_energy, stiffness_study(), measured=False)
    source = campaign_path.name if campaign_path else "the default campaign"
    study = Study(
        title="clearjoint: reproduction of the clearance-joint study",
        what_was_run=[
            f"clearjoint reproduce: {source} on the virtual rig, {len(campaign.tests)} tests "
            f"({len(campaign.structures)} structures x {len(campaign.frequencies)} frequencies "
            f"x {len(campaign.force_amplitudes)} forces), identified from its records "
            f"({len(analysis.rows)} used), plus a control run: {control_text}.",
        ],
        analysis=analysis,
        findings=findings,
        figures=figures,
        records_folder=out_dir / "records",
        truth_figures={
            "Identification against the rig's truth: relative error of every test": (
                identification_accuracy_figure(accuracy)
            )
        },
        accuracy=accuracy,
        worst=worst,
        comparisons=comparisons,
        control=control_text,
        control_analysis=control,
        timing=timing,
    )
    written = write_report(out_dir, study, force=force)
    (out_dir / "records" / JOURNAL_NAME).unlink(missing_ok=True)
    return written
