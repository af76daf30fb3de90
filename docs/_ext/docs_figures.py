"""Sphinx-gallery scraper: show the figures an example lists in DOCS_FIGURES, and save them.

An example in examples/gallery/ that draws a figure of the docs adds it to a
module-level ``DOCS_FIGURES = {"name.png": figure}``. After each code block this
scraper shows every new figure of that mapping in the gallery page and writes it
to docs/figures/name.png, the file the Markdown pages link to, so building the
docs redraws every such picture from the code (``python docs/make_figures.py``
does the same without Sphinx).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from sphinx_gallery.scrapers import figure_rst

FIGURES = Path(__file__).resolve().parents[1] / "figures"
DPI = 110

_shown: set[tuple[str, str]] = set()


def save(name: str, figure: Any) -> Path:
    """Write ``figure`` to docs/figures/``name`` and return the path."""
    FIGURES.mkdir(exist_ok=True)
    path = FIGURES / name
    figure.savefig(path, dpi=DPI)
    return path


def scraper(block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any]) -> str:
    """Save and show the figures of DOCS_FIGURES that are new after this block."""
    listed = block_vars["example_globals"].get("DOCS_FIGURES", {})
    source = str(block_vars["src_file"])
    shown = []
    for name, figure in listed.items():
        if (source, name) in _shown:
            continue
        _shown.add((source, name))
        save(name, figure)
        image = next(block_vars["image_path_iterator"])
        figure.savefig(image, dpi=DPI)
        shown.append(image)
    return figure_rst(shown, gallery_conf["src_dir"]) if shown else ""
