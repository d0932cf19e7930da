"""Nova TCP server: tick cost and delivery delay with WATCH clients, and the publish loop's timing."""

from __future__ import annotations

import selectors
import socket
import statistics
import threading
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np

from nfwserver.clock import SystemClock, VirtualClock
from nfwserver.config.schema import TcpConfig
from nfwserver.core.publisher import Publisher
from nfwserver.core.station_core import StationCore
from nfwserver.tcp import NovaTcpServer
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer

ROOT = Path(__file__).resolve().parent.parent
CATALOG = Catalog(load_element_file(ROOT / "tests" / "data" / "visual.txt").sets)
OBS = Observer(52.2, 0.12, 20.0)
START = datetime(2026, 5, 8, tzinfo=timezone.utc)
CONFIG = TcpConfig(enabled=True, host="127.0.0.1", port=0, allow=("127.0.0.1/32",))


class Watchers:
    """``n`` WATCH clients read on one thread; records when each line arrived (perf_counter)."""

    def __init__(self, address: tuple[str, int], n: int) -> None:
        self.socks = []
        for _ in range(n):
            sock = socket.create_connection(address)
            sock.sendall(b"WATCH\r\n")
            self.socks.append(sock)
        self.arrivals: dict[int, list[float]] = {i: [] for i in range(n)}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        sel = selectors.DefaultSelector()
        for i, sock in enumerate(self.socks):
            sock.setblocking(False)
            sel.register(sock, selectors.EVENT_READ, i)
        skip = {i: 2 for i in self.arrivals}  # the greeting and WATCH's OK
        while not self._stop.is_set():
            for key, _ in sel.select(0.05):
                data = key.fileobj.recv(65536)
                now = time.perf_counter()
                lines = data.count(b"\r\n")
                taken = min(lines, skip[key.data])
                skip[key.data] -= taken
                self.arrivals[key.data].extend([now] * (lines - taken))
        sel.close()

    def received(self) -> int:
        return min(len(a) for a in self.arrivals.values())

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        for sock in self.socks:
            sock.close()


def _wait(predicate, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.001)


def tick_cost(clients: int, ticks: int = 2000) -> tuple[float, float, float, int]:
    """Median tick cost (us) and delivery delay to the last client (p50, p99 in ms), strings lost."""
    clock = VirtualClock(START)
    core = StationCore(CATALOG, OBS, clock, satellite=25544, rate_hz=10)
    server = NovaTcpServer(core, CONFIG, max_clients=clients + 10)
    server.start()
    watchers = Watchers(server.address, clients)
    _wait(lambda: server.watcher_count() == clients)
    core.set_tune(True)
    costs, sent = [], []
    when = START
    for k in range(ticks):
        when += timedelta(milliseconds=100)
        clock.set(when)
        t = time.perf_counter()
        core.tick(when)
        costs.append(time.perf_counter() - t)
        sent.append(t)
        if clients:
            _wait(lambda k=k: watchers.received() > k, 5.0)  # one string in flight at a time
    delays = []
    for k, t in enumerate(sent if clients else []):
        delays.append(max(a[k] for a in watchers.arrivals.values()) - t)
    watchers.close()
    lost = server.stats.lost
    server.stop()
    d = np.array(delays or [0.0]) * 1e3
    return statistics.median(costs) * 1e6, float(np.percentile(d, 50)), float(np.percentile(d, 99)), lost


def loop_lateness(clients: int, rate: float, seconds: float) -> tuple[float, float, float, int, int]:
    core = StationCore(CATALOG, OBS, SystemClock(), satellite=25544, rate_hz=rate)
    server = NovaTcpServer(core, CONFIG, max_clients=clients + 10)
    server.start()
    watchers = Watchers(server.address, clients)
    _wait(lambda: server.watcher_count() == clients)
    core.set_tune(True)
    publisher = Publisher(core, SystemClock())
    publisher.start()
    time.sleep(seconds)
    publisher.stop()
    _wait(lambda: watchers.received() >= publisher.stats.ticks)
    got = watchers.received()
    watchers.close()
    server.stop()
    late = np.array(publisher.stats.lateness_s) * 1e3
    return (float(np.percentile(late, 50)), float(np.percentile(late, 99)), float(late.max()),
            publisher.stats.ticks, got)


def main() -> None:
    print("## Nova TCP server\n")
    print("Tick = compute look angles, format the Nova string, hand it to the TCP server (the publisher's part: "
          "queue the string, wake the server thread). Delivery = from the start of the tick until the last WATCH "
          "client has read the line over loopback (server thread `nfw-tcp` and one reader thread). Median tick "
          "cost over 2,000 ticks, one string in flight at a time.\n")
    print("| WATCH clients | tick cost | delivery p50 | delivery p99 | strings lost |")
    print("|---|---|---|---|---|")
    for n in (0, 10, 100):
        cost, p50, p99, lost = tick_cost(n)
        delivery = ("-", "-") if n == 0 else (f"{p50:.2f} ms", f"{p99:.2f} ms")
        print(f"| {n} | {cost:.1f} us | {delivery[0]} | {delivery[1]} | {lost} |")
    print()
    print("Real-time publish loop (SystemClock, 10 Hz, 30 s) with WATCH clients, lateness of each tick against "
          "its schedule:\n")
    print("| WATCH clients | ticks | every client got every string | p50 | p99 | max | goal |")
    print("|---|---|---|---|---|---|---|")
    for n in (10, 100):
        p50, p99, worst, ticks, got = loop_lateness(n, 10.0, 30.0)
        print(f"| {n} | {ticks} | {'yes' if got >= ticks else f'no ({got})'} | {p50:.3f} ms | {p99:.3f} ms | "
              f"{worst:.3f} ms | p99 <= 2 ms |")
    print()


if __name__ == "__main__":
    main()
