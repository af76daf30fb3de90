"""Redraw the pictures in docs/figures/ without Sphinx: ``python docs/make_figures.py``.

Each script examples/gallery/plot_*.py draws figures of the docs and lists them in
``DOCS_FIGURES``; this runs every script and saves those figures here, exactly as the
docs build does (docs/_ext/docs_figures.py). To add a figure to the docs, draw it in a
gallery script and add it to that script's ``DOCS_FIGURES``.
"""

from __future__ import annotations

import os
import runpy
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

HERE = Path(__file__).resolve().parent
GALLERY = HERE.parent / "examples" / "gallery"
sys.path.insert(0, str(HERE / "_ext"))

from docs_figures import save  # noqa: E402


def main() -> None:
    import matplotlib.pyplot as plt

    for script in sorted(GALLERY.glob("plot_*.py")):
        here = Path.cwd()
        os.chdir(script.parent)  # as sphinx-gallery runs it
        try:
            names = runpy.run_path(str(script), run_name="__main__")
        finally:
            os.chdir(here)
        for name, figure in names.get("DOCS_FIGURES", {}).items():
            print(f"wrote {save(name, figure)}")
        plt.close("all")


if __name__ == "__main__":
    main()
