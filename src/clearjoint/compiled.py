"""The solvers' kernels compiled ahead of time, at install, so that a first run compiles nothing.

Every numba kernel that clearjoint's Python code calls on the way of a documented
command is compiled at first use (``clearjoint.jit``), and cached on disk; the first run
of ``clearjoint frf`` spends about seven-eighths of its time compiling (issue 28,
``benchmarks/bench_cold.py``). Here the same kernels, from the same source, are compiled
by ``numba.pycc`` into one extension module when the package is built (the build hook
``hatch_build.py`` calls :func:`build`; ``python -m clearjoint.compiled`` does it by hand).
The Python callers then call the extension's functions (:func:`prefer`), and the JIT
kernels, numba's cache and its compile are not touched.

The module is used only when it was built from the kernels' source as it is now: its
name carries a digest of every package file that holds a kernel (:func:`source_digest`),
so a changed kernel, an upgrade, or an editable checkout on another commit finds no
module of that name and falls back to the JIT kernels, as does a machine where it could
not be built (no C compiler), or ``CLEARJOINT_COMPILED=0`` in the environment (or
``NUMBA_DISABLE_JIT=1``, which asks for the kernels as plain Python). A call
with argument types the export does not take (its signatures are in :data:`EXPORTS`)
goes to the JIT kernel too. The exported code is numba's own lowering of the same
Python functions, for a generic CPU of the machine's family; the suite checks that the
two give equal results to the bit (``tests/test_compiled.py``). docs/simulate.md,
"Start-up and the compiled-code cache".
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import os
import re
import sys
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any, TypeVar

import numpy as np

F = TypeVar("F", bound=Callable[..., Any])

_A1 = "f8[::1]"
_A2 = "f8[:, ::1]"
_I1 = "i8[::1]"  # int64
_B1 = "i1[::1]"  # int8 (contact states)
_B2 = "i1[:, ::1]"
_F2 = "f8[::1, :]"  # Fortran order


def _arguments(*kinds: str) -> str:
    return ", ".join(kinds)


_MARCH = _arguments(
    _A1, _B1, "f8", _A1, "f8", "i8", "f8", "f8", "f8", _A1, _A1, _I1, _I1, _A1, _A1, _I1, _I1,
    _A1, _I1, _I1, _A1, _A2, _A2, _A1, _A1, _A1, _A1, "f8", "i8", _A2, _B2, _A1, _A1, "f8",
)  # fmt: skip

_ONE_DOF = _arguments(
    _A1, _A1, _A1, _A1, _A1, _A1, _A2, _F2, _A2, _A1, _A2, _A2
)  # fmt: skip

#: The kernels called from Python on the way of the documented commands, with the one
#: signature each is called with: (module, name, numba signature).
EXPORTS: tuple[tuple[str, str, str], ...] = (
    (
        "clearjoint.exact.kernel",
        "advance",
        f"UniTuple(i8, 4)({_A1}, {_A1}, i8, f8, b1, {_A2}, {_A2}, {_A2}, {_A2})",
    ),
    ("clearjoint.exact.kernel", "region_of", f"i8({_A1}, f8, f8)"),
    ("clearjoint.exact.kernel", "decide_slip", f"i8({_A1}, i8, f8, f8)"),
    ("clearjoint.exact.kernel", "sample", f"void({_A1}, {_A2}, i8, {_A1}, {_A2})"),
    ("clearjoint.exact.shooting", "start_state", f"void({_A1}, f8, f8, {_A1})"),
    ("clearjoint.exact.shooting", "shoot_map", f"i8({_A1}, {_A1}, i8, {_A1}, i8)"),
    (
        "clearjoint.exact.shooting",
        "correct_orbit",
        f"i8({_A1}, i8, {_A1}, {_A1}, {_A1}, b1, f8, i8, {_A1}, {_A2}, {_A1})",
    ),
    (
        "clearjoint.exact.shooting",
        "arclength_step",
        f"i8({_A1}, i8, {_A2}, f8, {_A1}, {_A1}, {_A1}, f8, i8, {_A1}, {_A2}, {_A1}, {_A1})",
    ),
    ("clearjoint.continuation", "tangent_solve", f"b1({_A2}, {_A1}, {_A1})"),
    (
        "clearjoint.laws.clearance",
        "forces_and_tangents",
        f"UniTuple({_A2}, 2)({_A2}, {_A1}, {_A1}, {_A1}, {_A1}, {_A1})",
    ),
    ("clearjoint.laws.clearance", "potentials", f"{_A2}({_A2}, {_A1}, {_A1}, {_A1}, {_A1}, {_A1})"),
    ("clearjoint.laws.clearance", "contact_forces", f"{_A2}({_A2}, {_A1}, {_A1}, {_A1}, {_A1})"),
    ("clearjoint.laws.clearance", "state_law", "UniTuple(f8, 2)(i8, f8, f8, f8, f8, f8)"),
    ("clearjoint.laws.clearance", "contact_states", f"{_B1}({_A1}, {_A1}, {_A1}, {_A1})"),
    (
        "clearjoint.laws.clearance",
        "state_tables",
        f"UniTuple({_A2}, 2)({_A1}, {_A1}, {_A1}, {_A1}, {_A1})",
    ),
    (
        "clearjoint.exact.march",
        "march",
        f"Tuple(({_A1}, {_B1}, f8, {_A1}, {_I1}, {_B1}, i8, i8))({_MARCH})",
    ),
    ("clearjoint.exact.march", "pattern_history", f"{_B2}({_B1}, {_I1}, {_B1})"),
    ("clearjoint.continuation", "extrapolate", f"{_A1}({_A2}, f8)"),
    (
        "clearjoint.harmonic.aft",
        "_evaluate_one_dof",
        f"Tuple(({_A1}, {_A2}, {_A1}, {_A2}))({_A1}, f8, f8, f8, f8, f8, {_ONE_DOF})",
    ),
    (
        "clearjoint.harmonic.aft",
        "_correct_one_dof",
        f"Tuple((i8, {_A1}, {_A2}, i8, {_A1}, {_A2}, {_A1}, {_A2}))"
        f"({_A1}, {_A1}, {_A1}, f8, i8, b1, f8, f8, f8, f8, f8, {_ONE_DOF})",
    ),
)

#: Set to ``0`` to use the JIT kernels even where the compiled module is present.
SWITCH = "CLEARJOINT_COMPILED"
PREFIX = "_kernels_"
_PACKAGE = Path(__file__).resolve().parent
_KERNEL_FILE = re.compile(rb"^\s*@njit", re.MULTILINE)
_NOT_LOADED = object()
_loaded: Any = _NOT_LOADED
_preferred: dict[str, tuple[Any, Any]] = {}


def source_digest(root: Path | None = None) -> str:
    """The first 16 hex digits of the SHA-256 of every package file that defines a kernel.

    Files are taken in sorted order by their path inside the package, with this module
    (which holds the signatures) among them; a change to any kernel's source changes it.
    """
    root = _PACKAGE if root is None else root
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        text = path.read_bytes()
        if _KERNEL_FILE.search(text) or path.name == "compiled.py":
            digest.update(path.relative_to(root).as_posix().encode())
            digest.update(text)
    return digest.hexdigest()[:16]


def module_name(root: Path | None = None) -> str:
    """The name of the extension module built from the kernels' source as it is now."""
    return PREFIX + source_digest(root)


