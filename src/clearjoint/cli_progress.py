"""The command line's progress display and Ctrl-C handling: what the user sees while a
command works, and the one line it ends with when interrupted. No physics here.

Progress: a rich bar with the time left on a terminal, a line every
:data:`PROGRESS_EVERY_S` seconds otherwise (a log file, a CI job), nothing with --quiet; the
solvers report through :mod:`clearjoint.progress`. Ctrl-C: the command's SIGINT handler
notes it (a KeyboardInterrupt raised inside a callback from compiled code is otherwise
lost); :func:`interrupted` says what was left and ends with exit code 130.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from clearjoint.budget import for_people


def progress_bar(*columns: Any) -> Any:
    """A rich progress bar on stderr, drawn only on a terminal (stdout stays the output)."""
    from rich.console import Console
    from rich.progress import Progress

    return Progress(
        *columns, console=Console(stderr=True), transient=True, disable=not sys.stderr.isatty()
    )


#: Seconds between two progress lines when stderr is no terminal (a log file, a CI job).
PROGRESS_EVERY_S = 10.0
#: Progress lines when main() is called from Python rather than run as the command: off, so
#: that a caller's stderr holds only warnings and errors (the bar on a terminal stays).
PROGRESS_LINES_IN_PROCESS = False


@contextlib.contextmanager
def shown_progress(
    args: argparse.Namespace, what: str, *, announce: bool = False
) -> Iterator[Callable[[float, float], None]]:
    """Show how far the work inside has come; yield the listener ``(done, total)``.

    On a terminal: a rich bar with the time left. Otherwise: one line saying ``what`` at
    the first report (or at once with ``announce``; not by default, since the work may
    still refuse its input, in one line of its own), then one every
    :data:`PROGRESS_EVERY_S` seconds with the share done and the time left, when run as
    the command (see
    :data:`PROGRESS_LINES_IN_PROCESS`). Nothing with ``--quiet``. The solvers' own reports
    (clearjoint.progress) go to the same listener; the first series of reports to finish
    (done = total) ends the display, so that the smaller loops of the work that follows
    (a study's analysis after its campaign) do not restart it.
    """
    from clearjoint.progress import listening

    quiet = getattr(args, "quiet", False)
    terminal = not quiet and sys.stderr.isatty()
    quiet = quiet or not (terminal or getattr(args, "progress_lines", False))
    seen: dict[str, float | bool] = {
        "done": 0.0,
        "finished": False,
        "announced": announce or quiet,
        "at": 0.0,
    }

    def say(text: str) -> None:
        print(f"clearjoint {args.command}: {text}", file=sys.stderr, flush=True)

    if announce and not quiet and not terminal:
        say(what)
    with contextlib.ExitStack() as stack:
        bar = stack.enter_context(progress_bar(*bar_columns())) if terminal else None
        task = bar.add_task(what, total=None) if bar is not None else None

        def listener(done: float, total: float) -> None:
            stop_if_interrupted()
            if quiet or seen["finished"]:
                return
            seen["done"] = done = max(done, float(seen["done"]))  # a fold may step back
            seen["finished"] = done >= total
            if bar is not None:
                bar.update(task, completed=done, total=total)
                return
            now = time.perf_counter()
            if not seen["announced"]:
                seen["announced"] = True
                say(what)
            if "first" not in seen:  # the rate is taken from here: a compile came before
                seen["first"], seen["from"] = now, done
            ran, went = now - float(seen["first"]), done - float(seen["from"])
            # the time left is told from a rate measured over PROGRESS_EVERY_S at least: just
            # after a compile the first two reports are milliseconds apart ("0 s left")
            if now - max(float(seen["first"]), float(seen["at"])) < PROGRESS_EVERY_S or went <= 0.0:
                return
            seen["at"] = now
            left = ran * (total - done) / went
            say(f"{100.0 * done / total:.0f} % done, about {for_people(left)} left")

        stack.enter_context(listening(listener))
        if not quiet:
            stack.enter_context(compile_notice(say))
        yield listener


@contextlib.contextmanager
def compile_notice(say: Callable[[str], None]) -> Iterator[None]:
    """Say once, when numba starts compiling inside the block, that this is a first run.

    A compile happens when the on-disk cache of compiled solvers is empty or stale (a
    fresh install, an upgrade, a changed NUMBA_CACHE_DIR); a cached kernel only loads.
    """
    from numba.core import event

    told: list[bool] = []

    class Notice(event.Listener):
        def on_start(self, _event: Any) -> None:
            if not told:
                told.append(True)
                say("compiling the solvers, first run only")

        def on_end(self, _event: Any) -> None:
            pass

    notice = Notice()
    event.register("numba:compile", notice)  # type: ignore[no-untyped-call]
    try:
        yield
    finally:
        event.unregister("numba:compile", notice)  # type: ignore[no-untyped-call]


def bar_columns() -> tuple[Any, ...]:
    """The progress bar's columns: rich's default ones, the time left last."""
    from rich.progress import Progress, TimeRemainingColumn

    return (*Progress.get_default_columns()[:-1], TimeRemainingColumn())


#: Set by Ctrl-C (see :func:`on_interrupt`); stays set for the rest of the command.
CTRL_C = threading.Event()


def on_interrupt(_signum: int, _frame: Any) -> None:
    """The command's SIGINT handler: note the Ctrl-C, then raise KeyboardInterrupt as Python does.

    Raised inside a callback from compiled code (numba's compiler calls back into Python), the
    KeyboardInterrupt is printed as "Exception ignored" and lost; the note makes the next
    progress report (:func:`stop_if_interrupted`), or the end of the command, stop it.
    """
    CTRL_C.set()
    raise KeyboardInterrupt


def unraisable(unraisable: Any) -> None:
    """sys.unraisablehook: a Ctrl-C lost in a callback is noted (not printed as a traceback)."""
    if isinstance(unraisable.exc_value, KeyboardInterrupt):
        CTRL_C.set()
        return
    sys.__unraisablehook__(unraisable)


def stop_if_interrupted(_done: float = 0.0, _total: float = 0.0) -> None:
    """Raise KeyboardInterrupt if Ctrl-C was pressed (a progress listener, so it is checked
    at every report of the solvers)."""
    if CTRL_C.is_set():
        raise KeyboardInterrupt


#: What an interrupted command leaves, beyond its partial files (removed), by command.
LEFT_ON_INTERRUPT = {
    "rig": "the finished records are kept in {out}: run the same command again to "
    "simulate only the rest",
    "reproduce": "the finished records are kept in {out}/records: run the same command "
    "again to simulate only the rest",
    "sweep": "finished chunks are in {out}: run again with --resume to compute only the rest",
}


def caused_by_interrupt(exc: BaseException) -> bool:
    """Whether a KeyboardInterrupt is ``exc`` or in the chain of errors that led to it."""
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        if isinstance(current, KeyboardInterrupt):
            return True
        seen.add(id(current))
        current = current.__cause__ or current.__context__
    return False


def interrupted(args: argparse.Namespace, started: float, *, end: bool = False) -> int:
    """Say in one line that the command was interrupted and what it left; return 130.

    A file output (--out, --plot) written since the command started is incomplete: removed.
    With ``end`` (the command itself, not a caller of main) the process ends here with 130:
    the work was stopped and its pools and clusters closed on the way out, while the
    interpreter's own shutdown after a Ctrl-C sometimes ended the process by SIGINT
    instead (exit -2, seen about one run in four of tests/test_interrupt.py's modes case;
    the cause was not traced).
    """
    removed = []
    for option in ("out", "plot"):
        name = getattr(args, option, None)
        path = Path(name) if isinstance(name, str) else None
        if path is not None and path.is_file() and path.stat().st_mtime >= started - 1.0:
            with contextlib.suppress(OSError):
                path.unlink()
                removed.append(str(path))
    left = LEFT_ON_INTERRUPT.get(args.command, "nothing written")
    if removed:
        left = f"removed the incomplete {' and '.join(removed)}"
    print(
        f"clearjoint {args.command}: interrupted; " + left.format(out=getattr(args, "out", "")),
        file=sys.stderr,
    )
    if end:
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(130)
    return 130
