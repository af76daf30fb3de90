"""clearjoint.records.formats: the one registry of record file endings, and the imports.

The registry is the one place that knows which file endings hold records: every ending
a reader takes is in it, every place that picks record files by name (identify,
reproduction, rig) asks it, and none of them keeps its own list.
"""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import clearjoint
from clearjoint.records import (
    FORMATS,
    Record,
    RecordError,
    import_readers,
    is_record_file,
    read_record,
    record_format,
    record_suffixes,
    sniff,
    write_record,
)

SRC = Path(clearjoint.__file__).resolve().parent
SHIPPED = Path(__file__).resolve().parent / "data" / "brfd" / "2Hz0lbtension0.5amplitude.json"


def _record() -> Record:
    t = np.arange(2000) / 1000.0
    return Record(
        time=t,
        force=100.0 * np.sin(2 * np.pi * 10 * t),
        displacement=1e-5 * np.sin(2 * np.pi * 10 * t - 0.3),
        joint_id="J1",
        frequency_hz=10.0,
    )


def _one_file_per_ending(folder: Path) -> dict[str, Path]:
    """A record file of every registered ending, in its own format."""
    written = {s: write_record(_record(), folder / f"r{s}") for s in record_suffixes(writable=True)}
    files: dict[str, Path] = {}
    for suffix, entry in FORMATS.items():
        path = folder / f"r{suffix}"
        if suffix not in written:
            source = next(
                (w for s, w in written.items() if FORMATS[s].content == entry.content), SHIPPED
            )
            shutil.copyfile(source, path)
        files[suffix] = path
    return files


def test_every_ending_of_the_registry_is_read_as_what_it_claims(tmp_path: Path) -> None:
    files = _one_file_per_ending(tmp_path)
    assert set(files) == set(FORMATS) == set(record_suffixes())
    for suffix, path in files.items():
        assert sniff(path) == FORMATS[suffix].content
        assert read_record(path).time.size > 0
        assert record_format(path.with_suffix(suffix.upper())) is FORMATS[suffix]


def test_every_content_the_sniffer_finds_has_a_reader_in_the_registry(tmp_path: Path) -> None:
    # sniff names three contents; a file of another ending is read by its content
    contents = {entry.content for entry in FORMATS.values()}
    assert contents == {"csv", "netcdf", "json"}
    files = _one_file_per_ending(tmp_path)
    for suffix, path in files.items():
        unnamed = path.with_name(f"unnamed{suffix}.dat")
        shutil.copyfile(path, unnamed)
        assert not is_record_file(unnamed)
        assert sniff(unnamed) == FORMATS[suffix].content
        np.testing.assert_array_equal(read_record(unnamed).time, read_record(path).time)


def test_a_name_that_claims_another_content_is_refused_for_every_ending(tmp_path: Path) -> None:
    files = _one_file_per_ending(tmp_path)
    for suffix, entry in FORMATS.items():
        other = next(p for s, p in files.items() if FORMATS[s].content != entry.content)
        liar = tmp_path / f"liar{suffix}"
        shutil.copyfile(other, liar)
        with pytest.raises(RecordError, match=f"named as {entry.description} but"):
            sniff(liar)


def test_records_are_written_exactly_in_the_writable_endings(tmp_path: Path) -> None:
    writable = record_suffixes(writable=True)
    assert writable == (".csv", ".nc")
    for suffix in record_suffixes():
        path = tmp_path / f"w{suffix}"
        if suffix in writable:
            assert write_record(_record(), path) == path
        else:
            with pytest.raises(RecordError, match=r"write records as \.csv or \.nc"):
                write_record(_record(), path)


def test_reproduction_takes_exactly_the_registrys_record_files(tmp_path: Path) -> None:
    from clearjoint.reproduction import _record_files

    for suffix in FORMATS:
        (tmp_path / f"a{suffix}").write_text("x")
        (tmp_path / f"B{suffix.upper()}").write_text("x")
    for name in ("manifest.csv", "notes.txt", "r.toml", "r.xlsx", "r.nc.bak"):
        (tmp_path / name).write_text("x")
    (tmp_path / "folder.csv").mkdir()
    taken = {Path(p).name for p in _record_files(tmp_path)}
    expected = {f"a{s}" for s in FORMATS} | {f"B{s.upper()}" for s in FORMATS}
    assert taken == expected


def test_identify_imports_the_readers_the_registry_names(monkeypatch: pytest.MonkeyPatch) -> None:
    import clearjoint.identify.core as core
    import clearjoint.records.formats as formats

    assert core.import_readers is import_readers
    imported: list[str] = []
    monkeypatch.setattr(formats.importlib, "import_module", imported.append)
    for suffix, entry in FORMATS.items():
        imported.clear()
        import_readers([f"x{suffix.upper()}", "y.txt", "z"])
        assert imported == sorted(entry.modules)
    imported.clear()
    import_readers([f"x{s}" for s in FORMATS])
    assert imported == sorted({m for entry in FORMATS.values() for m in entry.modules})


def test_the_campaign_formats_are_the_writable_endings(tmp_path: Path) -> None:
    from clearjoint.rig import CampaignError, default_campaign_path, load_campaign

    text = default_campaign_path().read_text()
    assert 'format = "nc"' in text
    for suffix in record_suffixes(writable=True):
        path = tmp_path / f"c{suffix}.toml"
        path.write_text(text.replace('format = "nc"', f'format = "{suffix[1:]}"'))
        assert load_campaign(path).format == suffix[1:]
    path = tmp_path / "bad.toml"
    path.write_text(text.replace('format = "nc"', 'format = "json"'))
    with pytest.raises(CampaignError, match="format must be 'csv' or 'nc'"):
        load_campaign(path)


def _suffix_literals(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [
        f"{path.relative_to(SRC)}:{node.lineno}: {node.value!r}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and node.value.lower() in FORMATS
    ]


def test_no_other_place_keeps_its_own_list_of_record_endings() -> None:
    places = [
        *sorted((SRC / "identify").glob("*.py")),
        *sorted((SRC / "records").glob("*.py")),
        SRC / "reproduction.py",
        SRC / "rig.py",
    ]
    found = [hit for path in places if path.name != "formats.py" for hit in _suffix_literals(path)]
    assert found == []


def _fresh(code: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(SRC.parent)}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=False
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@pytest.mark.parametrize(
    "order",
    [
        ("clearjoint.records", "clearjoint.identify"),
        ("clearjoint.identify", "clearjoint.records"),
        ("clearjoint.identify.cycles", "clearjoint.records"),
        ("clearjoint.records.record", "clearjoint.identify.cycles"),
    ],
)
def test_records_and_identify_import_alone_in_either_order(order: tuple[str, str]) -> None:
    first, second = order
    code = (
        "import importlib, sys\n"
        f"importlib.import_module({first!r})\n"
        f"importlib.import_module({second!r})\n"
        "from clearjoint.identify.cycles import STEADY_RULE\n"
        "import clearjoint.records\n"
        "assert STEADY_RULE is clearjoint.records.STEADY_RULE\n"
        "print('ok')\n"
    )
    assert _fresh(code) == "ok"


def test_records_import_no_identification_and_identify_no_rig_or_simulator() -> None:
    code = (
        "import sys\n"
        "import clearjoint.records\n"
        "print(sorted(m for m in sys.modules if m.startswith('clearjoint.identify')))\n"
        "import clearjoint.identify\n"
        "print(sorted(m for m in sys.modules if m in ('clearjoint.rig', 'clearjoint.simulate')))\n"
    )
    assert _fresh(code).splitlines() == ["[]", "[]"]
