"""Sphinx configuration of clearjoint's documentation.

Build it as CI does (warnings are errors):

    python3.11 -m pip install -e ".[docs]"
    python3.11 -m sphinx -W --keep-going -b html docs docs/_build/html

The Markdown pages (docs/*.md) are read by myst-parser; the API reference is
generated from the package's docstrings (numpydoc); the gallery runs
examples/gallery/plot_*.py, which also redraw docs/figures/*.png.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

import clearjoint

matplotlib.use("Agg")
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))  # docs_figures, the gallery's figure scraper

project = "clearjoint"
author = "clearjoint developers"
copyright = "2026, clearjoint developers (MIT licence)"  # noqa: A001 (Sphinx's name)
release = clearjoint.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = [
    "_build",
    "_ext",
    "_templates",
    "**/*.ipynb",
    "auto_examples/*.py",
    "sg_execution_times.rst",  # the gallery's timings, not a page of the guide
]
templates_path = ["_templates"]

# ---- Markdown ------------------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

# ---- API reference -------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections give the types, with shapes
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True

# ---- Gallery: each example draws figures of these pages ------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": [str(HERE.parent / "examples" / "gallery")],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/plot_",
    # docs_figures first: it draws each docs figure once (docs/_ext/docs_figures.py says why)
    "image_scrapers": ("docs_figures.scraper", "matplotlib"),
    "reset_modules": ("matplotlib",),
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "show_memory": False,
}

# ---- HTML ----------------------------------------------------------------------------------
# pydata-sphinx-theme: the theme of numpy, scipy and xarray's sites, which a scientific
# Python user already knows how to read (navigation left, page contents right).
html_theme = "pydata_sphinx_theme"
html_title = f"clearjoint {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navbar_align": "left",
    "header_links_before_dropdown": 4,  # the rest of the guide under "More", not two rows
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
    "secondary_sidebar_items": ["page-toc"],
}
html_sidebars: dict[str, list[str]] = {"index": []}  # the front page uses the full width
