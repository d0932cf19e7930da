"""Following the stored element catalog while the station runs.

``nfwserver elements update`` (another process) writes the store; a running station must take the new sets
without a restart.  :class:`StoreWatcher` looks at the store file's size, modification time and inode every
``interval_s`` seconds of the station's clock, waits until a change has stopped changing (``settle_s``; the
store is replaced atomically, so one look is normally enough), then calls ``reload()``, which reads the store
and merges it into the live catalog (newer epochs only).  :meth:`StoreWatcher.request` asks for a read now
(SIGHUP).  The station's own refresher writes the store too; reading its own write back changes nothing.

Owned by its own thread, ``nfw-store``; it waits on the injected clock.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from pathlib import Path

from nfwserver.app.config_watcher import Signature, file_signature, settled_signature
from nfwserver.clock import Clock
from nfwserver.core.service_thread import ServiceThread

log = logging.getLogger(__name__)


class StoreWatcher(ServiceThread):
    """Calls ``reload()`` after each settled change of ``path`` and on request; see the module docstring."""

    thread_name = "nfw-store"

    def __init__(self, path: Path, clock: Clock, reload: Callable[[], object], interval_s: float = 2.0,
                 settle_s: float = 0.5) -> None:
        self.path = path
        self.clock = clock
        self.reload = reload
        self.interval_s = interval_s
        self.settle_s = settle_s
        super().__init__()
        self._seen: Signature = None
        self._requested = threading.Event()

    def start(self) -> None:
        if self._thread is None:
            self._seen = file_signature(self.path)  # what the station loaded at start
        super().start()

    def request(self) -> None:
        """Read the store now, changed or not (any thread)."""
        self._requested.set()
        self._wake.set()

    def check(self, force: bool = False) -> bool:
        """One look (the thread's step); True when the store was read."""
        now = file_signature(self.path)
        if now == self._seen and not force:
            return False
        if not force:  # let a writer finish
            now = settled_signature(self.path, now, self.clock, self._stop, self.settle_s)
        if self._stop.is_set():
            return False
        self._seen = now
        if now is None:
            return False  # removed (or not a regular file): the sets in memory stay
        self.reload()
        return True

    def _run(self) -> None:
        while not self._stop.is_set():
            self.clock.wait(self._wake, self.interval_s)
            if self._stop.is_set():
                return
            self._wake.clear()
            forced = self._requested.is_set()
            self._requested.clear()
            try:
                self.check(force=forced)
            except OSError as exc:
                log.warning("cannot read the element store %s: %s", self.path, exc.strerror or exc)
            except Exception:  # the watcher must outlive any surprise
                log.exception("reading the element store failed")
