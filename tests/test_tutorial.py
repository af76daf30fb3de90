"""docs/tutorial/csv-to-report.md: its commands run on the shipped CSV files as it says."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from clearjoint.cli import main

ROOT = Path(__file__).resolve().parents[1]
LAB = ROOT / "examples" / "lab-csv"
#: The clearance each file was made with by examples/make_lab_csv.py (the rig's truth), m.
TRUTH = {"joint-1": 0.106e-3, "joint-2": 0.196e-3}


def read_rows(path: Path) -> list[dict[str, str]]:
    with path.open(encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def test_report_on_the_lab_csv_finds_the_clearances_and_fits_eq_21(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "lab-report"
    assert main(["report", "--records", str(LAB), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    for name in ("report.html", "results.json", "results.csv", "fits.csv"):
        assert (out / name).stat().st_size > 0
    rows = read_rows(out / "results.csv")
    assert len(rows) == 6  # every shipped test identified
    for row in rows:
        truth = TRUTH[Path(row["file"]).name.split("_")[0]]
        assert float(row["clearance_m"]) == pytest.approx(truth, rel=0.02)
    fitted = {(row["law"], row["group"]) for row in read_rows(out / "fits.csv")}
    assert ("eq 21", "joint-1, 40 Hz") in fitted
    # Six files of two joints and no bare beam cannot test what needs eq 20 (a structure
    # without clearance) or the model's exact cycles (the speed claim): n/a, not NO, while
    # k_c > k_t, which both joints' slopes can test, gets a verdict.
    findings = {f["finding"]: f for f in json.loads((out / "results.json").read_text())["findings"]}
    for name in ("k_dj rises with A", "the fitted law is faster than integration"):
        assert findings[name]["reproduced"] is False
        assert findings[name]["why"].startswith("Not testable with these data"), findings[name]
        assert f"n/a  model      {name}" in printed
    assert not findings["k_c > k_t"]["why"].startswith("Not testable")
    assert "<td>n/a</td>" in (out / "report.html").read_text(encoding="utf-8")


def test_identify_step_prints_what_the_page_says_and_finds_the_clearances(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Step 2 of the page: `clearjoint identify examples/lab-csv/*.csv --out lab-results.csv`."""
    out = tmp_path / "lab-results.csv"
    files = sorted(str(path) for path in LAB.glob("*.csv"))
    assert main(["identify", *files, "--out", str(out), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "identified 6 of 6 records (6 flagged, see the flag and flag_reason columns)" in printed
    page = (ROOT / "docs" / "tutorial" / "csv-to-report.md").read_text(encoding="utf-8")
    assert "identified 6 of 6 records (6 flagged, see the flag and flag_reason columns)" in page
    rows = read_rows(out)
    assert len(rows) == 6
    for row in rows:
        truth = TRUTH[Path(row["file"]).name.split("_")[0]]
        assert float(row["clearance_m"]) == pytest.approx(truth, rel=0.005)
