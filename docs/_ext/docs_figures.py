"""Sphinx-gallery scraper: show the figures an example lists in DOCS_FIGURES, and save them.

An example in examples/gallery/ that draws a figure of the docs adds it to a
module-level ``DOCS_FIGURES = {"name.png": figure}`` (a matplotlib figure, or the PNG's
bytes when the picture comes drawn, as the report's do). After each code block this
scraper shows every new figure of that mapping in the gallery page and writes it
to docs/figures/name.png, the file the Markdown pages link to, so building the
docs redraws every such picture from the code (``python docs/make_figures.py``
does the same without Sphinx).

Byte for byte the same picture either way: a figure with ``layout="constrained"`` lays
itself out again from its last layout at each draw, so a second ``savefig`` gives other
bytes than the first (text and colour bars move by a fraction of a pixel). Each figure is
therefore drawn once, at :data:`DPI`, before any other scraper has drawn it (conf.py lists
this scraper first), and those bytes are written to both places; the figure is then closed
so that sphinx-gallery's matplotlib scraper does not draw it a second time (which also
showed it twice in the gallery page). PNG metadata holds no date (matplotlib writes only
the "Software" key), so equal drawings are equal files.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

FIGURES = Path(__file__).resolve().parents[1] / "figures"
DPI = 110

_shown: set[tuple[str, str]] = set()


def png(figure: Any) -> bytes:
    """The PNG of a matplotlib figure drawn once at DPI, or a PNG already drawn (bytes)."""
    if isinstance(figure, bytes):
        return figure
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI)
    return buffer.getvalue()


def save(name: str, figure: Any) -> Path:
    """Write ``figure`` (a Figure or PNG bytes) to docs/figures/``name``; return the path."""
    FIGURES.mkdir(exist_ok=True)
    path = FIGURES / name
    path.write_bytes(png(figure))
    return path


def scraper(block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any]) -> str:
    """Save and show the figures of DOCS_FIGURES that are new after this block."""
    from sphinx_gallery.scrapers import figure_rst  # here: save() works without the docs extra
    listed = block_vars["example_globals"].get("DOCS_FIGURES", {})
    source = str(block_vars["src_file"])
    shown = []
    for name, figure in listed.items():
        if (source, name) in _shown:
            continue
        _shown.add((source, name))
        drawn = png(figure)  # once: a second draw of a constrained layout moves the text
        save(name, drawn)
        image = next(block_vars["image_path_iterator"])
        Path(image).write_bytes(drawn)
        shown.append(image)
        if not isinstance(figure, bytes):
            import matplotlib.pyplot as plt

            plt.close(figure)  # drawn and shown: the matplotlib scraper leaves it
    return figure_rst(shown, gallery_conf["src_dir"]) if shown else ""
