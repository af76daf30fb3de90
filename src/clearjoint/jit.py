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

import warnings
from collections.abc import Callable
from typing import Any, TypeVar, overload

from numba import njit as _njit

_warned = False

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
