"""Memory that plateaus (#44 item 1): a station run for many virtual hours, with what an unattended station
meets -- satellite switches from TCP, element re-reads every 3 minutes, a radio daemon that is not there, a
rotor following passes -- keeps what it holds bounded.  The publish loop's timing is recorded per tick as the
publisher does.  Before: the lateness record alone grew by a float per tick (100,000 kept), and every element
re-read froze the cyclic garbage alive at that moment for good.

tracemalloc is the oracle: the memory allocated while the station runs (its own records and what they hold) is
compared from the second virtual hour (the bounded records, such as the 5,000-event log, full by then) to the
last."""

from __future__ import annotations

import gc
import logging
import random
import tracemalloc
from datetime import datetime, timedelta, timezone

from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.core.publisher import PublishStats
from nfwserver.fake_dde import FakeDdeSystem
from tests.conftest import DATA
from tests.hamlib_daemons import HamlibDaemon, free_port

START = datetime(2026, 5, 8, 6, tzinfo=timezone.utc)
HOURS = 5
RATE_HZ = 1.0


def _held(snapshot: tracemalloc.Snapshot) -> int:
    """Bytes allocated since tracing began and still alive, but tracemalloc's own."""
    mine = snapshot.filter_traces([tracemalloc.Filter(False, tracemalloc.__file__)])
    return sum(stat.size for stat in mine.statistics("filename"))


def test_five_virtual_hours_hold_no_more_than_the_second(monkeypatch) -> None:
    # The log goes nowhere: pytest's capture keeps every record, and with it the texts the station made.
    monkeypatch.setattr(logging.getLogger("nfwserver"), "propagate", False)
    monkeypatch.setattr(logging.getLogger("nfwserver"), "handlers", [logging.NullHandler()])
    with HamlibDaemon("rotctld", extra=["--set-conf=min_az=0,max_az=450,min_el=0,max_el=90"]) as rot:
        _run_for_hours(rot.port)


def _run_for_hours(rotctld_port: int) -> None:
    config = parse_config(
        '[observer]\nlocation = "JO02ae"\n'
        f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = true\n'
        f'[server]\nrate_hz = {RATE_HZ:g}\nstate_file = "none"\nsatellite = 25544\ntune = true\ntrack = true\n'
        f'[radio]\nbackend = "rigctld"\nport = {free_port()}\nenabled = true\n'  # nobody listens: probed, failing
        f'[rotor]\nbackend = "rotctld"\nport = {rotctld_port}\ngeometry = "overlap-450"\n')
    clock = VirtualClock(START)
    station = Station(config, clock, transport=FakeDdeSystem().server_transport())
    station._load_catalog()
    station._restore_session()
    core, rotor, radio = station.core, station.rotor, station.radio
    assert rotor is not None and radio is not None
    stats = PublishStats()  # the publisher's record, fed as its loop feeds it
    numbers = [25544, 14129, 27844, 43017, 7530, 20580]  # switched every 2 s: the event log (5,000) is full in 2 h
    rng = random.Random(44)
    held: list[int] = []
    tracemalloc.start()
    try:
        for k in range(int(HOURS * 3600 * RATE_HZ) + 1):
            clock.set(START + timedelta(seconds=k / RATE_HZ))
            sample = core.tick(clock.now())
            rotor.process(sample)
            radio.process(sample)
            stats.record(rng.random() * 0.002)
            if k % 2 == 0:
                core.command(f"SAT={rng.choice(numbers)}", source="tcp 127.0.0.1:5000")
            if k % 180 == 0:
                station.refresh_elements()
            if k % 3600 == 0 and k:
                gc.collect()
                held.append(_held(tracemalloc.take_snapshot()))
    finally:
        tracemalloc.stop()
        gc.unfreeze()
    assert radio.link_state() == "unreachable" and core.health.faults().get("rigctld")
    # From the second hour on (the bounded records full by then) nothing grows: 100 KiB is less than an
    # hour's lateness samples (3,600 floats) and less than an element re-read's frozen garbage.
    assert max(held[2:]) - held[1] < 100_000, [f"{h / 1024:.0f} KiB" for h in held]
