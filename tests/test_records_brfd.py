"""clearjoint.records.brfd: the BRFD JSON records, their fast parsers and their refusals."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from clearjoint.records import RecordError, read_brfd, read_record

#: The real records, in shared/ beside the clone (as on the developers' machines and CI).
BRFD = Path(__file__).resolve().parents[2] / "shared" / "data" / "brfd"
#: Without it (a fresh clone), the three records the clone ships.
SHIPPED_BRFD = Path(__file__).resolve().parent / "data" / "brfd"


def test_brfd_adapter_reads_all_31_files_in_si() -> None:
    """All 31 with ../shared beside the clone; on a fresh clone, the 3 it ships."""
    files = sorted((BRFD if BRFD.exists() else SHIPPED_BRFD).glob("*.json"))
    if BRFD.exists():
        assert len(files) == 31
    else:
        assert len(files) == 3
    for path in files:
        r = read_record(path)
        raw = np.asarray(json.loads(path.read_text())["data"])
        np.testing.assert_allclose(r.time, raw[:, 0])
        np.testing.assert_allclose(r.displacement, raw[:, 1] * 0.0254, rtol=1e-12)
        np.testing.assert_allclose(r.force, raw[:, 2] * 4448.2216152605, rtol=1e-9)
        np.testing.assert_allclose(r.velocity, raw[:, 3] * 0.0254, rtol=1e-12)
        assert r.control == "displacement"
        assert r.sampling_rate == pytest.approx(1024.0, rel=1e-6)
        assert r.frequency_hz in (0.25, 0.5, 1.0, 2.0)
        assert any(r.displacement_amplitude == pytest.approx(a) for a in (0.0127, 0.0254, 0.0381))
        assert "band tension" in r.notes
        assert "Coble" in r.notes
        # the nominal amplitude is reached (within the ramps' and the actuator's error)
        assert np.max(np.abs(r.displacement)) == pytest.approx(r.displacement_amplitude, rel=0.25)


def test_brfd_adapter_refuses_a_wrong_matrix(tmp_path: Path) -> None:
    # a shipped record's own content with one column dropped (runs on a fresh clone)
    shipped = Path(__file__).resolve().parent / "data" / "brfd" / "2Hz0lbtension0.5amplitude.json"
    content = json.loads(shipped.read_text())
    content["data"] = [row[:5] for row in content["data"]]
    path = tmp_path / shipped.name
    path.write_text(json.dumps(content))
    with pytest.raises(RecordError, match="must have 6 columns"):
        read_brfd(path)


SHIPPED = Path(__file__).resolve().parent / "data" / "brfd"


@pytest.mark.parametrize("name", sorted(p.name for p in SHIPPED.glob("*.json")))
def test_brfd_reader_gives_pythons_own_doubles_bit_for_bit(name: str) -> None:
    # the fast reader (orjson) against the standard library's json, an independent parser
    path = SHIPPED / name
    raw = np.array(json.loads(path.read_text())["data"], dtype=np.float64)
    r = read_brfd(path)
    assert r.time.size == raw.shape[0] > 1000
    np.testing.assert_array_equal(r.time, raw[:, 0])  # exactly: the same doubles
    np.testing.assert_array_equal(r.displacement, raw[:, 1] * 0.0254)
    np.testing.assert_array_equal(r.velocity, raw[:, 3] * 0.0254)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b'{"data": [[0.0, 1.0], [1.0, "x"]]}', "not numeric"),
        (b'{"data": [[0.0, 1.0], [1.0, 2.0]], "note": "caf\xe9"}', "not a JSON file"),
        (b"[1, 2]", "not a BRFD record"),
    ],
)
def test_brfd_reader_refuses_what_is_not_a_numeric_matrix(
    tmp_path: Path, content: bytes, message: str
) -> None:
    path = tmp_path / "1Hz0lbtension1amplitude.json"
    path.write_bytes(content)
    with pytest.raises(RecordError, match=message):
        read_brfd(path)


@pytest.mark.parametrize(
    ("rows", "taken"),
    [
        ([[0, 1.5, -2e-300], [3, 4.25, True]], True),  # ints, a bool, a subnormal
        ([[1.0, 2.0], [3.0]], False),  # ragged: refused by numpy, as before
        (["123456", "654321"], False),  # strings of equal length are not rows of numbers
        ([[1.0, "2.5"], [3.0, 4.0]], None),  # either way, the same numbers
        ([[1.0, None], [3.0, 4.0]], None),
        ([[[1.0], [2.0]], [[3.0], [4.0]]], False),
        ([], False),
    ],
)
def test_fast_matrix_reader_agrees_with_numpy_or_declines(
    rows: list[object], taken: bool | None
) -> None:
    from clearjoint.records.brfd import _rows_matrix

    fast = _rows_matrix(rows)
    if taken is not None:
        assert (fast is not None) == taken
    if fast is not None:  # declined, the reader converts by numpy.array: its own behaviour
        np.testing.assert_array_equal(fast, np.array(rows, dtype=np.float64), strict=True)


def test_brfd_reader_refuses_rows_that_are_strings(tmp_path: Path) -> None:
    path = tmp_path / "1Hz0lbtension1amplitude.json"
    path.write_text(json.dumps({"data": ["123456", "654321"]}))
    with pytest.raises(RecordError, match="must have 6 columns"):
        read_brfd(path)


def _orjson_route(raw: bytes) -> tuple[dict[str, object], np.ndarray]:
    """The reader's route for what simdjson declines: orjson's lists, then the rows."""
    import orjson

    from clearjoint.records.brfd import _json_matrix

    return _json_matrix("x.json", raw, orjson)


def test_simdjson_matrix_gives_pythons_doubles_bit_for_bit() -> None:
    # numbers written every way a JSON writer may (repr, %.17g, %.6e, integers, negative
    # zero, subnormals, the largest doubles, 2**53 + 1), against Python's json module (an
    # integer is an int there, so "-0" reads +0.0 as from orjson; float("-0") is -0.0)
    from clearjoint.records.brfd import _simd_matrix

    rng = np.random.default_rng(7)
    values = np.concatenate(
        (
            rng.standard_normal(300) * 10.0 ** rng.integers(-300, 300, 300),
            [0.0, -0.0, 5e-324, -2.2250738585072014e-308, 1.7976931348623157e308, 0.1],
        )
    )
    texts = [repr(float(v)) for v in values] + [f"{v:.17g}" for v in values]
    texts += [f"{v:.6e}" for v in values] + ["9007199254740993", "-0", "123456789012345678"]
    texts += ["1E5", "1e-400", "0.30000000000000004", "18446744073709551615"]
    texts += [str(int(v)) for v in rng.integers(-(2**62), 2**62, 20)]
    width = 3
    texts += ["0"] * (-len(texts) % width)
    rows = [texts[i : i + width] for i in range(0, len(texts), width)]
    raw = '{"dt": 0.5, "data": [' + ", ".join(f"[{', '.join(r)}]" for r in rows) + "]}"
    fast = _simd_matrix(raw.encode())
    assert fast is not None
    meta, matrix = fast
    expected = np.array(json.loads(raw)["data"], dtype=np.float64)
    assert matrix.shape == expected.shape
    assert matrix.tobytes() == expected.tobytes()  # bit for bit, -0.0 included
    assert meta == {"dt": 0.5}
    assert matrix.tobytes() == _orjson_route(raw.encode())[1].tobytes()


@pytest.mark.parametrize(
    "raw",
    [
        b'{"data": [[1.0, 2.0, 3.0], [4.0], [5.0, 6.0]]}',  # ragged, 6 numbers in 3 rows
        b'{"data": [[1.0, [2.0]], [3.0, 4.0]]}',  # nested: the flat buffer would fit 2 x 2
        b'{"data": [[1.0, 2.0], 3.0, [4.0, 5.0]]}',  # a number for a row
        b'{"data": [[1.0, true], [3.0, 4.0]]}',  # a bool (orjson: 1.0, as before)
        b'{"data": [[1.0, null], [3.0, 4.0]]}',
        b'{"data": [[1.0, "2.5"], [3.0, 4.0]]}',
        b'{"data": [[1.0, 2.0]], "data": [[3.0, 4.0]]}',  # a repeated key: the last one
        b'{"data": [[1.0, 2.0]], "note": "a [bracket"}',  # a [ in a text
        b'{"data": [[1.0, 2.0]], "gains": [1, 2]}',  # another list
        b'{"data": [[1.0, 2.0]], "d\\u0061ta": [[3.0, 4.0]]}',  # the same key, escaped
        b'\xef\xbb\xbf{"data": [[1.0, 2.0]]}',  # a byte-order mark (orjson refuses it)
        b'{"data": [[1.0, 2.0]], "note": "caf\xe9"}',  # not UTF-8
        b'{"data": [[1e400, 2.0]]}',
        b'{"data": [[NaN, 2.0]]}',
        b'{"data": [[]]}',
        b'{"data": []}',
        b'{"data": 3}',
        b"[1, 2]",
        b'{"data": [[1.0, 2.0]]} trailing',
    ],
)
def test_simdjson_declines_what_orjson_must_judge(raw: bytes) -> None:
    # whatever simdjson does not take as a plain matrix goes the orjson route, which
    # gives the same matrix or the same error as before the fast path
    from clearjoint.records.brfd import _brfd_json, _simd_matrix

    assert _simd_matrix(raw) is None

    def outcome(read: Callable[[bytes], tuple[dict[str, object], np.ndarray]]) -> object:
        try:
            meta, matrix = read(raw)
        except RecordError as exc:
            return str(exc)
        return meta, matrix.shape, matrix.tobytes()

    assert outcome(lambda b: _brfd_json("x.json", b)) == outcome(_orjson_route)


def test_simdjson_takes_a_plain_matrix_with_its_metadata() -> None:
    from clearjoint.records.brfd import _simd_matrix

    raw = b'{"data": [[0, 1.5], [2, -3e-5]], "units": {"a": "in"}, "dt": 1, "x": null}'
    fast = _simd_matrix(raw)
    assert fast is not None
    assert fast[0] == {"units": {"a": "in"}, "dt": 1, "x": None}
    assert fast[1].tolist() == [[0.0, 1.5], [2.0, -3e-5]]
    assert fast[0] == _orjson_route(raw)[0]
