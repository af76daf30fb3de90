"""benchmarks/compare_numbers.py: the comparison of two written sets of numbers (not the writing).

Each case builds two small sets of entries by hand, as ``write`` would have written
them, and checks the verdict of ``compare``.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest


@pytest.fixture(scope="module")
def numbers() -> ModuleType:
    path = Path(__file__).parents[1] / "benchmarks" / "compare_numbers.py"
    spec = importlib.util.spec_from_file_location("bench_numbers", path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks its module up there
    spec.loader.exec_module(module)
    return module


def _entries(numbers: ModuleType, **values: Any) -> dict[str, Any]:
    return {name: numbers.value_entry(f"made by {name}", v) for name, v in values.items()}


def _verdicts(numbers: ModuleType, a: dict[str, Any], b: dict[str, Any]) -> dict[str, str]:
    return {r.name: r.verdict for r in numbers.compare(a, b, rtol=1e-9)}


def test_equal_entries_are_equal(numbers: ModuleType) -> None:
    a = _entries(numbers, x=[1.0, 2.5, -3e-7], flag=[True, False], kind="shooting", n=3)
    b = _entries(numbers, x=[1.0, 2.5, -3e-7], flag=[True, False], kind="shooting", n=3)
    assert _verdicts(numbers, a, b) == {
        "x": "equal",
        "flag": "equal",
        "kind": "equal",
        "n": "equal",
    }


def test_a_difference_of_2e_9_relative_differs(numbers: ModuleType) -> None:
    a = _entries(numbers, x=[1.0, 2.5, 4.0])
    b = _entries(numbers, x=[1.0, 2.5 * (1 + 2e-9), 4.0])
    (result,) = numbers.compare(a, b, rtol=1e-9)
    assert result.verdict == "differs"
    assert "(1,)" in result.detail


def test_a_difference_within_rtol_is_equal(numbers: ModuleType) -> None:
    a = _entries(numbers, x=[1.0, 2.5, 4.0])
    b = _entries(numbers, x=[1.0, 2.5 * (1 + 5e-10), 4.0])
    assert _verdicts(numbers, a, b) == {"x": "equal"}


def test_nan_equals_nan_but_not_a_number(numbers: ModuleType) -> None:
    a = _entries(numbers, x=[1.0, math.nan], y=[1.0, math.nan], z=[None, 2.0])
    b = _entries(numbers, x=[1.0, math.nan], y=[1.0, 2.0], z=[math.nan, 2.0])
    assert _verdicts(numbers, a, b) == {"x": "equal", "y": "differs", "z": "equal"}


def test_a_missing_key_or_missing_entry_is_missing(numbers: ModuleType) -> None:
    a = _entries(numbers, x=[1.0], y=[2.0])
    b = _entries(numbers, x=[1.0], w=[3.0])
    b["x"] = numbers.missing_entry("api call", "AttributeError: gone")
    assert _verdicts(numbers, a, b) == {"x": "missing", "y": "missing", "w": "missing"}


def test_a_shape_mismatch_differs(numbers: ModuleType) -> None:
    a = _entries(numbers, x=[[1.0, 2.0], [3.0, 4.0]], y=[1.0, 2.0])
    b = _entries(numbers, x=[1.0, 2.0, 3.0, 4.0], y=[1.0, 2.0, 3.0])
    results = numbers.compare(a, b)
    assert [r.verdict for r in results] == ["differs", "differs"]
    assert all("shape" in r.detail for r in results)


def test_strings_and_booleans_compare_exactly(numbers: ModuleType) -> None:
    a = _entries(numbers, kind="fold", flags=[True, True])
    b = _entries(numbers, kind="Fold", flags=[True, False])
    assert _verdicts(numbers, a, b) == {"kind": "differs", "flags": "differs"}


def test_values_near_zero_are_judged_on_the_array_scale(numbers: ModuleType) -> None:
    a = _entries(numbers, x=[1.0, 1e-20], y=[1e-20, 2e-20])
    b = _entries(numbers, x=[1.0, 2e-20], y=[1e-20, 2.1e-20])
    assert _verdicts(numbers, a, b) == {"x": "equal", "y": "differs"}
