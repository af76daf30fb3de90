"""report.py and the two study commands: a small reproduction and a report on given records."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from clearjoint.cli import main

FIGURES = ("Fig. 7", "Fig. 8", "Fig. 9", "Fig. 10", "Fig. 11", "Fig. 12", "Fig. 13")
BRFD = Path(__file__).resolve().parents[2] / "shared" / "data" / "brfd"


def self_contained(page: str) -> None:
    assert "http://" not in page
    assert "https://" not in page
    for source in re.findall(r'src="([^"]+)"', page):
        assert source.startswith("data:image/png;base64,")
    assert "<link" not in page
    assert "<script" not in page


def test_reproduction_has_every_figure_and_table(reproduction: Path) -> None:
    page = (reproduction / "report.html").read_text()
    self_contained(page)
    for name in FIGURES:
        assert f"<figcaption>{name}" in page
    for text in (
        "Fitted coefficients",
        "eq 19",
        "eq 21",
        "eq 22",
        "By AIC",
        "k_dj, eq 20 on k_d,s",
        "What was assumed",
        "Identification against the rig&#x27;s truth",
        "closed form (section 2) against the exact cycle",
    ):
        assert text in page
    results = json.loads((reproduction / "results.json").read_text())
    assert len(results["tests"]) == 27
    assert results["not_fitted"] == []
    worst = results["worst_errors"]
    assert worst["clearance_error"] < 0.02
    assert worst["compression_stiffness_error"] < 0.03
    # eq 20 on the contact slopes gives back the rig's joint, 200 and 100 MN/m, within 3 %
    for label, values in results["contact_joint_stiffness"].items():
        expected = 2e8 if label.endswith("compression") else 1e8
        assert all(abs(v / expected - 1) < 0.03 for v in values["k_dj_n_per_m"]), label
    fits = (reproduction / "fits.csv").read_text()
    assert "eq 22,all jointed tests,d0" in fits
    assert (reproduction / "results.csv").exists()
    assert len(list((reproduction / "records").glob("*.nc"))) == 27


def test_reproduce_never_overwrites(reproduction: Path, capsys: pytest.CaptureFixture[str]) -> None:
    before = (reproduction / "report.html").stat().st_mtime_ns
    assert main(["reproduce", "--out", str(reproduction)]) == 2
    assert "will not overwrite" in capsys.readouterr().err
    assert (reproduction / "report.html").stat().st_mtime_ns == before


def test_report_on_a_folder_of_records(reproduction: Path, tmp_path: Path) -> None:
    out = tmp_path / "report"
    assert main(["report", "--records", str(reproduction / "records"), "--out", str(out)]) == 0
    page = (out / "report.html").read_text()
    self_contained(page)
    assert "<figcaption>Fig. 8" in page
    assert "<figcaption>Fig. 10" in page


@pytest.mark.skipif(not BRFD.exists(), reason="the shared BRFD data is not beside this clone")
def test_report_on_real_brfd_records_says_what_it_cannot_fit(tmp_path: Path) -> None:
    folder = tmp_path / "brfd"
    folder.mkdir()
    for name in (
        "0.5Hz30lbtension0.5amplitude.json",
        "0.5Hz30lbtension1.5amplitude.json",
        "1Hz30lbtension0.5amplitude.json",
        "1Hz30lbtension1.5amplitude.json",
        "2Hz0lbtension1amplitude.json",
    ):
        shutil.copy(BRFD / name, folder / name)
    out = tmp_path / "report"
    assert main(["report", "--records", str(folder), "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    assert any("eq 20" in line for line in results["not_fitted"])  # no structure without play
    assert any("2Hz0lbtension1amplitude" in line for line in results["records_not_used"])
    self_contained((out / "report.html").read_text())


def test_report_needs_records(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["report", "--records", str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    assert "no record files" in capsys.readouterr().err
