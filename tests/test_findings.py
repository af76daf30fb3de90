"""findings.py: every row of the findings table follows from the fitted numbers in results.json.

The expectations are rebuilt here from results.json's tests (and its control run's) with
an ordinary least-squares fit written in this file (numpy only), its standard errors from
the residual variance, and the issue's rule: a trend is reproduced when its slope has the
paper's sign by more than two standard errors for every joint and side; its source is
"model" only when it holds in the control too (and, for k_c > k_t, when the contact slopes
the rig was given do not already carry it).
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from clearjoint.findings import Finding

KEYS = ["finding", "paper", "reproduced", "source", "evidence", "why"]
NAMES = [
    "k_c > k_t",
    "stiffness rises with w",
    "stiffness rises with A and saturates",
    "k_dj rises with A",
    "k_dj first falls with w",
    "dissipation rises with w",
    "dissipation rises with A",
    "dissipation falls with c",
    "c_d rises with A and saturates",
    "the fitted law is faster than integration",
]


def ols(design: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients and their covariance, sigma^2 (X'X)^-1 with sigma^2 = RSS / (n - p)."""
    b, *_ = np.linalg.lstsq(design, y, rcond=None)
    r = y - design @ b
    n, p = design.shape
    return b, float(r @ r) / (n - p) * np.linalg.inv(design.T @ design)


def sign_by_two_se(g: list[float], b: np.ndarray, cov: np.ndarray, sign: int) -> bool:
    g_ = np.asarray(g, dtype=float)
    return bool(sign * (g_ @ b) > 2 * math.sqrt(g_ @ cov @ g_))


def jointed_sides(tests: list[dict[str, Any]]) -> list[tuple[list[dict[str, Any]], str]]:
    names = sorted({t["structure"] for t in tests if t["jointed"]})
    return [
        ([t for t in tests if t["structure"] == n and t["jointed"]], side)
        for n in names
        for side in ("compression", "tension")
    ]


def side_arrays(tests: list[dict[str, Any]], side: str, column: str) -> tuple[np.ndarray, ...]:
    w = np.array([t["omega"] for t in tests])
    a = np.array([t[f"{side}_penetration_m"] for t in tests])
    y = np.array([t[f"{side}_{column}"] for t in tests], dtype=float)
    keep = np.isfinite(y)
    return w[keep], a[keep], y[keep]


def k_c_above_k_t(tests: list[dict[str, Any]], column: str) -> bool:
    out = []
    for name in sorted({t["structure"] for t in tests if t["jointed"]}):
        d = np.array(
            [
                t[f"compression_{column}"] - t[f"tension_{column}"]
                for t in tests
                if t["structure"] == name and t["jointed"]
            ]
        )
        out.append(d.mean() > 2 * d.std(ddof=1) / math.sqrt(d.size))
    return all(out)


def rises_with_w(tests: list[dict[str, Any]]) -> bool:
    out = []
    for sel, side in jointed_sides(tests):
        w, a, k = side_arrays(sel, side, "dynamic_stiffness_n_per_m")
        b, cov = ols(np.column_stack((w, a, np.ones_like(w))), k)
        out.append(sign_by_two_se([1, 0, 0], b, cov, 1))
    return all(out)


def rises_and_saturates(tests: list[dict[str, Any]], column: str) -> bool:
    out = []
    for sel, side in jointed_sides(tests):
        w, a, y = side_arrays(sel, side, column)
        b, cov = ols(np.column_stack((w, a, np.ones_like(w))), y)
        q, qcov = ols(np.column_stack((np.ones_like(a), a, a * a, w)), y)
        out.append(
            sign_by_two_se([0, 1, 0], b, cov, 1) and sign_by_two_se([0, 0, 1, 0], q, qcov, -1)
        )
    return all(out)


def joint_trends(joint: dict[str, Any]) -> tuple[bool, bool]:
    """(k_dj rises with A, k_dj first falls with w), over every eq 20 group."""
    if not joint:
        return False, False
    rises, falls = [], []
    for values in joint.values():
        k = np.array(values["k_dj_n_per_m"], dtype=float)
        keep = np.isfinite(k)
        w = 2 * math.pi * np.array(values["frequency_hz"])[keep]
        a = np.array(values["amplitude_m"])[keep]
        b, cov = ols(np.column_stack((w, a, np.ones_like(w))), k[keep])
        rises.append(sign_by_two_se([0, 1, 0], b, cov, 1))
        q, qcov = ols(np.column_stack((np.ones_like(w), w, w * w, a)), k[keep])
        falls.append(sign_by_two_se([0, 1, 2 * w.min(), 0], q, qcov, -1))
    return all(rises), all(falls)


