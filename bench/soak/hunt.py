"""Where memory goes: the station in this process under the soak's load, with ``tracemalloc`` snapshots compared.

``python -m bench.soak.hunt [--minutes N] [--accelerated]``: the same station, daemons, faults and clients as
``python -m bench soak``, but the station runs in this process (``Station`` on the system clock) so that
``tracemalloc`` sees its allocations.  Every 30 s: a full collection, then a snapshot; prints the memory traced
then, and at the end the allocation sites (12 frames) that grew between the snapshot a third into the run and
the last one.  Slower than the real process (tracemalloc costs a few times the allocations), so its CPU and
timing figures mean nothing; its growth figures are the point.
"""

from __future__ import annotations

import argparse
import gc
import logging
import sys
import tempfile
import threading
import time
import tracemalloc
from pathlib import Path

from bench.soak.load import Load
from bench.soak.station import Soak
from nfwserver.app.station import Station
from nfwserver.clock import SystemClock
from nfwserver.config.loader import load_config

SATELLITES = [25544, 14129, 27844, 43017]


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(prog="python -m bench.soak.hunt")
    parser.add_argument("--minutes", type=float, default=12.0)
    parser.add_argument("--accelerated", action="store_true", help="50 Hz, events five times as often")
    args = parser.parse_args(argv)
    speed = 5.0 if args.accelerated else 1.0
    with tempfile.TemporaryDirectory(prefix="nfw-hunt-") as work:
        soak = Soak(50.0 if args.accelerated else 10.0, Path(work))
        soak.rotctld.start()
        soak.rigctld.start()
        logging.basicConfig(level=logging.INFO, filename=str(soak.log))
        config = load_config(soak.config(0.05 / speed))
        tracemalloc.start(12)
        station = Station(config, SystemClock())
        station.start()
        load = Load(soak.tcp_port, soak.web_port, SATELLITES, 20.0 / speed, 60.0 / speed)
        load.start()
        stop = threading.Event()

        def faults() -> None:
            for second in range(1, 10**9):
                if stop.wait(1.0):
                    return
                if second % int(240 / speed) == 0:
                    soak.kill("rotctld", 15.0, stop)
                if second % int(360 / speed) == 0:
                    soak.kill("rigctld", 15.0, stop)

        threading.Thread(target=faults, daemon=True).start()
        started = time.monotonic()
        snapshots = []
        try:
            while time.monotonic() - started < args.minutes * 60.0:
                time.sleep(30.0)
                gc.collect()
                snapshots.append(tracemalloc.take_snapshot())
                print(f"{(time.monotonic() - started) / 60.0:5.1f} min: traced "
                      f"{tracemalloc.get_traced_memory()[0] / 2**20:.2f} MiB", flush=True)
        finally:
            stop.set()
            load.join()
            station.stop()
            soak.rotctld.kill()
            soak.rigctld.kill()
    if len(snapshots) < 3:
        return
    ignored = [tracemalloc.Filter(False, tracemalloc.__file__), tracemalloc.Filter(False, __file__)]
    early = snapshots[len(snapshots) // 3].filter_traces(ignored)
    late = snapshots[-1].filter_traces(ignored)
    for stat in [s for s in late.compare_to(early, "traceback") if s.size_diff > 2000][:15]:
        print(stat)
        for line in stat.traceback.format()[-12:]:
            print("   ", line)


if __name__ == "__main__":
    main(sys.argv[1:])
