"""The publish loop: ticks the station core at its rate, on the clock it is given.

:class:`Publisher` runs on its own thread and waits through the clock (``Clock.wait``), so it
follows real time with a :class:`~nfwserver.clock.SystemClock` and virtual time with a
:class:`~nfwserver.clock.VirtualClock` advanced by a test.  Ticks are scheduled on the clock's monotonic time at
``t0 + k / rate``, so errors never accumulate; a tick that overruns makes the loop skip the
slots it missed (counted in :attr:`PublishStats.skipped`) instead of bursting to catch up.  Each
tick computes for the wall-clock instant it runs at.  A tick that raises is logged and the loop
goes on.

Lateness is kept in constant memory (:class:`~nfwserver.core.publish_timing.LatenessHistogram`): a station
running for weeks holds bin counts, not a sample per tick.  A tick later than :data:`STALL_S` is a *stall*:
the publisher logs what held it (garbage collection timed through ``gc.callbacks``, the previous tick's own
work, or the thread waiting to be scheduled; :func:`~nfwserver.core.publish_timing.explain_stall`) and keeps
the last :data:`STALLS_KEPT` in :attr:`PublishStats.stalls`.

Virtual time (:func:`run_virtual`): a :class:`~nfwserver.clock.VirtualClock` is stepped to each
tick instant in turn, so a 45-minute session runs as fast as the computation allows.
"""

from __future__ import annotations

import logging
import math
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import timedelta

from nfwserver.clock import Clock, VirtualClock
from nfwserver.core.publish_timing import GcPauses, LatenessHistogram, Stall, explain_stall
from nfwserver.core.service_thread import ServiceThread
from nfwserver.core.station_core import StationCore
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)


#: a tick starting this many seconds late is a stall, logged with what held it (clock seconds; #44's target:
#: none above 0.5 s at 10 Hz)
STALL_S = 0.5
#: stalls remembered in :attr:`PublishStats.stalls`
STALLS_KEPT = 32


@dataclass
class PublishStats:
    """Timing of the real-time loop: how late ticks started (seconds, a histogram), slots skipped, and the
    last stalls with their causes.  Constant size however long the loop runs."""

    ticks: int = 0
    skipped: int = 0
    failures: int = 0
    lateness: LatenessHistogram = field(default_factory=LatenessHistogram)
    stalls: deque[Stall] = field(default_factory=lambda: deque(maxlen=STALLS_KEPT))

    def record(self, late: float) -> None:
        """Count one tick that started ``late`` seconds after it was due."""
        self.ticks += 1
        self.lateness.add(late)


class Publisher(ServiceThread):
    """Runs ``core.tick()`` at the state's rate on a background thread (thread ``nfw-publisher``)."""

    thread_name = "nfw-publisher"

    def __init__(self, core: StationCore, clock: Clock) -> None:
        super().__init__()
        self.core = core
        self.clock = clock
        self.stats = PublishStats()
        self._failures = RateLimitedLog(log, clock, 60.0)  #: a tick that raises: one line, then a count a minute
        self._stall_lines = RateLimitedLog(log, clock, 10.0)  #: a stall: one line, then a count every 10 s
        self.gc_pauses = GcPauses(clock)
        self._tick_end = 0.0  # clock monotonic seconds the previous tick ended
        self._tick_cpu = 0.0  # this process's CPU seconds then
        self._tick_thread_cpu = 0.0  # CPU seconds the publish thread itself spent in the previous tick

    def _stalled(self, late: float, due: float, now: float) -> None:
        """A tick ``late`` seconds late: record and log what held it (see :func:`explain_stall`)."""
        gc_s, generation = self.gc_pauses.within(due, now)
        work_s = max(0.0, self._tick_end - due)
        work_s = max(0.0, work_s - self.gc_pauses.within(due, self._tick_end)[0])
        cpu_s = max(0.0, time.process_time() - self._tick_cpu)
        stall = Stall(now, late, explain_stall(late, gc_s, generation, work_s, cpu_s,
                                              work_cpu_s=min(work_s, self._tick_thread_cpu)))
        self.stats.stalls.append(stall)
        self._stall_lines.log(logging.INFO, "stall", "publish tick %.2f s late: %s", late, stall.cause)

    def _run(self) -> None:
        self.gc_pauses.install()
        try:
            self._loop()
        finally:
            self.gc_pauses.remove()

    def _loop(self) -> None:
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
            if late >= STALL_S and k > 0:  # woke late (the first tick has no schedule to be late for)
                self._stalled(late, due, now)
            thread_cpu = time.thread_time()
            try:
                self.core.tick()
            except Exception:
                self.stats.failures += 1
                self._failures.log(logging.ERROR, "tick", "publish tick failed", exc_info=True)
            self._tick_end, self._tick_cpu = self.clock.monotonic(), time.process_time()
            self._tick_thread_cpu = time.thread_time() - thread_cpu
            self.stats.record(late)
            k += 1
            behind = self._tick_end - (t0 + k / rate)
            if behind >= STALL_S:  # the tick itself overran its slots by a stall's length
                self._stalled(behind, t0 + k / rate, self._tick_end)
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
