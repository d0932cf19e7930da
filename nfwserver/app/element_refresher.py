"""Refreshing the element sets while the station runs, off every protocol and UI thread.

:class:`ElementRefresher` owns one thread (``nfw-elements``) that fetches the configured element
files and URLs: once right after start (so a slow web site never delays the first publish), then
every ``period_s`` seconds of the station's clock, and whenever :meth:`request` asks (PREDICT's
``RELOAD_TLE``, the console).  Requests are coalesced: at most one fetch is in flight, a request
during a fetch runs one more afterwards at most, and request-triggered fetches are at least
``min_interval_s`` apart, so a flood of requests costs one fetch.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

from nfwserver.clock import Clock
from nfwserver.core.service_thread import ServiceThread

log = logging.getLogger(__name__)


class ElementRefresher(ServiceThread):
    thread_name = "nfw-elements"

    """Runs ``refresh()`` on its own thread; see the module docstring.  ``period_s`` 0: only on request."""

    def __init__(self, refresh: Callable[[], object], clock: Clock, period_s: float,
                 min_interval_s: float = 60.0, initial: bool = True) -> None:
        self.refresh = refresh
        self.clock = clock
        self.period_s = period_s
        self.min_interval_s = min_interval_s
        self.initial = initial
        self.fetches = 0
        super().__init__()
        self._requested = threading.Event()
        self._last_fetch: float | None = None

    def request(self) -> None:
        """Ask for a fetch soon (cheap; callable from any thread)."""
        self._requested.set()
        self._wake.set()


    def _fetch(self) -> None:
        self._last_fetch = self.clock.monotonic()
        self.fetches += 1
        try:
            self.refresh()
        except OSError as exc:  # out of descriptors, a full disk: one line, the next request tries again
            log.warning("element refresh failed: %s", exc.strerror or exc)
        except Exception:  # never let a refresh take the station down
            log.exception("element refresh failed")

    def _run(self) -> None:
        if self.initial:
            self._fetch()
        due = self.clock.monotonic() + self.period_s if self.period_s > 0 else None
        while not self._stop.is_set():
            now = self.clock.monotonic()
            timeout = (due - now) if due is not None else 3600.0
            if self._requested.is_set() and self._last_fetch is not None:
                timeout = min(timeout, self._last_fetch + self.min_interval_s - now)
            self.clock.wait(self._wake, max(0.0, timeout))
            self._wake.clear()
            if self._stop.is_set():
                return
            now = self.clock.monotonic()
            periodic = due is not None and now >= due
            requested = self._requested.is_set() and (
                self._last_fetch is None or now - self._last_fetch >= self.min_interval_s)
            if periodic or requested:
                self._requested.clear()
                self._fetch()
                if due is not None and periodic:
                    due = self.clock.monotonic() + self.period_s
