"""numba's ``njit``, caching compiled code where it can and compiling afresh where it cannot.

The compiled kernels are cached on disk (``cache=True``) so that only the first run
compiles. numba stores the cache beside the source (``__pycache__``), else in the
user's cache folder, or in ``NUMBA_CACHE_DIR`` when that environment variable is
set. In a read-only install with no writable cache folder numba refuses to
decorate (``cannot cache function ...: no locator available``), which would make
``import clearjoint.simulate`` fail: here the function is compiled without a disk
cache instead, with one warning that says how to get the cache back
(``NUMBA_CACHE_DIR=/a/writable/folder``). docs/simulate.md, "Start-up and the
compiled-code cache".
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, overload

from numba import njit as _njit

_warned = False

#: Source files whose compiled functions other files' kernels call (and numba inlines).
#: numba's cache notices a change to a kernel's own file only, so a change to one of these
#: would leave the kernels that call it compiled from the old code: they are dropped.
DEPENDENCIES = ("laws/clearance.py", "exact/kernel.py")
STAMP_NAME = "numba-dependencies.sha256"


def drop_stale_caches(root: Path | None = None) -> bool:
    """Delete the package's numba caches when a file in ``DEPENDENCIES`` changed; say if so.

    The digest of those files is kept beside the caches (``__pycache__/`` of the package
    and, when set, ``NUMBA_CACHE_DIR``); when it differs, every cached kernel of the
    package (``*.nbi``, ``*.nbc``) is removed, so that the next call compiles from the
    code as it is. A cache folder that cannot be written is left as it is.
    """
    root = Path(__file__).resolve().parent if root is None else root
    digest = hashlib.sha256()
    for name in DEPENDENCIES:
        try:
            digest.update((root / name).read_bytes())
        except OSError:
            return False
    text = digest.hexdigest()
    folders = [(root, root / "__pycache__" / STAMP_NAME)]
    if os.environ.get("NUMBA_CACHE_DIR"):
        cache_dir = Path(os.environ["NUMBA_CACHE_DIR"])
        folders.append((cache_dir, cache_dir / f"clearjoint-{STAMP_NAME}"))
    dropped = False
    for folder, stamp in folders:
        try:
            if stamp.read_text(encoding="ascii") == text:
                continue
        except OSError:
            pass
        try:  # the stamp first: where it cannot be written, nothing is deleted either
            stamp.parent.mkdir(parents=True, exist_ok=True)
            stamp.write_text(text, encoding="ascii")
        except OSError:
            continue
        for cached in (*folder.rglob("*.nbi"), *folder.rglob("*.nbc")):
            if folder == root or "clearjoint" in str(cached):
                with contextlib.suppress(OSError):
                    cached.unlink()
                    dropped = True
    return dropped


drop_stale_caches()

F = TypeVar("F", bound=Callable[..., Any])


class CacheWarning(UserWarning):
    """numba found nowhere writable for its cache: the kernels compile on every run."""


@overload
def njit(function: F, /) -> F: ...


@overload
def njit(*, cache: bool = False, **options: Any) -> Callable[[F], F]: ...


def njit(*args: Any, cache: bool = False, **options: Any) -> Any:
    """``numba.njit``, with ``cache=True`` falling back to no disk cache where none is writable.

    Used exactly as ``numba.njit``: ``@njit``, ``@njit(cache=True)``. For type checkers
    the compiled function keeps the Python function's signature.
    """

    def decorate(function: Callable[..., Any]) -> Any:
        global _warned
        if not cache:
            return _njit(**options)(function)
        try:
            return _njit(cache=True, **options)(function)
        except RuntimeError as exc:
            if "cannot cache" not in str(exc):
                raise
            if not _warned:
                _warned = True
                warnings.warn(
                    "clearjoint: numba has no writable cache folder, so the simulation kernels "
                    "compile on every run; set NUMBA_CACHE_DIR to a writable folder",
                    CacheWarning,
                    stacklevel=2,
                )
            return _njit(**options)(function)

    if len(args) == 1 and callable(args[0]) and not options:
        return decorate(args[0])
    return decorate
