"""Following the server's ticks on a worker thread, newest sample wins.

Devices (rotors, radios) answer in milliseconds to seconds, or not at all when a daemon is down;
the publish loop must never wait for them.  A :class:`TickWorker` is registered as a tick listener
(:meth:`on_tick` only records the sample and wakes the worker) and calls :meth:`process` on its own
thread with the newest sample, skipping any that arrived while it was busy.
"""

from __future__ import annotations

import logging
import threading

from nfwserver.clock import Clock, SystemClock
from nfwserver.core.sample import TickSample
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)


class TickWorker:
    """Base class: subclasses implement :meth:`process` and may extend :meth:`stop`."""

    worker_name = "nfw-worker"

    def __init__(self, clock: Clock | None = None) -> None:
        #: A failure repeated every tick is logged (with its traceback) once, then counted.
        self.warnings = RateLimitedLog(log, clock if clock is not None else SystemClock())
        self._pending: TickSample | None = None
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def process(self, sample: TickSample) -> object:
        raise NotImplementedError

    def on_tick(self, sample: TickSample) -> None:
        """Tick listener: remember the newest sample (cheap, never blocks)."""
        self._pending = sample
        self._wake.set()

    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(0.5)
            self._wake.clear()
            sample, self._pending = self._pending, None
            if sample is not None:
                try:
                    self.process(sample)
                except Exception:  # keep the worker alive whatever happens
                    self.warnings.log(logging.ERROR, "tick failed", "%s failed on a tick", self.worker_name,
                                      exc_info=True)

    def start(self) -> None:
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(target=self._run, name=self.worker_name, daemon=True)
            self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(5.0)
            self._thread = None
