"""The docs site's promises that a test can check without building it.

Every picture a page shows is drawn by a script the docs build runs (a gallery
example lists it in ``DOCS_FIGURES``, the reports' figures by name pattern in
examples/gallery/plot_report_figures.py), so none can
fall behind the code; and the LICENSE is the one pyproject.toml names.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Figures cut out of the two reports by examples/gallery/plot_report_figures.py.
REPORT_FIGURES = ("reproduce_fig", "brfd_fig")


def pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def shown() -> dict[str, Path]:
    found = {}
    for page in pages():
        if "_build" in page.parts:
            continue
        for name in re.findall(r"figures/([\w.-]+\.png)", page.read_text(encoding="utf-8")):
            found[name] = page
    return found


def drawn_by_gallery() -> set[str]:
    names: set[str] = set()
    for script in (ROOT / "examples" / "gallery").glob("plot_*.py"):
        text = script.read_text(encoding="utf-8")
        names.update(re.findall(r"DOCS_FIGURES\[\"([\w.-]+\.png)\"\]", text))
    return names


def test_every_figure_a_page_shows_is_drawn_by_a_script() -> None:
    gallery = drawn_by_gallery()
    assert len(gallery) >= 7
    for name, page in shown().items():
        assert (ROOT / "docs" / "figures" / name).is_file(), f"{page} shows a missing {name}"
        assert name in gallery or name.startswith(REPORT_FIGURES), (
            f"{page.name} shows figures/{name}, which no script draws: draw it in an "
            "examples/gallery/plot_*.py and add it to that script's DOCS_FIGURES"
        )


def test_the_report_figures_are_drawn_by_a_gallery_script() -> None:
    script = ROOT / "examples" / "gallery" / "plot_report_figures.py"
    text = script.read_text(encoding="utf-8")
    for prefix in REPORT_FIGURES:
        assert f'"{prefix.removesuffix("_fig")}")' in text, prefix
    assert "DOCS_FIGURES.update(" in text


def test_every_gallery_figure_is_shown_somewhere() -> None:
    unused = drawn_by_gallery() - set(shown())
    assert not unused, f"drawn for the docs but shown on no page: {sorted(unused)}"


def test_license_file_is_the_mit_licence_pyproject_names() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["license"]["text"] == "MIT"
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License")
    assert "Permission is hereby granted, free of charge" in text


def test_no_docstring_has_a_bar_pair_that_restructuredtext_reads_as_a_substitution() -> None:
    """``|x|`` in a public docstring or a ``#:`` comment breaks the docs build: write abs(x).

    The docs build (sphinx -W) runs outside the test command; this catches its commonest
    break here. Private modules and functions (a leading _) are not in the API pages.
    """
    import ast

    bars = re.compile(r"(?<![|\w])\|[^|\s`][^|`\n]*\|(?![|\w])")
    kinds = ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef
    found = []
    for path in sorted((ROOT / "src" / "clearjoint").rglob("*.py")):
        if path.name.startswith("_") and path.name != "__init__.py":
            continue
        source = path.read_text(encoding="utf-8")
        texts = [(n, t) for n, t in enumerate(source.splitlines(), 1) if t.strip().startswith("#:")]
        for node in ast.walk(ast.parse(source)):
            if not isinstance(node, kinds) or getattr(node, "name", "").startswith("_"):
                continue
            doc = ast.get_docstring(node, clean=False)
            if doc:
                texts.append((node.body[0].lineno, doc))
        found += [f"{path.name}:{n}: {m.group(0)}" for n, t in texts for m in bars.finditer(t)]
    assert not found, f"write abs(...) instead of |...|: {found}"


def test_a_docs_figure_is_drawn_once_so_the_build_and_make_figures_write_the_same_bytes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A constrained layout moves its text at each new draw, so the build drew the docs'
    figures after sphinx-gallery's matplotlib scraper had drawn them once already, and
    wrote other bytes than `python docs/make_figures.py` (and than the previous build, run
    to run, whenever one of the two had written the file)."""
    import io
    import sys

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pytest.importorskip("sphinx_gallery")
    monkeypatch.syspath_prepend(str(ROOT / "docs" / "_ext"))
    sys.modules.pop("docs_figures", None)
    import docs_figures

    monkeypatch.setattr(docs_figures, "FIGURES", tmp_path / "figures")
    monkeypatch.setattr(docs_figures, "_shown", set())

    def figure() -> Any:
        fig, ax = plt.subplots(figsize=(4.0, 3.0), layout="constrained")
        mesh = ax.pcolormesh([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
        fig.colorbar(mesh, ax=ax, label="peak amplitude (um)")
        ax.set_title("peak of the stepped-sine response")
        ax.set_xlabel("joint.clearance (um)")
        return fig

    alone = docs_figures.save("a.png", figure()).read_bytes()  # as make_figures.py does
    again = figure()
    again.savefig(io.BytesIO(), format="png", dpi=100)  # a first draw by another scraper
    assert docs_figures.png(again) != alone  # the trap is real

    built = figure()
    gallery_image = tmp_path / "sphx_glr_x_001.png"
    rst = docs_figures.scraper(
        None,
        {
            "example_globals": {"DOCS_FIGURES": {"a.png": built}},
            "src_file": str(tmp_path / "plot_x.py"),
            "image_path_iterator": iter([str(gallery_image)]),
        },
        {"src_dir": str(tmp_path)},
    )
    assert (tmp_path / "figures" / "a.png").read_bytes() == alone
    assert gallery_image.read_bytes() == alone
    assert "sphx_glr_x_001.png" in rst
    assert not plt.fignum_exists(built.number)  # the matplotlib scraper will not draw it again
    conf = (ROOT / "docs" / "conf.py").read_text(encoding="utf-8")
    scrapers = re.search(r'"image_scrapers": \(([^)]*)\)', conf)
    assert scrapers is not None
    assert scrapers[1].split(",")[0].strip() == '"docs_figures.scraper"'
    plt.close("all")
