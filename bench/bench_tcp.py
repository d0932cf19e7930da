"""Nova TCP server: tick cost and delivery delay with WATCH clients, and the publish loop's timing."""

from __future__ import annotations

import json
import selectors
import socket
import statistics
import sys
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np

from bench.realtime_loop import ClientProcess, run_publisher
from nfwserver.clock import SystemClock, VirtualClock
from nfwserver.config.schema import TcpConfig
from nfwserver.core.station_core import StationCore
from nfwserver.tcp.server import NovaTcpServer
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from tests.waiting import wait_for

ROOT = Path(__file__).resolve().parent.parent
CATALOG = Catalog(load_element_file(ROOT / "tests" / "data" / "visual.txt").sets)
OBS = Observer(52.2, 0.12, 20.0)
START = datetime(2026, 5, 8, tzinfo=timezone.utc)
CONFIG = TcpConfig(enabled=True, host="127.0.0.1", port=0, allow=("127.0.0.1/32",), max_per_address=4096)


def watcher_process(host: str, port: int, n: int) -> None:
    """Child process: ``n`` WATCH clients on one thread; prints "ready", and on a line on stdin the
    arrival times (perf_counter, comparable across processes on Linux) of every line, as JSON."""
    socks = []
    for _ in range(n):
        sock = socket.create_connection((host, port))
        sock.sendall(b"WATCH\r\n")
        socks.append(sock)
    arrivals: list[list[float]] = [[] for _ in range(n)]
    skip = [2] * n  # the greeting and WATCH's OK
    sel = selectors.DefaultSelector()
    for i, sock in enumerate(socks):
        sock.setblocking(False)
        sel.register(sock, selectors.EVENT_READ, i)
    sel.register(sys.stdin, selectors.EVENT_READ, -1)
    print("ready", flush=True)
    expected, deadline = None, 0.0
    while True:
        if expected is not None and (all(len(a) >= expected for a in arrivals) or time.monotonic() > deadline):
            print(json.dumps(arrivals), flush=True)
            return
        for key, _ in sel.select(0.1):
            if key.data == -1:
                expected, deadline = int(sys.stdin.readline()), time.monotonic() + 20.0
                sel.unregister(sys.stdin)
                continue
            data = key.fileobj.recv(65536)
            now = time.perf_counter()
            lines = data.count(b"\n")  # a CR LF may straddle two reads
            taken = min(lines, skip[key.data])
            skip[key.data] -= taken
            arrivals[key.data].extend([now] * (lines - taken))


class Watchers(ClientProcess):
    """``n`` WATCH clients in another process (``--watchers``); ``arrivals(str(expected))`` waits until each
    has ``expected`` lines (or 20 s) and returns every client's arrival times."""

    def __init__(self, address: tuple[str, int], n: int) -> None:
        super().__init__("bench.bench_tcp", "--watchers", address, n, ROOT)


def tick_cost(clients: int, ticks: int = 2000, pace_s: float = 0.005) -> tuple[float, float, float, int]:
    """Median tick cost (us), delivery delay to the last client (p50, p99 in ms), strings lost."""
    clock = VirtualClock(START)
    core = StationCore(CATALOG, OBS, clock, satellite=25544, rate_hz=10)
    server = NovaTcpServer(core, CONFIG, max_clients=clients + 10)
    server.start()
    watchers = Watchers(server.address, clients) if clients else None
    wait_for(lambda: server.watcher_count() == clients, 20.0, "the watchers to connect", interval_s=0.001)
    core.set_feed(True)
    costs, sent = [], []
    when = START
    for _ in range(ticks):
        when += timedelta(milliseconds=100)
        clock.set(when)
        t = time.perf_counter()
        core.tick(when)
        costs.append(time.perf_counter() - t)
        sent.append(t)
        time.sleep(pace_s)
    delays = [0.0]
    if watchers is not None:
        arrivals = watchers.arrivals(str(ticks))
        assert all(len(a) == ticks for a in arrivals), f"a client missed strings: {sorted({len(a) for a in arrivals})}"
        delays = [max(a[k] for a in arrivals) - t for k, t in enumerate(sent)]
    lost = server.stats.lost
    server.stop()
    d = np.array(delays) * 1e3
    return statistics.median(costs) * 1e6, float(np.percentile(d, 50)), float(np.percentile(d, 99)), lost


def loop_lateness(clients: int, rate: float, seconds: float) -> tuple[float, float, float, int, int]:
    core = StationCore(CATALOG, OBS, SystemClock(), satellite=25544, rate_hz=rate)
    server = NovaTcpServer(core, CONFIG, max_clients=clients + 10)
    server.start()
    watchers = Watchers(server.address, clients)
    wait_for(lambda: server.watcher_count() == clients, 20.0, "the watchers to connect", interval_s=0.001)
    core.set_feed(True)
    p50, p99, worst, ticks = run_publisher(core, seconds)
    got = min(len(a) for a in watchers.arrivals(str(ticks)))
    server.stop()
    return p50, p99, worst, ticks, got


def main() -> None:
    print("## Nova TCP server\n")
    print("Tick = compute look angles, format the Nova string, hand it to the TCP server (the publisher's part: "
          "queue the string, wake the server thread). Delivery = from the start of the tick until the last WATCH "
          "client has read the line over loopback (server thread `nfw-tcp`; the clients on one thread of a "
          "separate process, as real clients are). Median tick cost over 2,000 ticks, one every 5 ms (so each tick "
          "starts with cold caches, as in service; the DDE table above ticks back to back).\n")
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
    if sys.argv[1:2] == ["--watchers"]:
        watcher_process(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
    else:
        main()
