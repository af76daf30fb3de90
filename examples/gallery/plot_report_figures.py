"""
The reports' figures: the reproduction and the BRFD records (paper Figs. 7-13)
==============================================================================

Runs ``clearjoint reproduce`` (the default campaign on the virtual rig) and
``clearjoint report --records`` on the real BRFD records (Coble, Huggins, Cao, Ricles &
Downey, "Dataset-Friction-Damper-with-Backlash", ARTS Laboratory, 2022; CC BY-SA 4.0; in
../shared/data/brfd beside the clone, or the folder given as the first argument) into a
temporary folder, and keeps every figure of both reports as docs/figures/reproduce_*.png
and brfd_*.png, the pictures docs/report.md and docs/identify.md show. Without the BRFD
folder only the reproduction's figures are redrawn. The docs build runs this script, so
the report pictures in the docs are those of the code that built them;
``python docs/make_figures.py`` does the same without Sphinx.
"""

import base64
import re
import sys
import tempfile
from pathlib import Path

from clearjoint.cli import main as cli

DOCS_FIGURES = {}  # figures of the docs this script draws: here, PNGs cut from the reports

try:
    ROOT = Path(__file__).resolve().parents[2]
except NameError:  # sphinx-gallery runs the script from its own folder, without __file__
    ROOT = Path.cwd().resolve().parents[1]
args = [a for a in sys.argv[1:] if not a.startswith("-")]
BRFD = Path(args[0]) if args else ROOT.parent / "shared" / "data" / "brfd"


def figure_name(alt):
    """A figure's file name from its caption: figN, fig8_contact (slopes) or fig_truth."""
    number = re.match(r"Fig\. (\d+)", alt)
    if number:
        return f"fig{number.group(1)}"
    if alt.startswith("Contact slopes"):
        return "fig8_contact"
    if alt.startswith("Identification against"):
        return "fig_truth"
    return None


def report_pngs(report, prefix):
    """Every named figure embedded in a report.html, as {file name: PNG bytes}."""
    page = report.read_text(encoding="utf-8")
    pattern = r'<img alt="([^"]*)" src="data:image/png;base64,([^"]+)"'
    found = {}
    for alt, data in re.findall(pattern, page):
        name = figure_name(alt)
        if name is not None:
            found[f"{prefix}_{name}.png"] = base64.b64decode(data)
    return found


with tempfile.TemporaryDirectory() as folder:
    out = Path(folder)
    cli(["reproduce", "--out", str(out / "reproduce")])
    DOCS_FIGURES.update(report_pngs(out / "reproduce" / "report.html", "reproduce"))
    if BRFD.is_dir():
        cli(["report", "--records", str(BRFD), "--out", str(out / "brfd")])
        DOCS_FIGURES.update(report_pngs(out / "brfd" / "report.html", "brfd"))
    else:
        print(f"{BRFD}: no BRFD records here, their figures are left as they are")
print(sorted(DOCS_FIGURES))
