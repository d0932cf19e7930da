"""Autotrack on the station's ticks: a :class:`~nfwserver.core.tick_worker.TickWorker` that hands each tick's
instant to an :class:`~nfwserver.autotrack.runtime.AutotrackRuntime`, on a thread of its own (a plan takes
milliseconds to tens of milliseconds: never on the publish loop)."""

from __future__ import annotations

from nfwserver.autotrack.runtime import AutotrackRuntime
from nfwserver.clock import Clock
from nfwserver.core.sample import TickSample
from nfwserver.core.tick_worker import TickWorker

__all__ = ["AutotrackWorker"]


class AutotrackWorker(TickWorker):
    """Register :meth:`on_tick` as a tick listener and start the worker; the newest tick wins."""

    thread_name = "nfw-autotrack"

    def __init__(self, runtime: AutotrackRuntime, clock: Clock | None = None) -> None:
        super().__init__(clock)
        self.runtime = runtime

    def process(self, sample: TickSample) -> int | None:
        return self.runtime.tick(sample.time)
