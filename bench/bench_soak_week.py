"""Soak: a week of virtual time at 10 Hz with clients coming and going, satellite switches and hourly
element refreshes, on the fake DDE transport.  Reports ticks, missed ticks, RSS and bounded queues.

Run alone with ``python -m bench soak-week`` (about five minutes on this machine).
"""

from __future__ import annotations

import random
import resource
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

from nfwserver.clock import VirtualClock
from nfwserver.core.station_core import StationCore
from nfwserver.dde.nova_service import NovaDdeService
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer

ROOT = Path(__file__).resolve().parent.parent
DAYS = 7
RATE = 10.0
CLIENTS = 20


def rss_mib() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    rng = random.Random(8)
    sets = load_element_file(ROOT / "tests" / "data" / "visual.txt").sets
    catalog = Catalog(sets)
    numbers = [s.catalog_number for s in catalog]
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    server = StationCore(catalog, Observer(52.2, 0.12, 20.0), clock, satellite=25544, rate_hz=RATE)
    system = FakeDdeSystem(received_capacity=64)
    NovaDdeService(server).attach(system.server_transport())
    clients = [system.connect("NFW32", "NFW_DATA") for _ in range(CLIENTS)]
    for c in clients:
        c.start_advise("NFW_SERVER")
    clients[0].poke("NFW_SERVER", "TUNE ON")
    ticks = int(DAYS * 86400 * RATE)
    published = 0
    samples = []

    def count(sample) -> None:
        nonlocal published
        published += bool(sample.text)

    server.subscribe(count)
    rss_start = None
    started = time.perf_counter()
    step = timedelta(seconds=1.0 / RATE)
    when = clock.now()
    for k in range(ticks):
        when += step
        clock.set(when)
        server.tick(when)
        if k % 3000 == 0:  # every 5 minutes: a client leaves and a new one joins; switch satellite
            victim = rng.randrange(CLIENTS)
            clients[victim].disconnect()
            clients[victim] = system.connect("NFW32", "NFW_DATA")
            clients[victim].start_advise("NFW_SERVER")
            clients[0].poke("NFW_SERVER", f"SAT={rng.choice(numbers)}")
        if k % 36000 == 0:  # hourly element refresh
            catalog.update(sets)
        if k % 864000 == 0:
            samples.append((k, rss_mib(), len(server.events), system.conversation_count()))
            if rss_start is None and k > 0:
                rss_start = samples[-1][1]
    elapsed = time.perf_counter() - started
    rss_end = rss_mib()
    print("## Soak (a week of virtual time)\n")
    print(f"{DAYS} days at {RATE:g} Hz = {ticks:,} ticks with {CLIENTS} hot-advise clients, one replaced and the "
          "satellite switched every 5 minutes, elements refreshed hourly; fake DDE transport, virtual clock.\n")
    print("| measurement | value |")
    print("|---|---|")
    print(f"| ticks run / strings published | {ticks:,} / {published:,} |")
    print(f"| missed ticks | {ticks - published:,} |")
    print(f"| wall time | {elapsed:.0f} s ({elapsed / ticks * 1e6:.1f} us per tick) |")
    print(f"| RSS after day 1 / at the end | {rss_start:.1f} MiB / {rss_end:.1f} MiB |")
    print(f"| event log length (bounded) | {len(server.events):,} (capacity 5,000) |")
    print(f"| open conversations at the end | {system.conversation_count()} |")
    print()
    print("| tick | RSS MiB | event log | conversations |")
    print("|---|---|---|---|")
    for k, rss, events, convs in samples:
        print(f"| {k:,} | {rss:.1f} | {events:,} | {convs} |")
    print()


if __name__ == "__main__":
    main()