def energy_trend(tests: list[dict[str, Any]], variable: str, sign: int, amplitude: str) -> bool:
    """eq 22 by hand: ln E on (1, w, c, A, w A, c A); the slope at the tests' means."""
    jointed = [t for t in tests if t["jointed"]]
    w = np.array([t["omega"] for t in jointed])
    c = np.array([t["nominal_clearance_m"] for t in jointed])
    a = np.array([t[amplitude] for t in jointed])
    e = np.array([t["energy_per_cycle_j"] for t in jointed])
    b, cov = ols(np.column_stack((np.ones_like(w), w, c, a, w * a, c * a)), np.log(e))
    g = {
        "w": [0, 1, 0, 0, a.mean(), 0],
        "A": [0, 0, 0, 1, w.mean(), c.mean()],
        "c": [0, 0, 1, 0, 0, a.mean()],
    }[variable]
    return sign_by_two_se(g, b, cov, sign)


def expected(results: dict[str, Any]) -> dict[str, tuple[bool, bool]]:
    """Each finding's (reproduced, holds in the control), from results.json alone."""
    checks = {
        "k_c > k_t": lambda t, _j: k_c_above_k_t(t, "dynamic_stiffness_n_per_m"),
        "stiffness rises with w": lambda t, _j: rises_with_w(t),
        "stiffness rises with A and saturates": lambda t, _j: rises_and_saturates(
            t, "dynamic_stiffness_n_per_m"
        ),
        "k_dj rises with A": lambda _t, j: joint_trends(j)[0],
        "k_dj first falls with w": lambda _t, j: joint_trends(j)[1],
        "dissipation rises with w": lambda t, _j: energy_trend(t, "w", 1, "mean_amplitude_m"),
        "dissipation rises with A": lambda t, _j: energy_trend(t, "A", 1, "mean_amplitude_m"),
        "dissipation falls with c": lambda t, _j: energy_trend(t, "c", -1, "amplitude_m"),
        "c_d rises with A and saturates": lambda t, _j: rises_and_saturates(
            t, "stiffness_coefficient"
        ),
    }
    out = {}
    for name, check in checks.items():
        main = check(results["tests"], results["joint_stiffness"])
        control = check(results["control_tests"], results["control_joint_stiffness"])
        out[name] = (main, control)
    return out


def check_table(results: dict[str, Any]) -> None:
    rows = results["findings"]
    assert [r["finding"] for r in rows] == NAMES
    for row in rows:
        assert list(row) == KEYS
        assert row["source"] in ("model", "rig input")
        assert row["evidence"]
        assert row["why"]
    by_name = {r["finding"]: r for r in rows}
    slopes_given = k_c_above_k_t(results["tests"], "stiffness_n_per_m")
    for name, (main, control) in expected(results).items():
        row = by_name[name]
        assert row["reproduced"] is main, name
        given = name == "k_c > k_t" and slopes_given
        source = "rig input" if main and (not control or given) else "model"
        assert row["source"] == source, name


def test_every_row_follows_from_the_fitted_numbers(reproduction: Path) -> None:
    results = json.loads((reproduction / "results.json").read_text())
    check_table(results)
    # the rig's joint was given k_c = 200 MN/m > k_t = 100 MN/m: its slopes say so
    assert k_c_above_k_t(results["tests"], "stiffness_n_per_m")
    ordering = results["findings"][0]
    assert ordering["source"] == ("rig input" if ordering["reproduced"] else "model")
    speed = results["findings"][-1]
    timing = results["timing"]
    assert speed["reproduced"] is (timing["integration_s_per_test"] > timing["law_s_per_test"])
    # eq 19 in fits.csv is the fit this file makes by hand (a check of fit.py by numpy)
    sel, side = jointed_sides(results["tests"])[0]
    w, a, k = side_arrays(sel, side, "dynamic_stiffness_n_per_m")
    b, cov = ols(np.column_stack((w, a, np.ones_like(w))), k)
    label = f"{sel[0]['structure']}, {side}"
    a1 = next(f for f in results["fits"] if f["law"] == "eq 19" and f["group"] == label)
    assert a1["value"] == pytest.approx(b[0], rel=1e-6)
    assert a1["std_error"] == pytest.approx(math.sqrt(cov[0, 0]), rel=1e-6)


def test_the_report_opens_with_the_findings_table(reproduction: Path) -> None:
    page = (reproduction / "report.html").read_text()
    body = page[page.index("<body>") :]
    assert body.index('<table id="findings">') < body.index("<h2>Figures</h2>")
    assert body.index('<table id="findings">') < body.index("<details")
    for name in NAMES:
        assert name.replace(">", "&gt;") in page


