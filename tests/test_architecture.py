"""The package's shape (issue 23): no import cycle, no private name across packages, a thin CLI.

Read from the source with ``ast``, not by importing. Every import statement counts,
those inside functions too: an import deferred into a function to get round a circle is
still a circle between the two modules. ``if TYPE_CHECKING:`` blocks are left out (they
never run). A module's package is its folder: ``clearjoint.simulate`` for
``simulate/core.py``, ``clearjoint`` for ``periodic.py``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "clearjoint"


def _modules() -> dict[str, Path]:
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


MODULES = _modules()


def _package_of(module: str) -> str:
    path = MODULES[module]
    return module if path.name == "__init__.py" else module.rpartition(".")[0]


def _runtime_imports(tree: ast.Module) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement of a module, at any depth, but those under ``TYPE_CHECKING``."""
    found: list[ast.Import | ast.ImportFrom] = []

    def walk(node: ast.AST) -> None:
        if isinstance(node, ast.Import | ast.ImportFrom):
            found.append(node)
        elif isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.orelse:
                walk(child)
        else:
            for child in ast.iter_child_nodes(node):
                walk(child)

    walk(tree)
    return found


def _absolute(module: str, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    base = _package_of(module).split(".")
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str) -> list[tuple[str, str]]:
    """(imported module, imported name or '') for each runtime import of clearjoint code."""
    tree = ast.parse(MODULES[module].read_text(encoding="utf-8"))
    edges = []
    for node in _runtime_imports(tree):
        if isinstance(node, ast.Import):
            edges += [(a.name, "") for a in node.names if a.name.startswith("clearjoint")]
            continue
        target = _absolute(module, node)
        if not target.startswith("clearjoint"):
            continue
        for alias in node.names:
            sub = f"{target}.{alias.name}"
            edges.append((sub, "") if sub in MODULES else (target, alias.name))
    return edges


def _graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {m: set() for m in MODULES}
    for module in MODULES:
        for target, _ in _imports(module):
            # importing a.b.c runs a/__init__, a/b/__init__ and a/b/c; the packages that
            # hold the importer itself are loaded already, so they are no edge
            parts = target.split(".")
            for k in range(1, len(parts) + 1):
                name = ".".join(parts[:k])
                if name in MODULES and name != module and not module.startswith(name + "."):
                    graph[module].add(name)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                out.append(sorted(part))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_checks_see_a_cycle_and_a_private_import() -> None:
    # the two checks below on made-up graphs and sources, so that they can fail
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []
    tree = ast.parse("from x import y\nif TYPE_CHECKING:\n    import z\ndef f():\n    import w\n")
    assert [ast.unparse(n) for n in _runtime_imports(tree)] == ["from x import y", "import w"]


def test_no_import_cycle() -> None:
    assert _cycles(_graph()) == []


def _private_crossings() -> list[str]:
    bad = []
    for module in MODULES:
        here = _package_of(module)
        for target, name in _imports(module):
            if target not in MODULES:
                continue
            private_module = any(p.startswith("_") for p in target.split(".")[1:])
            there = _package_of(target)
            if name.startswith("_") and not name.startswith("__") and there != here:
                bad.append(f"{module} imports {name} from {target}")
            elif private_module and name == "" and there != here and target != module:
                owner = target.rpartition(".")[0]
                if owner != here:
                    bad.append(f"{module} imports the private module {target}")
    return bad


def test_no_private_name_is_imported_across_packages() -> None:
    assert _private_crossings() == []


@pytest.mark.parametrize(("module", "most"), [("clearjoint.cli", 700)])
def test_the_command_line_is_thin(module: str, most: int) -> None:
    lines = MODULES[module].read_text(encoding="utf-8").count("\n")
    assert lines <= most, f"{module} has {lines} lines; parsing and printing fit in {most}"
