"""Clocks: the only place the server learns what time it is.

Every component that needs the time takes a :class:`Clock` argument; nothing reads the wall clock on
its own.  :class:`SystemClock` follows real time; :class:`VirtualClock` only moves when told to (or
when something sleeps on it), so tests and ``nfwserver simulate`` run whole passes at any speed.

Times are timezone-aware :class:`datetime.datetime` objects in UTC.  ``monotonic()`` is in seconds
and only meaningful as a difference.
"""

from __future__ import annotations

import threading
import time
from datetime import datetime, timedelta, timezone
from typing import Protocol


class Clock(Protocol):
    """What the server needs from a clock."""

    def now(self) -> datetime:
        """The current instant, timezone-aware UTC."""
        ...

    def monotonic(self) -> float:
        """Seconds on a clock that never goes backwards (only differences are meaningful)."""
        ...

    def sleep(self, seconds: float) -> None:
        """Block (or, for a virtual clock, advance) for ``seconds``; non-positive returns at once."""
        ...

    def wait(self, event: threading.Event, seconds: float) -> bool:
        """Block until ``event`` is set or ``seconds`` of *this clock's* time have passed.

        Returns True when the event was set.  Every loop in the server waits through this, so a
        whole station runs on a :class:`VirtualClock` in tests without real sleeps.
        """
        ...


class SystemClock:
    """Real time: UTC from the operating system, ``time.monotonic`` and ``time.sleep``."""

    def now(self) -> datetime:
        return datetime.now(timezone.utc)

    def monotonic(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            time.sleep(seconds)

    def wait(self, event: threading.Event, seconds: float) -> bool:
        return event.wait(max(0.0, seconds))


class VirtualClock:
    """A clock that stands still until advanced; ``sleep`` advances it instantly.

    Thread-safe.  ``start`` must be timezone-aware (naive datetimes are taken as UTC).  Threads in
    :meth:`wait` wake when another thread advances the clock past their deadline (or their event is
    set; that is noticed within :attr:`POLL_S` real seconds), so loops run on virtual time.
    """

    POLL_S = 0.01

    def __init__(self, start: datetime) -> None:
        if start.tzinfo is None:
            start = start.replace(tzinfo=timezone.utc)
        self._start = start.astimezone(timezone.utc)
        self._elapsed = 0.0
        self._lock = threading.Lock()
        self._advanced = threading.Condition(self._lock)
        #: (thread ident, deadline in s of virtual time) of each thread in wait()
        self._deadlines: list[tuple[int, float]] = []

    def now(self) -> datetime:
        with self._lock:
            return self._start + timedelta(seconds=self._elapsed)

    def is_waiting(self, thread: threading.Thread | None) -> bool:
        """Whether ``thread`` is in :meth:`wait` for a moment still ahead of the clock: settled until the clock is
        advanced again.  A test that advances the clock waits for a loop to get there instead of pausing for it."""
        ident = None if thread is None else thread.ident
        with self._lock:
            return any(who == ident and deadline > self._elapsed for who, deadline in self._deadlines)

    def monotonic(self) -> float:
        with self._lock:
            return self._elapsed

    def advance(self, seconds: float) -> None:
        """Move time forward by ``seconds`` (negative values are refused)."""
        if seconds < 0:
            raise ValueError("a virtual clock cannot go backwards")
        with self._lock:
            self._elapsed += seconds
            self._advanced.notify_all()

    def set(self, when: datetime) -> None:
        """Jump to ``when`` (must not be earlier than now)."""
        if when.tzinfo is None:
            when = when.replace(tzinfo=timezone.utc)
        self.advance((when - self.now()).total_seconds())

    def sleep(self, seconds: float) -> None:
        if seconds > 0:
            self.advance(seconds)

    def wait(self, event: threading.Event, seconds: float) -> bool:
        with self._lock:
            deadline = self._elapsed + max(0.0, seconds)
            entry = (threading.get_ident(), deadline)
            self._deadlines.append(entry)
            try:
                while not event.is_set() and self._elapsed < deadline:
                    self._advanced.wait(self.POLL_S)
            finally:
                self._deadlines.remove(entry)
        return event.is_set()
