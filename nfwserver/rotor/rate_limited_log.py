"""One clear diagnostic for a repeated condition: the first occurrence, then at most one per interval.

Times come from an injected ``clock.monotonic()``; a later message says how many were left out.
"""

from __future__ import annotations

import logging
from collections.abc import Callable


class RateLimitedLog:
    def __init__(self, logger: logging.Logger, monotonic: Callable[[], float], interval_s: float = 60.0) -> None:
        self.logger = logger
        self.monotonic = monotonic
        self.interval_s = interval_s
        self._last: dict[str, float] = {}
        self._suppressed: dict[str, int] = {}

    def warning(self, key: str, message: str, *args: object) -> bool:
        """Log ``message`` under ``key`` unless one was logged less than ``interval_s`` ago; True if logged."""
        now = self.monotonic()
        last = self._last.get(key)
        if last is not None and now - last < self.interval_s:
            self._suppressed[key] = self._suppressed.get(key, 0) + 1
            return False
        left_out = self._suppressed.pop(key, 0)
        self._last[key] = now
        suffix = f" ({left_out} more like it not shown)" if left_out else ""
        self.logger.warning(message + suffix, *args)
        return True
