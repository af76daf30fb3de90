"""How far a long computation has come, told to whoever listens (the command line's bar).

A solver's loop calls :func:`report` with what it has done of what it has to do (points of
a continuation's parameter range, amplitudes of a mode, steps of an integration); nothing
listens unless a caller wrapped the work in :func:`listening`, so the library is silent and
the cost of a report is one context-variable lookup. No physics here, and no printing: the
command line decides how progress is shown (a rich bar on a terminal, a line every few
seconds otherwise; clearjoint.cli).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from contextvars import ContextVar

__all__ = ["Listener", "listening", "report", "silenced"]

#: A listener: called with (done, total), in any units the reporting loop counts in.
Listener = Callable[[float, float], None]

_LISTENER: ContextVar[Listener | None] = ContextVar("clearjoint_progress", default=None)


def report(done: float, total: float) -> None:
    """Tell the listener, if any, that ``done`` of ``total`` is done (``0 <= done <= total``)."""
    listener = _LISTENER.get()
    if listener is not None and total > 0.0:
        listener(min(max(float(done), 0.0), float(total)), float(total))


@contextlib.contextmanager
def listening(listener: Listener) -> Iterator[None]:
    """Send the reports made inside the ``with`` block (in this thread) to ``listener``."""
    token = _LISTENER.set(listener)
    try:
        yield
    finally:
        _LISTENER.reset(token)


@contextlib.contextmanager
def silenced() -> Iterator[None]:
    """Drop the reports made inside the ``with`` block: a solver run as one step of a loop
    that reports in its own units (a test of the rig's campaign, counted in tests, whose
    transient would report seconds of motion)."""
    token = _LISTENER.set(None)
    try:
        yield
    finally:
        _LISTENER.reset(token)
