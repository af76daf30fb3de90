"""io_toml.py: the one reader for TOML files with units."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from clearjoint.errors import ClearjointError
from clearjoint.io_toml import quantity, read_table, read_toml


class FileError(ClearjointError, ValueError):
    """The caller's own error class, which the reader raises."""


SPEC = {"mass": "mass", "frequency": "frequency", "damping_ratio": "dimensionless",
        "mode": "text", "samples": "count"}  # fmt: skip


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (None, "no such study file"),
        ("folder", "is a folder; give a study file"),
        (b"", "empty file"),
        (b"  \n\n", "empty file"),
        (bytes(range(256)), "not a text file"),
        (b"a = 1\x00", "a binary file"),
        (b"a = = 1", "not valid TOML"),
    ],
)
def test_read_toml_says_what_is_wrong_with_the_file(
    tmp_path: Path, content: bytes | str | None, words: str
) -> None:
    path = tmp_path / "x.toml"
    if content == "folder":
        path.mkdir()
    elif isinstance(content, bytes):
        path.write_bytes(content)
    with pytest.raises(FileError) as info:
        read_toml(path, what="study", error=FileError)
    assert words in str(info.value)
    assert str(path) in str(info.value)


def test_read_table_converts_by_dimension_and_takes_unit_named_keys() -> None:
    table = {"mass": "1500g", "frequency": "2513rad/s", "damping_ratio": 0.02,
             "mode": "steady", "samples": 64}  # fmt: skip
    values = read_table(table, SPEC, where="f.toml", section="[a]", error=FileError)
    assert values["mass"] == pytest.approx(1.5)
    assert values["frequency"] == pytest.approx(2513.0 / (2 * math.pi))
    assert values["damping_ratio"] == 0.02
    assert (values["mode"], values["samples"]) == ("steady", 64)
    named = read_table({"mass_kg": 2, "frequency_hz": 400}, SPEC, where="f", section="",
                       error=FileError)  # fmt: skip
    assert named == {"mass": 2.0, "frequency": 400.0}


@pytest.mark.parametrize(
    ("table", "words"),
    [
        ({"mas": "2kg"}, "unknown key(s) ['mas'] in [a]"),
        ({"mass": 2}, '[a] mass = 2: give a unit, e.g. "2kg"'),
        ({"mass": "2m"}, "is not a mass"),
        ({"mass_kg": "2kg"}, "the key names its unit"),
        ({"mass": "2kg", "mass_kg": 2}, "given twice"),
        ({"mode": 3}, "must be text"),
        ({"samples": 6.5}, "must be a whole number"),
        ({"damping_ratio": True}, "must be a number"),
    ],
)
def test_read_table_refuses_with_one_line(table: dict[str, object], words: str) -> None:
    with pytest.raises(FileError) as info:
        read_table(table, SPEC, where="f.toml", section="[a]", error=FileError)
    assert words in str(info.value)
    assert len(str(info.value).splitlines()) == 1


def test_zero_needs_no_unit() -> None:
    assert quantity(0, "length", name="f: gap_offset", error=FileError) == 0.0
