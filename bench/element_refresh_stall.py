"""How long a refresh of a large element file holds up the publish thread (#23 item 16).

``python -m bench.element_refresh_stall [--sets N] [--rate HZ] [--refreshes K] [--unlimited]``: writes a TLE
file of N sets (tests/data/active.txt over and over, catalog numbers 1..99999 repeating, so N/3 ... sets per
refresh are new), starts a real ``Station`` on the system clock publishing at HZ, then refreshes K times, each
time from a file whose epochs are half a day newer (every set replaced), on a thread of its own as the
station's refresher does (the stored catalog is on, in the same temporary directory).  Prints, per refresh,
how long it took and the longest gap between two published samples while it ran (the tick period when
nothing held the publish thread up).  ``--unlimited`` raises
``[elements] max_source_mib``/``max_source_sets`` to their maxima so files over the default limits are read.
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import threading
import time
from pathlib import Path

from nfwserver.app.station import Station
from nfwserver.clock import SystemClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.tle import tle_checksum

ACTIVE = Path(__file__).resolve().parent.parent / "tests" / "data" / "active.txt"


def catalog_text(count: int, shift_days: float) -> str:
    """``count`` 3-line TLEs from active.txt with catalog numbers 1..99999 (repeating), epochs moved."""
    lines = ACTIVE.read_text().splitlines()
    triples = [(lines[k], lines[k + 1], lines[k + 2]) for k in range(0, len(lines) - 2, 3)]
    out = []
    for n in range(count):
        _, one, two = triples[n % len(triples)]
        cat = f"{n % 99999 + 1:05d}"
        day = float(one[20:32]) + shift_days
        one = one[:2] + cat + one[7:20] + f"{day:012.8f}" + one[32:68]
        two = two[:2] + cat + two[7:68]
        out += [f"SAT {n}", one + str(tle_checksum(one)), two + str(tle_checksum(two))]
    return "\n".join(out) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=99_999)
    parser.add_argument("--rate", type=float, default=10.0)
    parser.add_argument("--refreshes", type=int, default=3)
    parser.add_argument("--unlimited", action="store_true")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        keps = Path(tmp) / "keps.txt"
        keps.write_text(catalog_text(args.sets, 0.0))
        limits = "max_source_mib = 1024\nmax_source_sets = 1000000\n" if args.unlimited else ""
        store = Path(tmp) / "store.txt"
        config = parse_config(f'[elements]\nfiles = ["{keps}"]\nstore = "{store}"\nrefresh_hours = 0\n{limits}'
                              f"[server]\nrate_hz = {args.rate:g}\ntune = true\nsatellite = 1\n")
        started = time.monotonic()
        station = Station(config, SystemClock(), transport=FakeDdeSystem().server_transport())
        station.start()
        print(f"{keps.stat().st_size / 2**20:.1f} MiB, {args.sets} sets: start {time.monotonic() - started:.2f} s, "
              f"catalog {len(station.catalog)} satellites, publishing at {args.rate:g} Hz")
        stamps: list[float] = []
        station.core.subscribe(lambda sample: stamps.append(time.monotonic()))
        try:
            time.sleep(1.0)
            for k in range(1, args.refreshes + 1):
                keps.write_text(catalog_text(args.sets, 0.5 * k))
                station.config = dataclasses.replace(station.config)  # the same sources, newer contents
                began = time.monotonic()
                result: list = []
                worker = threading.Thread(target=lambda out=result: out.append(station.refresh_elements()))
                worker.start()
                worker.join()
                ended = time.monotonic()
                time.sleep(3.0 / args.rate)
                during = [t for t in stamps if began - 1.0 / args.rate <= t <= ended + 2.0 / args.rate]
                gap = max((b - a for a, b in zip(during, during[1:])), default=float("nan"))
                updated = len(result[0].updated) if result else 0
                print(f"refresh {k}: {ended - began:.2f} s, {updated} sets replaced; longest gap between published "
                      f"samples {gap * 1000:.0f} ms (period {1000 / args.rate:.0f} ms)")
        finally:
            station.stop()


if __name__ == "__main__":
    main()
