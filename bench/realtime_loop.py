"""The real-time publish loop as the benchmarks run it: a station core ticking on the system clock for a
while, and the lateness of each tick against its schedule (milliseconds)."""

from __future__ import annotations

import time

import numpy as np

from nfwserver.clock import SystemClock
from nfwserver.core.publisher import Publisher
from nfwserver.core.station_core import StationCore


def run_publisher(core: StationCore, seconds: float) -> tuple[float, float, float, int]:
    """Publish ``core``'s ticks in real time for ``seconds``; returns the lateness p50, p99 and maximum (ms)
    and the number of ticks."""
    publisher = Publisher(core, SystemClock())
    publisher.start()
    time.sleep(seconds)
    publisher.stop()
    late = np.array(publisher.stats.lateness_s) * 1e3
    return (float(np.percentile(late, 50)), float(np.percentile(late, 99)), float(late.max()),
            publisher.stats.ticks)