def load() -> ModuleType | None:
    """The compiled module for the current source, or None (absent, stale, switched off).

    Looked up once per process: a module that fails to import (built against another
    numpy, say) counts as absent.
    """
    global _loaded
    if _loaded is _NOT_LOADED:
        _loaded = None
        from numba.core import config

        # NUMBA_DISABLE_JIT=1 asks for the kernels as plain Python: the module is not that
        if os.environ.get(SWITCH, "1").strip() != "0" and not config.DISABLE_JIT:  # type: ignore[attr-defined]
            try:
                _loaded = importlib.import_module(f"clearjoint.{module_name()}")
            except ImportError:
                _loaded = None
    return _loaded  # type: ignore[no-any-return]


def prefer(kernel: F) -> F:
    """``kernel`` (a numba dispatcher) as compiled at install when that is usable, else itself.

    For Python callers only: numba kernels must go on calling the dispatcher. The
    returned function takes the same arguments. The extension's functions convert their
    arguments without a check (a float32 array would crash the process), so each call's
    arguments are checked against the export's signature first (float64 arrays of the
    right rank, C-contiguous and writable; ints; floats; bools), and any other call
    (keyword arguments included) runs the JIT kernel, as does a kernel of an exported
    name from another module than the export's.
    """
    name = getattr(kernel, "__name__", "")
    if _preferred.get(name, (None,))[0] is kernel:
        return _preferred[name][1]  # type: ignore[no-any-return]
    # the export of that name is this kernel only if it comes from the module it was
    # exported from: another module's kernel of the same name is not the compiled one
    if _MODULES.get(name) != getattr(kernel, "__module__", None):
        return kernel
    module = load()
    exported = getattr(module, name, None) if module is not None else None
    if exported is None:
        return kernel
    kinds = argument_kinds(_SIGNATURES[name])

    @functools.wraps(kernel)
    def call(*args: Any, **keywords: Any) -> Any:
        # the extension takes its arguments by position only, in the signature's types
        if (
            not keywords
            and len(args) == len(kinds)
            and all(_ACCEPTS[kind](value) for kind, value in zip(kinds, args, strict=True))
        ):
            return exported(*args)
        return kernel(*args, **keywords)

    call.jit = kernel  # type: ignore[attr-defined]
    _preferred[name] = (kernel, call)
    return call  # type: ignore[return-value]