def test_the_same_table_for_a_folder_of_records(
    reproduction: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from clearjoint.cli import main

    out = tmp_path / "report"
    assert main(["report", "--records", str(reproduction / "records"), "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    printed = capsys.readouterr().out.splitlines()
    for row in results["findings"]:  # the command prints the same table
        untestable = row["why"].startswith("Not testable with these data")
        mark = "yes" if row["reproduced"] else ("n/a" if untestable else "NO")
        assert any(
            line.split()[:1] == [mark]
            and line.rstrip().endswith(row["finding"])
            and row["source"] in line
            for line in printed
        ), row["finding"]
    check_table(results)  # its control: the contact slopes frozen at their medians
    assert "frozen" in results["control"]
    assert results["findings"][-1]["reproduced"] is False  # no exact cycles to time here
    assert not any(t["file"].startswith("/") for t in results["tests"])  # relative paths


def test_a_finding_has_one_of_two_sources() -> None:
    with pytest.raises(ValueError, match="source"):
        Finding("f", "p", True, "given", "e", "w")


# ---- issue 28: each finding at a glance, its number named --------------------------------


def test_at_a_glance_each_finding_has_its_verdict_and_its_number_named(
    reproduction: Path,
) -> None:
    results = json.loads((reproduction / "results.json").read_text())
    glance = results["at_a_glance"]
    assert [g["finding"] for g in glance] == NAMES
    for g, row in zip(glance, results["findings"], strict=True):
        untestable = row["why"].startswith("Not testable with these data")
        assert g["verdict"] == ("yes" if row["reproduced"] else "n/a" if untestable else "NO")
        assert g["headline"]
        assert "\n" not in g["headline"]
        assert len(g["headline"]) < 130, g["headline"]  # one line of the table
    # k_c > k_t names its quantity and gives the weakest joint's mean difference, rebuilt
    # here from the tests in results.json (numpy, not findings.py)
    tests = [t for t in results["tests"] if t["jointed"]]
    margins = {}
    for name in sorted({t["structure"] for t in tests}):
        d = np.array(
            [
                t["compression_dynamic_stiffness_n_per_m"] - t["tension_dynamic_stiffness_n_per_m"]
                for t in tests
                if t["structure"] == name
            ]
        )
        mean, se = d.mean(), d.std(ddof=1) / math.sqrt(d.size)
        margins[name] = (mean / se, mean, se)
    weakest = min(margins, key=lambda n: margins[n][0])
    _, mean, se = margins[weakest]
    headline = glance[0]["headline"]
    assert headline.startswith("mean k_d,c - k_d,t = ")
    assert f"({weakest}, weakest of {len(margins)})" in headline
    number = re.match(r"mean k_d,c - k_d,t = (\S+) ± (\S+) MN/m", headline)
    assert number is not None
    assert float(number[1]) == pytest.approx(mean / 1e6, rel=5e-3)
    assert float(number[2]) == pytest.approx(se / 1e6, rel=5e-3)
    # the evidence names the quantity too, for the contact slopes as k_s,c - k_s,t
    assert "mean k_d,c - k_d,t = " in results["findings"][0]["evidence"]
    assert "Contact slopes: " in results["findings"][0]["evidence"]
    assert "mean k_s,c - k_s,t = " in results["findings"][0]["evidence"]


def test_a_finding_not_seen_says_why_in_its_own_numbers(reproduction: Path) -> None:
    """A NO says how far its weakest number is from a trend, in standard errors, and
    whether the data show the opposite; the margin is rebuilt from the headline's numbers."""
    results = json.loads((reproduction / "results.json").read_text())
    seen_no = False
    for g, row in zip(results["at_a_glance"], results["findings"], strict=True):
        if g["verdict"] != "NO":
            continue
        seen_no = True
        assert row["why"].startswith("Not shown by these data at 2 standard errors: ")
        value, error = (float(v) for v in re.findall(r"= (\S+) ± (\S+)", g["headline"])[0])
        sign = -1 if "falls" in g["finding"] else 1
        z = sign * value / error  # from the rounded numbers shown: to a few per cent
        if z < -2:
            said = re.search(r"the other way by (\S+) s\.e\.", g["headline"])
            assert "these data show the opposite" in row["why"]
        else:
            said = re.search(r"is (\S+) standard errors from zero", row["why"])
            assert "within the noise" in row["why"]
        assert said is not None, row["why"]
        assert float(said[1]) == pytest.approx(abs(z), rel=0.05, abs=0.06), g["headline"]
    assert seen_no  # the small campaign has NO rows (stiffness rises with w)
