"""What the TCP and web benchmarks share: their clients in a process of their own, waiting for the station,
and the real-time publish loop (a station core ticking on the system clock for a while, and the lateness of
each tick against its schedule, in milliseconds)."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

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
    late = publisher.stats.lateness  # quantiles: the upper edges of 19 %-wide bins
    return late.quantile(0.5) * 1e3, late.quantile(0.99) * 1e3, late.max_s * 1e3, publisher.stats.ticks


class ClientProcess:
    """A benchmark's clients, run by ``python -m MODULE FLAG HOST PORT N`` in a process of their own (as real
    clients are: they do not share our interpreter lock).  The process prints ``ready`` once connected; a
    line sent to it asks for its arrival times, which it prints as one JSON line before it exits."""

    def __init__(self, module: str, flag: str, address: tuple[str, int], n: int, root: Path) -> None:
        self.proc = subprocess.Popen([sys.executable, "-m", module, flag, address[0], str(address[1]), str(n)],
                                     cwd=root, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        assert self.proc.stdout is not None and self.proc.stdout.readline().strip() == "ready"

    def arrivals(self, request: str = "") -> Any:
        """Send ``request`` (one line) and return the JSON the clients answer with."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(f"{request}\n")
        self.proc.stdin.flush()
        result = json.loads(self.proc.stdout.readline())
        self.proc.wait(10)
        return result
