"""Repeated warnings, logged once and then summarised: a misbehaving device must not flood the log.

A device polled at 50 Hz that keeps failing the same way would otherwise write 50 lines a second.
:class:`RateLimitedLog` writes the first occurrence of each kind (``key``) at once; further ones
within ``interval_s`` seconds (on the injected clock) are only counted, and the next occurrence
after the interval is written with the count of those suppressed since the last line.  When the
condition is over, :meth:`RateLimitedLog.clear` writes the pending count (if any) and forgets the
key, so the next failure is reported at once again.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass

from nfwserver.clock import Clock

#: Distinct keys remembered; beyond this the oldest is forgotten (keys are meant to be a few fixed names).
MAX_KEYS = 256


@dataclass
class _Window:
    since: float  #: monotonic seconds of the last line written for this key
    suppressed: int = 0


class RateLimitedLog:
    """Writes to ``logger`` at most one line per key every ``interval_s`` seconds of ``clock``."""

    def __init__(self, logger: logging.Logger, clock: Clock, interval_s: float = 60.0) -> None:
        if interval_s <= 0:
            raise ValueError("interval_s must be positive")
        self.logger, self.clock, self.interval_s = logger, clock, interval_s
        self._windows: dict[str, _Window] = {}
        self._lock = threading.Lock()

    def log(self, level: int, key: str, message: str, *args: object, exc_info: bool = False,
            force: bool = False) -> bool:
        """Log ``message % args`` unless ``key`` was logged less than ``interval_s`` ago; True if written.

        ``force`` writes it whatever the window (the first line of a new episode of a condition: only the
        repeats within one episode are limited), with the count of those suppressed before it."""
        now = self.clock.monotonic()
        with self._lock:
            window = self._windows.get(key)
            if window is not None and now - window.since < self.interval_s and not force:
                window.suppressed += 1
                return False
            suppressed = window.suppressed if window is not None else 0
            elapsed = now - window.since if window is not None else 0.0
            self._windows.pop(key, None)
            if len(self._windows) >= MAX_KEYS:
                self._windows.pop(next(iter(self._windows)))
            self._windows[key] = _Window(now)
        if suppressed:
            message += f" ({suppressed} more like this in the last {elapsed:.0f} s)"
        self.logger.log(level, message, *args, exc_info=exc_info or None)
        return True

    def warning(self, key: str, message: str, *args: object) -> bool:
        return self.log(logging.WARNING, key, message, *args)

    def error(self, key: str, message: str, *args: object) -> bool:
        return self.log(logging.ERROR, key, message, *args)

    def suppressed(self, key: str) -> int:
        """Occurrences of ``key`` counted but not yet written."""
        with self._lock:
            window = self._windows.get(key)
            return window.suppressed if window is not None else 0

    def clear(self, key: str) -> None:
        """The condition behind ``key`` is over: write the pending count, if any, and forget the key."""
        with self._lock:
            window = self._windows.pop(key, None)
        if window is not None and window.suppressed:
            self.logger.log(logging.INFO, "%s: %d more like this in the last %.0f s before it cleared",
                            key, window.suppressed, self.clock.monotonic() - window.since)
