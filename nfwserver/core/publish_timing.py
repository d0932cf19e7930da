"""How late the publish loop's ticks start, kept in constant memory, and what held a late one.

:class:`LatenessHistogram` counts lateness (seconds) in fixed bins whose edges grow by a factor 2^(1/4)
(19 %) from 0.1 ms to 105 s, so a station running for weeks keeps 81 integers, not a sample per tick;
quantiles are read back as the upper edge of their bin (at most 19 % high; the maximum is kept exactly).

:class:`GcPauses` times the cyclic garbage collector through :data:`gc.callbacks` on the injected clock
and keeps the last :data:`GC_KEPT` collections, so the publisher can say how much of a stall was a
collection (they run on whichever thread allocates, holding the interpreter lock for all of them).

:func:`explain_stall` names what held a late tick, from three measured parts: collections that ran between
the moment the tick was due and its start, the previous tick's own work (computing the sample, the locks it
took and every tick listener it handed the sample to), and the rest, which was the thread waiting to be
scheduled: with this process's CPU time in that window close to the rest, another of its threads held the
interpreter; with little, the machine was busy elsewhere or the process was paused.
"""

from __future__ import annotations

import bisect
import gc
import threading
from collections import deque
from dataclasses import dataclass, field

from nfwserver.clock import Clock

__all__ = ["GC_KEPT", "LATENESS_EDGES_S", "GcPause", "GcPauses", "LatenessHistogram", "Stall", "explain_stall"]

#: upper edges of the lateness bins (seconds): 0.1 ms growing by 2^(1/4) to 105 s; a last bin holds the rest
LATENESS_EDGES_S: tuple[float, ...] = tuple(0.0001 * 2.0 ** (k / 4) for k in range(81))
#: collections remembered by :class:`GcPauses` (a stall is explained from the ones in its window)
GC_KEPT = 64


@dataclass
class LatenessHistogram:
    """Counts of tick lateness (seconds) per bin of :data:`LATENESS_EDGES_S`; constant size."""

    counts: list[int] = field(default_factory=lambda: [0] * (len(LATENESS_EDGES_S) + 1))
    total: int = 0
    max_s: float = 0.0

    def add(self, late_s: float) -> None:
        """Count one tick that started ``late_s`` seconds after it was due."""
        self.counts[bisect.bisect_left(LATENESS_EDGES_S, late_s)] += 1
        self.total += 1
        self.max_s = max(self.max_s, late_s)

    def quantile(self, q: float) -> float:
        """An upper bound of the ``q`` quantile (0..1) of the lateness (seconds): its bin's upper edge, or
        the maximum when that is smaller or the quantile lies in the last bin; 0 before any tick."""
        if self.total == 0:
            return 0.0
        rank = q * self.total
        seen = 0
        for index, count in enumerate(self.counts):
            seen += count
            if seen >= rank and count:
                edge = LATENESS_EDGES_S[index] if index < len(LATENESS_EDGES_S) else self.max_s
                return min(edge, self.max_s)
        return self.max_s

    def over(self, late_s: float) -> int:
        """Ticks counted in bins wholly above ``late_s`` seconds (a lower bound of the ticks later than it)."""
        return sum(count for index, count in enumerate(self.counts)
                   if index > 0 and LATENESS_EDGES_S[index - 1] >= late_s)


@dataclass(frozen=True)
class GcPause:
    """One collection: when it started and ended (clock monotonic seconds) and its generation."""

    start: float
    end: float
    generation: int


class GcPauses:
    """The last :data:`GC_KEPT` collections of this process, timed on ``clock`` while installed."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self.pauses: deque[GcPause] = deque(maxlen=GC_KEPT)
        self._started: dict[int, float] = {}  # thread id -> start of the collection it runs
        self._lock = threading.Lock()

    def install(self) -> None:
        if self._callback not in gc.callbacks:
            gc.callbacks.append(self._callback)

    def remove(self) -> None:
        if self._callback in gc.callbacks:
            gc.callbacks.remove(self._callback)

    def _callback(self, phase: str, info: dict[str, int]) -> None:
        now = self.clock.monotonic()
        ident = threading.get_ident()
        with self._lock:
            if phase == "start":
                self._started[ident] = now
                return
            start = self._started.pop(ident, None)
        if start is not None:
            self.pauses.append(GcPause(start, now, int(info.get("generation", -1))))

    def within(self, start: float, end: float) -> tuple[float, int]:
        """Seconds of collection overlapping ``start..end`` (clock monotonic) and the oldest generation
        collected in it (-1 when none)."""
        total, generation = 0.0, -1
        for pause in list(self.pauses):
            overlap = min(end, pause.end) - max(start, pause.start)
            if overlap > 0:
                total += overlap
                generation = max(generation, pause.generation)
        return total, generation


@dataclass(frozen=True)
class Stall:
    """A tick that started ``late_s`` seconds late, at ``at`` (clock monotonic seconds), and why."""

    at: float
    late_s: float
    cause: str


def explain_stall(late_s: float, gc_s: float, generation: int, work_s: float, cpu_s: float,
                  work_cpu_s: float | None = None) -> str:
    """What held a tick ``late_s`` seconds: ``gc_s`` seconds of collection (oldest ``generation``), the
    previous tick's own ``work_s`` seconds (compute, locks, listeners; collections inside it not counted
    twice; ``work_cpu_s`` of them on the processor, when measured: the rest of the tick was the thread waiting
    for a lock, the interpreter or the processor), and the rest, waited for the thread to run, with ``cpu_s``
    seconds of this process's CPU time used in the window.  One line, the largest part first."""
    parts: list[tuple[float, str]] = []
    if gc_s > 0:
        parts.append((gc_s, f"garbage collection {gc_s:.2f} s (generation {generation})"))
    if work_s > 0:
        inside = "computing, locks, tick listeners"
        if work_cpu_s is not None:
            inside = (f"{work_cpu_s:.2f} s of it on the processor, the rest waiting inside the tick for a lock, "
                      "the interpreter or the processor")
        parts.append((work_s, f"the previous tick's own work {work_s:.2f} s ({inside})"))
    rest = max(0.0, late_s - gc_s - work_s)
    if rest > 0:
        who = ("another thread of this process held the interpreter" if cpu_s >= 0.5 * rest
               else "the machine was busy elsewhere or the process was paused")
        parts.append((rest, f"waiting to be scheduled {rest:.2f} s ({who}; process CPU {cpu_s:.2f} s)"))
    parts.sort(key=lambda part: -part[0])
    return "; ".join(text for _, text in parts) or "nothing measured"
