"""The publish loop: ticks the station core at its rate, on the clock it is given.

:class:`Publisher` runs on its own thread and waits through the clock (``Clock.wait``), so it
follows real time with a :class:`~nfwserver.clock.SystemClock` and virtual time with a
:class:`~nfwserver.clock.VirtualClock` advanced by a test.  Ticks are scheduled on the clock's monotonic time at
``t0 + k / rate``, so errors never accumulate; a tick that overruns makes the loop skip the
slots it missed (counted in :attr:`PublishStats.skipped`) instead of bursting to catch up.  Each
tick computes for the wall-clock instant it runs at.  A tick that raises is logged and the loop
goes on.

Virtual time (:func:`run_virtual`): a :class:`~nfwserver.clock.VirtualClock` is stepped to each
tick instant in turn, so a 45-minute session runs as fast as the computation allows.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import timedelta

from nfwserver.clock import Clock, VirtualClock
from nfwserver.core.service_thread import ServiceThread
from nfwserver.core.station_core import StationCore
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)


@dataclass
class PublishStats:
    """Timing of the real-time loop: how late each tick started (seconds), and slots skipped."""

    ticks: int = 0
    skipped: int = 0
    failures: int = 0
    lateness_s: list[float] = field(default_factory=list)
    keep: int = 100_000  #: most recent lateness samples kept

    def record(self, late: float) -> None:
        self.ticks += 1
        self.lateness_s.append(late)
        if len(self.lateness_s) > self.keep:
            del self.lateness_s[: len(self.lateness_s) - self.keep]


class Publisher(ServiceThread):
    """Runs ``core.tick()`` at the state's rate on a background thread (thread ``nfw-publisher``)."""

    thread_name = "nfw-publisher"

    def __init__(self, core: StationCore, clock: Clock) -> None:
        super().__init__()
        self.core = core
        self.clock = clock
        self.stats = PublishStats()
        self._failures = RateLimitedLog(log, clock, 60.0)  #: a tick that raises: one line, then a count a minute

    def _run(self) -> None:
        t0 = self.clock.monotonic()
        k = 0
        rate = self.core.state.rate_hz
        while not self._stop.is_set():
            if self.core.state.rate_hz != rate:  # rate changed: restart the schedule from now
                rate, t0, k = self.core.state.rate_hz, self.clock.monotonic(), 0
            due = t0 + k / rate
            now = self.clock.monotonic()
            if due > now:
                # Waiting on the event lets stop() interrupt the wait at once.
                if self.clock.wait(self._stop, due - now):
                    break
                now = self.clock.monotonic()
            late = now - due
            try:
                self.core.tick()
            except Exception:
                self.stats.failures += 1
                self._failures.log(logging.ERROR, "tick", "publish tick failed", exc_info=True)
            self.stats.record(late)
            k += 1
            behind = self.clock.monotonic() - (t0 + k / rate)
            if behind > 1.0 / rate:  # overran: skip the missed slots
                missed = math.floor(behind * rate)
                self.stats.skipped += missed
                k += missed


def run_virtual(
    core: StationCore,
    clock: VirtualClock,
    duration_s: float,
    before_tick: Callable[[float], None] | None = None,
) -> int:
    """Tick ``core`` at its rate for ``duration_s`` of virtual time; returns the number of ticks.

    The first tick is at the clock's current instant.  ``before_tick(offset_s)`` runs before each
    tick (with the clock already at that instant), e.g. to deliver scheduled pokes.
    """
    start = clock.now()
    rate = core.state.rate_hz
    period = 1.0 / rate
    count = int(math.floor(duration_s * rate + 1e-9)) + 1
    failures = RateLimitedLog(log, clock, 60.0)
    for k in range(count):
        offset = k * period
        clock.set(start + timedelta(seconds=offset))
        if before_tick is not None:
            before_tick(offset)
        try:
            core.tick(clock.now())
        except Exception:
            failures.log(logging.ERROR, "tick", "publish tick failed", exc_info=True)
    return count
