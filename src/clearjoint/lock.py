"""One writer per result store: a lock file beside it, with a heartbeat.

No physics here. A run that writes ``results.zarr`` first creates ``results.zarr.lock``
(atomically: ``O_CREAT | O_EXCL``, so of two clients starting at once exactly one gets
it) holding the host, PID and start time of its holder, a token and a heartbeat time
that a thread of the holder renews every ``timeout / 4`` seconds. The lock is taken
before the store is created, opened or deleted (``force``), and removed at the end.

A second client finds the lock and is refused with one line naming the holder. A lock
whose heartbeat is older than ``timeout`` seconds (its holder was killed, or its
machine lost) is *stale*: it is taken over, with one :class:`~clearjoint.store.StoreWarning`
line that says whose it was. A holder whose lock was taken over (it stalled for longer
than ``timeout``) finds out at its next heartbeat and stops writing
(:meth:`StoreLock.check`).

Heartbeats compare wall clocks: the hosts sharing a store should agree on the time to
well within ``timeout`` (NTP does).
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import threading
import time
import uuid
import warnings
from datetime import UTC, datetime
from pathlib import Path
from types import TracebackType
from typing import Any

from clearjoint.store import StoreError, StoreWarning

__all__ = [
    "LOCK_TIMEOUT_S",
    "StoreLock",
]

#: Seconds without a heartbeat after which a store's lock is stale and taken over.
LOCK_TIMEOUT_S = 60.0


def _read(file: Path) -> dict[str, Any] | None:
    """The lock's contents; None if it is gone; {} if it cannot be read (being written)."""
    try:
        text = file.read_text(encoding="utf-8")
    except FileNotFoundError:
        return None
    except OSError:
        return {}
    try:
        data = json.loads(text)
    except ValueError:
        return {}
    return data if isinstance(data, dict) else {}


def _holder(data: dict[str, Any]) -> str:
    if not data:
        return "a client whose lock file cannot be read"
    return f"{data.get('host', '?')} PID {data.get('pid', '?')} (since {data.get('started', '?')})"


class StoreLock:
    """The lock of the store at ``store`` (see the module docstring); a context manager.

    Parameters
    ----------
    store : path
        The store; the lock is the file ``<store>.lock`` beside it.
    timeout : float
        Seconds without a heartbeat after which the lock is stale (default
        :data:`LOCK_TIMEOUT_S`).
    """

    def __init__(self, store: str | Path, *, timeout: float = LOCK_TIMEOUT_S) -> None:
        if not timeout > 0:
            raise StoreError(f"the lock timeout must be > 0 s, got {timeout!r}")
        self.store = Path(store)
        self.file = Path(f"{store}.lock")
        self.timeout = float(timeout)
        self._token = uuid.uuid4().hex
        self._data: dict[str, Any] = {}
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._lost: str | None = None

    def __repr__(self) -> str:
        state = "held" if self._thread is not None else "not held"
        return f"StoreLock({str(self.file)!r}, {state}, timeout={self.timeout:g} s)"

    def __enter__(self) -> StoreLock:
        self.acquire()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.release()

    def acquire(self) -> None:
        """Take the lock, taking over a stale one (with a warning line).

        Raises
        ------
        StoreError
            Another client holds the lock and its heartbeat is fresh: one line naming it.
        """
        self.file.parent.mkdir(parents=True, exist_ok=True)
        for _ in range(5):
            if self._create():
                self._start_heartbeat()
                return
            data = _read(self.file)
            if data is None:  # released between our two looks: try again
                continue
            age = self._age(data)
            if age <= self.timeout:
                raise StoreError(
                    f"{self.store} is in use by {_holder(data)}, heartbeat {age:.0f} s ago; "
                    f"wait for it to end (a lock without heartbeat for {self.timeout:g} s is "
                    f"taken over: {self.file})"
                )
            if self._take_over(data):
                warnings.warn(
                    StoreWarning(
                        f"{self.store}: took over the lock of {_holder(data)}: no heartbeat "
                        f"for {age:.0f} s (more than {self.timeout:g} s)"
                    ),
                    stacklevel=2,
                )
        raise StoreError(f"{self.store}: its lock {self.file} keeps changing hands; try again")

    def _age(self, data: dict[str, Any]) -> float:
        beat = data.get("heartbeat")
        if not isinstance(beat, int | float):  # unreadable: judge by the file's own time
            with contextlib.suppress(OSError):
                beat = self.file.stat().st_mtime
        return time.time() - float(beat) if isinstance(beat, int | float) else 0.0

    def _contents(self) -> bytes:
        return json.dumps({**self._data, "heartbeat": time.time()}).encode("utf-8")

    def _create(self) -> bool:
        self._data = {
            "host": socket.gethostname(),
            "pid": os.getpid(),
            "started": datetime.now(UTC).isoformat(timespec="seconds"),
            "token": self._token,
        }
        try:
            fd = os.open(self.file, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            return False
        with os.fdopen(fd, "wb") as handle:
            handle.write(self._contents())
            handle.flush()
            os.fsync(handle.fileno())
        return True

    def _take_over(self, stale: dict[str, Any]) -> bool:
        """Move the stale lock aside if it is still the one judged stale; True if moved."""
        aside = self.file.with_name(f"{self.file.name}.stale-{self._token}")
        try:
            os.rename(self.file, aside)
        except FileNotFoundError:
            return False
        moved = _read(aside) or {}
        if moved.get("token") != stale.get("token"):  # a fresh lock was moved: put it back
            with contextlib.suppress(FileExistsError):
                os.link(aside, self.file)
            aside.unlink(missing_ok=True)
            return False
        aside.unlink(missing_ok=True)
        return True

    def _start_heartbeat(self) -> None:
        self._stop.clear()
        self._lost = None
        period = min(max(self.timeout / 4, 0.05), 15.0)
        self._thread = threading.Thread(
            target=self._beat, args=(period,), name="clearjoint-store-lock", daemon=True
        )
        self._thread.start()

    def _beat(self, period: float) -> None:
        while not self._stop.wait(period):
            data = _read(self.file)
            if data is None or data.get("token") != self._token:
                self._lost = _holder(data) if data else "nobody (the lock file is gone)"
                return
            temporary = self.file.with_name(f"{self.file.name}.{self._token}")
            try:
                temporary.write_bytes(self._contents())
                os.replace(temporary, self.file)
            except OSError:  # a file system hiccup: the next beat tries again
                continue

    def check(self) -> None:
        """Raise StoreError if the lock was taken over by another client (this run stalled)."""
        if self._lost is not None:
            raise StoreError(
                f"{self.store}: this run lost its lock to {self._lost} (no heartbeat for "
                f"more than {self.timeout:g} s); it stops writing, the chunks written are kept"
            )

    def release(self) -> None:
        """Stop the heartbeat and remove the lock if it is still ours."""
        if self._thread is None:
            return
        self._stop.set()
        self._thread.join()
        self._thread = None
        data = _read(self.file)
        if data is not None and data.get("token") == self._token:
            self.file.unlink(missing_ok=True)
