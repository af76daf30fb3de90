"""Numbers the docs quote from a command are the command's: each is run here as written
and the page's numbers are read back from the page, so neither can drift (issue 28).

The pages give the numbers to the digits they print; each is checked to half a unit of its
last digit. Timings are not here: a page states how it measured one (docs/sweep.md).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from clearjoint.cli import main

ROOT = Path(__file__).resolve().parents[1]


def page(name: str) -> str:
    """A docs page (or README.md) with its line breaks as spaces, as a reader reads it."""
    path = ROOT / name if name == "README.md" else ROOT / "docs" / name
    return " ".join(path.read_text(encoding="utf-8").split())


def quoted(pattern: str, text: str) -> list[str]:
    found = re.search(pattern, text)
    assert found is not None, f"the page no longer says {pattern!r}: update this test with it"
    return list(found.groups())


def agrees(shown: str, value: float, scale: float = 1.0) -> bool:
    """``shown`` is ``value * scale`` written to the digits it has (half a unit of its last)."""
    decimals = len(shown.partition(".")[2])
    return abs(float(shown) - value * scale) <= 0.5 * 10.0**-decimals + 1e-12


def run_json(args: list[str], capsys: pytest.CaptureFixture[str]) -> dict:
    capsys.readouterr()
    assert main(args) == 0
    return json.loads(capsys.readouterr().out)


def test_harmonic_md_modes_of_the_mast_from_1_to_7_mm(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The issue's drift: the page said 'no mode at 1 mm'; the command finds 1.126 Hz."""
    f1, f2, f7 = quoted(
        r"`--amplitude 1mm\.\.7mm --points 3` gives (\S+) Hz at 1 mm.*? (\S+) Hz at 2\.6 mm "
        r"and (\S+) Hz at 7 mm",
        page("harmonic.md"),
    )
    out = run_json(
        ["modes", str(ROOT / "examples" / "mast.toml"), "--amplitude", "1mm..7mm",
         "--points", "3", "--out", str(tmp_path / "m.nc"), "--json"],
        capsys,
    )  # fmt: skip
    np.testing.assert_allclose(out["amplitude_m"], [1e-3, 7e-3**0.5 * 1e-3**0.5, 7e-3])
    for shown, value in zip((f1, f2, f7), out["frequency_hz"], strict=True):
        assert value is not None
        assert agrees(shown, value), (shown, value)


def test_structure_md_decay_of_the_mast(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The issue's drift: the page quoted the gallery's 5.41 Hz / 0.55 % for the command."""
    text = page("structure.md")
    assert "`clearjoint structure examples/mast.toml decay --out d.nc --json`" in text
    first, ratio, sixth = quoted(
        r"first rings at (\S+) Hz with a damping ratio of (\S+) %.*?to (\S+) Hz in the sixth",
        text,
    )
    out = run_json(
        ["structure", str(ROOT / "examples" / "mast.toml"), "decay",
         "--out", str(tmp_path / "d.nc"), "--json"],
        capsys,
    )  # fmt: skip
    assert agrees(first, out["frequency_hz"][0])
    assert agrees(ratio, out["damping_ratio"][0], 100.0)
    assert agrees(sixth, out["frequency_hz"][5])


def test_readme_stiffness_table_is_what_the_command_prints(
    capsys: pytest.CaptureFixture[str],
) -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    block = readme.split("    $ clearjoint stiffness ", 1)[1].split("\n\n", 1)[0]
    command, *printed = block.splitlines()
    capsys.readouterr()
    assert main(["stiffness", *command.split()]) == 0
    out = capsys.readouterr().out.splitlines()
    assert [line[4:].rstrip() for line in printed] == [line.rstrip() for line in out]


def test_the_front_page_five_lines_give_the_numbers_in_their_comment() -> None:
    text = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    code = text.split("```python\n", 1)[1].split("```", 1)[0]
    lines = [line for line in code.splitlines() if line and not line.startswith("#")]
    assert len(lines) == 5
    namespace: dict = {}
    exec("\n".join(lines[:-1]), namespace)  # the page's own example
    k_d = eval(lines[-1].split("#", 1)[0], namespace)
    shown = re.search(r"# (\S+), (\S+), (\S+) N/m", lines[-1])
    assert shown is not None
    for text_value, value in zip(shown.groups(), k_d, strict=True):
        assert float(text_value) == pytest.approx(value, rel=5e-3), (text_value, value)


def test_steady_md_cascade_is_what_the_example_prints(capsys: pytest.CaptureFixture[str]) -> None:
    """docs/steady.md quotes examples/one_link_cascade.py's period doublings and ratios."""
    import runpy

    text = page("steady.md")
    doublings = quoted(r"doublings fall at (\S+), (\S+), (\S+) and (\S+) Hz", text)
    ratios = quoted(r"ratios of the intervals are (\S+) and (\S+)\.", text)
    capsys.readouterr()
    runpy.run_path(str(ROOT / "examples" / "one_link_cascade.py"), run_name="__main__")
    out = capsys.readouterr().out
    printed = [float(x) for x in re.findall(r"period doubling at (\S+) Hz", out)]
    assert len(printed) == 4
    assert all(agrees(s, v) for s, v in zip(doublings, printed, strict=True))
    gaps = -np.diff(printed)
    assert all(agrees(s, v) for s, v in zip(ratios, gaps[:-1] / gaps[1:], strict=True))
