"""One compiled copy of each kernel: no call between kernels that makes numba compile another.

numba compiles a kernel once per distinct tuple of argument types. Inside a kernel, a
literal int or bool argument (``f(x, 1)``, ``f(x, False)``: Literal[int](1),
Literal[bool](False)), a module constant of those types (frozen as a literal too) or a
default left out (``omitted``) is a type of its own, so each such call compiled the
whole callee again: three copies of ``shoot_map`` and two of ``correct_orbit`` made about
a third of the first run of ``clearjoint frf examples/frf.toml --from 10Hz --to 360Hz``
(issue 28). Read from the kernels' source, so that it holds whatever the compile cache
holds.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import textwrap
from collections.abc import Callable
from typing import Any

import pytest
from numba.core.registry import CPUDispatcher

MODULES = (
    "clearjoint.continuation",
    "clearjoint.exact.kernel",
    "clearjoint.exact.march",
    "clearjoint.exact.shooting",
    "clearjoint.harmonic.aft",
    "clearjoint.laws.clearance",
)


def _resolve(module: Any, node: ast.expr) -> Any:
    """What a name or ``alias.name`` in the module's namespace stands for (None if unknown)."""
    if isinstance(node, ast.Name):
        return getattr(module, node.id, None)
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
        return getattr(getattr(module, node.value.id, None), node.attr, None)
    return None


def _second_copies(name: str, source: Callable[[Any], str] = inspect.getsource) -> list[str]:
    """The calls between the module's kernels that would compile a callee a second time."""
    module = importlib.import_module(name)
    found = []
    for kernel_name, kernel in vars(module).items():
        if not isinstance(kernel, CPUDispatcher) or kernel.py_func.__module__ != name:
            continue
        for node in ast.walk(ast.parse(textwrap.dedent(source(kernel.py_func)))):
            if not isinstance(node, ast.Call):
                continue
            callee = _resolve(module, node.func)
            if not isinstance(callee, CPUDispatcher):
                continue
            where = f"{kernel_name} -> {callee.py_func.__name__}"
            given = len(node.args) + len(node.keywords)
            if given != len(inspect.signature(callee.py_func).parameters):
                found.append(f"a default left out in {where}")
            for arg in node.args:
                value = arg.operand if isinstance(arg, ast.UnaryOp) else arg
                if isinstance(value, ast.Constant) and isinstance(value.value, int):
                    found.append(f"a literal in {where}")
                elif isinstance(_resolve(module, value), int):  # bool is an int too
                    found.append(f"a module constant in {where}")
    return found


@pytest.mark.parametrize("name", MODULES)
def test_kernels_call_kernels_with_one_tuple_of_types(name: str) -> None:
    assert _second_copies(name) == []


def test_the_check_finds_the_calls_that_compiled_second_copies() -> None:
    """As the code stood before: a literal False, a literal 1 and a default left out."""

    def before(function: Any) -> str:
        text = inspect.getsource(function)
        text = text.replace("bool(False)", "False").replace("int(1)", "1")
        return text.replace("(q, shifted, once, o2, int(NO_PARAMETER))", "(q, shifted, 1, o2)")

    assert sorted(_second_copies("clearjoint.exact.shooting", before)) == [
        "a default left out in map_residual -> shoot_map",
        "a literal in arclength_step -> correct_orbit",
        "a literal in map_residual -> shoot_map",
    ]
