"""DDE server speed: the cost of one tick, and the real-time publish loop's timing error."""

from __future__ import annotations

import os
import statistics
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

from nfwserver.clock import SystemClock, VirtualClock
from nfwserver.core.publisher import Publisher
from nfwserver.core.station_core import StationCore
from nfwserver.dde.nova_service import NovaDdeService
from nfwserver.fake_dde import DdeError, FakeDdeSystem
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer

ROOT = Path(__file__).resolve().parent.parent
CATALOG = Catalog(load_element_file(ROOT / "tests" / "data" / "visual.txt").sets)
OBS = Observer(52.2, 0.12, 20.0)
START = datetime(2026, 5, 8, tzinfo=timezone.utc)


def tick_cost_us(clients: int, ticks: int = 3000) -> float:
    clock = VirtualClock(START)
    server = StationCore(CATALOG, OBS, clock, satellite=25544, rate_hz=10)
    system = FakeDdeSystem(received_capacity=4)
    NovaDdeService(server).attach(system.server_transport())
    for _ in range(clients):
        try:
            system.connect("NFW32", "NFW_DATA").start_advise("NFW_SERVER")
        except DdeError:  # the service is full (max_conversations_per_service): refused
            pass
    server.set_feed(True)
    times = []
    step = timedelta(milliseconds=100)
    when = START
    for _ in range(ticks):
        when += step
        t = time.perf_counter()
        server.tick(when)
        times.append(time.perf_counter() - t)
    return statistics.median(times) * 1e6


def reference_us(rounds: int = 20_000) -> float:
    """The machine's speed now: the median cost of one scalar look-angle computation (SGP4 and the frame
    rotation, no server), measured beside the ticks so that a tick's cost can be read against it."""
    from nfwserver.tracking.look_angles import LookAngleCalculator

    calc, satrec = LookAngleCalculator(OBS), CATALOG.get(25544).satrec  # type: ignore[union-attr]
    times = []
    when = START
    for _ in range(rounds):
        when += timedelta(milliseconds=100)
        t = time.perf_counter()
        calc.compute(satrec, when)
        times.append(time.perf_counter() - t)
    return statistics.median(times) * 1e6


def loop_error_ms(rate: float, seconds: float) -> tuple[float, float, float, int]:
    server = StationCore(CATALOG, OBS, SystemClock(), satellite=25544, rate_hz=rate)
    system = FakeDdeSystem(received_capacity=4)
    NovaDdeService(server).attach(system.server_transport())
    for _ in range(10):
        system.connect("NFW32", "NFW_DATA").start_advise("NFW_SERVER")
    server.set_feed(True)
    publisher = Publisher(server, SystemClock())
    publisher.start()
    time.sleep(seconds)
    publisher.stop()
    late = publisher.stats.lateness
    return late.quantile(0.5) * 1e3, late.quantile(0.99) * 1e3, late.max_s * 1e3, publisher.stats.ticks


def main() -> None:
    print("## DDE server\n")
    print("Tick = compute look angles, format the Nova string, post it to every hot advise loop on the fake "
          "transport, record the event, call listeners. Median over 3,000 ticks.\n")
    reference = reference_us()
    print("Beside each tick cost, the same cost in units of one scalar look-angle computation measured in the "
          "same run (SGP4 and the frame rotation, no server): the machine's speed changes with its load (it is "
          "shared), the ratio much less.\n")
    print("| advise clients | tick cost | in look-angle computations | goal |")
    print("|---|---|---|---|")
    for n in (1, 10, 100):
        goal = "<= 50 us" if n == 10 else ""
        cost = tick_cost_us(n)
        print(f"| {n} | {cost:.1f} us | {cost / reference:.1f} | {goal} |")
    cap = FakeDdeSystem().max_conversations_per_service
    cost = tick_cost_us(20_000, 300)
    print(f"| 20,000 tried, {cap} accepted (never read) | {cost:.1f} us | {cost / reference:.1f} | bounded by the "
          "cap |")
    print(f"\nOne scalar look-angle computation: {reference:.2f} us in this run; load average (1 min) "
          f"{os.getloadavg()[0]:.1f}.")
    print()
    print("Real-time publish loop (SystemClock, 10 hot clients), lateness of each tick against its schedule:\n")
    print("| rate | duration | ticks | p50 | p99 | max | goal |")
    print("|---|---|---|---|---|---|---|")
    for rate in (10.0, 50.0):
        p50, p99, worst, ticks = loop_error_ms(rate, 60.0)
        print(f"| {rate:.0f} Hz | 60 s | {ticks} | {p50:.3f} ms | {p99:.3f} ms | {worst:.3f} ms | p99 <= 2 ms |")
    print()


if __name__ == "__main__":
    main()
