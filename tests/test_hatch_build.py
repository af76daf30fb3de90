"""hatch_build: a failed compile at install is reported by the line that says why.

hatchling is not needed: the hook's base class is stood in for, since only the module's
function that picks the reason is tested here (the install itself is checked by hand, as
the README's commands; tests/test_compiled.py checks the module it builds).
"""

from __future__ import annotations

import importlib.util
import sys
import types
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: What ``CC=/bin/false python -m clearjoint.compiled`` wrote to stderr (numba 0.68), cut.
NO_COMPILER = """\
Traceback (most recent call last):
  File "/x/numba/pycc/platform.py", line 130, in _raise_external_compiler_error
    raise RuntimeError(msg)
RuntimeError: Attempted to compile AOT function without the compiler used by `numpy.distutils` present. If using conda try:
#> conda install gcc_linux-64 gxx_linux-64
"""  # noqa: E501


def _hook_module(monkeypatch: pytest.MonkeyPatch) -> types.ModuleType:
    interface = types.ModuleType("hatchling.builders.hooks.plugin.interface")
    interface.BuildHookInterface = object  # type: ignore[attr-defined]
    for name in ("hatchling", "hatchling.builders", "hatchling.builders.hooks"):
        monkeypatch.setitem(sys.modules, name, types.ModuleType(name))
    monkeypatch.setitem(sys.modules, "hatchling.builders.hooks.plugin", types.ModuleType("p"))
    monkeypatch.setitem(sys.modules, interface.__name__, interface)
    spec = importlib.util.spec_from_file_location("hatch_build", ROOT / "hatch_build.py")
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_missing_c_compiler_is_reported_by_numbas_error_not_its_conda_hint(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    reason = _hook_module(monkeypatch).failure_reason(NO_COMPILER)
    assert reason.startswith("RuntimeError: Attempted to compile AOT function without the compiler")


def test_output_without_an_exception_gives_its_last_line(monkeypatch: pytest.MonkeyPatch) -> None:
    hook = _hook_module(monkeypatch)
    assert hook.failure_reason("one\ntwo\n\n") == "two"
    assert hook.failure_reason("") == "no output"