def argument_kinds(signature: str) -> tuple[str, ...]:
    """The kinds of a signature's arguments in :data:`EXPORTS`, as written there."""
    # the arguments are the last parenthesised group: "UniTuple(i8, 4)(f8[::1], i8)"
    start = signature.rindex(")(") + 2 if ")(" in signature else signature.index("(") + 1
    parts = re.split(r",\s*(?![^\[]*\])", signature[start:-1])
    return tuple(part.strip() for part in parts)


def _array(dtype: type, rank: int, order: str = "C") -> Callable[[Any], bool]:
    def accepts(value: Any) -> bool:
        return (
            type(value) is np.ndarray
            and value.dtype == dtype
            and value.ndim == rank
            and (value.flags.c_contiguous if order == "C" else value.flags.f_contiguous)
            and value.flags.writeable
            and value.flags.aligned
        )

    return accepts


def _integer(value: Any) -> bool:
    return isinstance(value, int | np.integer) and -(2**63) <= int(value) < 2**63


def _real(value: Any) -> bool:
    return isinstance(value, float | int | np.floating | np.integer) and not isinstance(
        value, np.longdouble | np.complexfloating
    )


def _boolean(value: Any) -> bool:
    return isinstance(value, bool | np.bool_)


#: What each argument kind of a signature in EXPORTS takes.
_ACCEPTS: dict[str, Callable[[Any], bool]] = {
    _A1: _array(np.float64, 1),
    _A2: _array(np.float64, 2),
    _I1: _array(np.int64, 1),
    _B1: _array(np.int8, 1),
    _B2: _array(np.int8, 2),
    _F2: _array(np.float64, 2, order="F"),
    "i8": _integer,
    "f8": _real,
    "b1": _boolean,
}
_SIGNATURES = {kernel: signature for _, kernel, signature in EXPORTS}
_MODULES = {kernel: module for module, kernel, _ in EXPORTS}


def build(folder: Path | None = None, *, quiet: bool = True) -> Path:
    """Compile :data:`EXPORTS` with everything they call into the module for this source.

    Writes ``_kernels_<digest>.<extension suffix>`` into ``folder`` (by default the
    package's own folder), after removing older ``_kernels_*`` modules there, and returns
    its path; an up-to-date module is left as it is. Needs numba's ``pycc`` and a C
    compiler; any failure raises (the build hook turns it into a warning).
    """
    import warnings

    folder = _PACKAGE if folder is None else Path(folder)
    name = module_name()
    suffix = _extension_suffix()
    target = folder / f"{name}{suffix}"
    if target.exists():
        return target
    for old in folder.glob(f"{PREFIX}*"):
        old.unlink()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numba.pycc's pending deprecation
        from numba.pycc import CC  # type: ignore[attr-defined]

        cc = CC(name)  # type: ignore[no-untyped-call]
        cc.output_dir = str(folder)
        cc.verbose = not quiet
        for module, kernel, signature in EXPORTS:
            dispatcher = getattr(importlib.import_module(module), kernel)
            cc.export(kernel, signature)(dispatcher.py_func)  # type: ignore[no-untyped-call]
        cc.compile()
    if not target.exists():
        raise RuntimeError(f"numba.pycc wrote no {target.name} in {folder}")
    return target


def _extension_suffix() -> str:
    import importlib.machinery

    return importlib.machinery.EXTENSION_SUFFIXES[0]


def main(argv: list[str] | None = None) -> int:
    """``python -m clearjoint.compiled [FOLDER]``: build the module, print its path."""
    args = sys.argv[1:] if argv is None else argv
    path = build(Path(args[0]) if args else None, quiet=False)
    print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
