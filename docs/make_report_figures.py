"""Ship the reports' figures in docs/figures: ``python docs/make_report_figures.py [BRFD]``.

Runs ``clearjoint reproduce`` (the default campaign) and ``clearjoint report`` on the
BRFD records (default: ../shared/data/brfd beside the clone) into a temporary folder and
saves every figure of both reports as docs/figures/reproduce_*.png and brfd_*.png.
"""

from __future__ import annotations

import base64
import re
import sys
import tempfile
from pathlib import Path

from clearjoint.cli import main as cli

HERE = Path(__file__).parent / "figures"


def _name(alt: str) -> str | None:
    """A figure's file name from its caption: figN, fig8_contact (slopes) or fig_truth."""
    number = re.match(r"Fig\. (\d+)", alt)
    if number:
        return f"fig{number.group(1)}"
    if alt.startswith("Contact slopes"):
        return "fig8_contact"
    if alt.startswith("Identification against"):
        return "fig_truth"
    return None


def save_figures(report: Path, prefix: str) -> None:
    page = report.read_text(encoding="utf-8")
    pattern = r'<img alt="([^"]*)" src="data:image/png;base64,([^"]+)"'
    for alt, data in re.findall(pattern, page):
        name = _name(alt)
        if name is None:
            continue
        path = HERE / f"{prefix}_{name}.png"
        path.write_bytes(base64.b64decode(data))
        print(f"wrote {path}")


def main() -> None:
    brfd = (
        Path(sys.argv[1])
        if len(sys.argv) > 1
        else (Path(__file__).resolve().parents[2] / "shared" / "data" / "brfd")
    )
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        cli(["reproduce", "--out", str(out / "reproduce")])
        save_figures(out / "reproduce" / "report.html", "reproduce")
        cli(["report", "--records", str(brfd), "--out", str(out / "brfd")])
        save_figures(out / "brfd" / "report.html", "brfd")


if __name__ == "__main__":
    main()
