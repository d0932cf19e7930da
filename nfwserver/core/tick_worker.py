"""Following the server's ticks on a worker thread, newest sample wins.

Devices (rotors, radios) answer in milliseconds to seconds, or not at all when a daemon is down;
the publish loop must never wait for them.  A :class:`TickWorker` is registered as a tick listener
(:meth:`on_tick` only records the sample and wakes the worker) and calls :meth:`process` on its own
thread with the newest sample, skipping any that arrived while it was busy.
"""

from __future__ import annotations

import logging
import threading
from datetime import datetime

from nfwserver.clock import Clock, SystemClock
from nfwserver.core.sample import TickSample
from nfwserver.core.service_thread import ServiceThread
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)


class TickWorker(ServiceThread):
    """Base class: subclasses implement :meth:`process` and may extend :meth:`stop`."""

    thread_name = "nfw-worker"

    def __init__(self, clock: Clock | None = None) -> None:
        self.clock: Clock = clock if clock is not None else SystemClock()  #: the station's clock (the system's)
        #: A failure repeated every tick is logged (with its traceback) once, then counted.
        self.warnings = RateLimitedLog(log, self.clock)
        super().__init__()
        self._pending_lock = threading.Lock()  #: the hand-over of the newest sample between the two threads
        self._pending: TickSample | None = None
        #: the time of the newest sample fully processed (how far behind the ticks the device is)
        self.processed_time: datetime | None = None

    def process(self, sample: TickSample) -> object:
        raise NotImplementedError

    def on_tick(self, sample: TickSample) -> None:
        """Tick listener: remember the newest sample (cheap: waits only for the worker taking the previous one)."""
        with self._pending_lock:
            self._pending = sample
        self._wake.set()

    def _take(self) -> TickSample | None:
        """The newest sample, once: a sample arriving while it is taken is kept for the next turn, never lost."""
        with self._pending_lock:
            sample, self._pending = self._pending, None
        return sample

    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(0.5)
            self._wake.clear()
            sample = self._take()
            if sample is not None:
                try:
                    self.process(sample)
                except Exception:  # keep the worker alive whatever happens
                    self.warnings.log(logging.ERROR, "tick failed", "%s failed on a tick", self.thread_name,
                                      exc_info=True)
                self.processed_time = sample.time

