"""The publish loop's timing (#44 items 1 and 4): lateness kept in constant memory whatever the run's length,
and a stall logged with what held it (a garbage collection, the tick's own work).

Before: every lateness sample was kept in a list of up to 100,000 floats (1.1 MiB/h of growth for 2.8 h at
10 Hz), and a stall was only a number in that list: nothing said why it happened."""

from __future__ import annotations

import gc
import logging
import random
import re
import threading
import tracemalloc
from datetime import datetime, timezone

from nfwserver.clock import VirtualClock
from nfwserver.core.publisher import Publisher, PublishStats
from nfwserver.core.station_core import StationCore
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from tests.conftest import DATA, advance_until

START = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)


def test_lateness_of_a_long_run_takes_constant_memory_and_keeps_its_quantiles() -> None:
    rng = random.Random(44)
    samples = [rng.lognormvariate(-6.0, 1.0) for _ in range(300_000)]  # ~2.5 ms median, a long tail
    stats = PublishStats()
    for late in samples[:1000]:
        stats.record(late)
    tracemalloc.start()
    try:
        before = tracemalloc.take_snapshot()
        for late in samples[1000:]:
            stats.record(late)
        grown = sum(stat.size_diff for stat in tracemalloc.take_snapshot().compare_to(before, "filename")
                    if "publish" in str(stat.traceback))
    finally:
        tracemalloc.stop()
    assert grown < 4096  # 299,000 more ticks (8.3 h at 10 Hz) cost nothing; the list grew by 800 KB
    ordered = sorted(samples)  # the oracle: the samples themselves
    for q in (0.5, 0.9, 0.99, 0.999):
        exact = ordered[int(q * len(ordered))]
        assert exact <= stats.lateness.quantile(q) <= exact * 1.19 + 1e-12
    assert stats.lateness.max_s == ordered[-1] and stats.ticks == len(samples)


def _core(clock: VirtualClock) -> StationCore:
    catalog = Catalog(load_element_file(DATA / "visual.txt").sets)
    return StationCore(catalog, Observer(52.2, 0.12, 20.0), clock, satellite=25544, rate_hz=10.0)


def _run_with(clock: VirtualClock, core: StationCore, caplog) -> Publisher:
    publisher = Publisher(core, clock)
    with caplog.at_level(logging.INFO, logger="nfwserver.core.publisher"):
        publisher.start()
        try:
            assert advance_until(clock, lambda: publisher.stats.ticks >= 30, step_s=0.05, limit_s=30.0)
        finally:
            publisher.stop()
    return publisher


def test_a_stall_in_a_garbage_collection_is_logged_as_one(caplog) -> None:
    clock = VirtualClock(START)
    core = _core(clock)
    armed = threading.Event()

    def slow_collection(phase: str, info: dict[str, int]) -> None:  # a 0.8 s collection, on the virtual clock
        if phase == "stop" and armed.is_set():
            armed.clear()
            clock.advance(0.8)

    def collect_on_tenth_tick(sample) -> None:
        collect_on_tenth_tick.count += 1  # type: ignore[attr-defined]
        if collect_on_tenth_tick.count == 10:  # type: ignore[attr-defined]
            armed.set()
            gc.collect()

    collect_on_tenth_tick.count = 0  # type: ignore[attr-defined]
    core.subscribe(collect_on_tenth_tick)
    gc.callbacks.insert(0, slow_collection)  # runs before the publisher's, so its "stop" sees the advance
    try:
        publisher = _run_with(clock, core, caplog)
    finally:
        gc.callbacks.remove(slow_collection)
    (stall,) = publisher.stats.stalls
    assert 0.7 <= stall.late_s <= 0.9
    assert re.fullmatch(r"garbage collection 0\.(7|8)\d s \(generation 2\)", stall.cause)
    assert any("publish tick 0.7" in r.getMessage() and "garbage collection" in r.getMessage()
               for r in caplog.records)


def test_a_stall_in_a_slow_tick_listener_is_logged_as_the_tick_work(caplog) -> None:
    clock = VirtualClock(START)
    core = _core(clock)

    def slow_on_tenth_tick(sample) -> None:
        slow_on_tenth_tick.count += 1  # type: ignore[attr-defined]
        if slow_on_tenth_tick.count == 10:  # type: ignore[attr-defined]
            clock.advance(0.9)  # a listener that held the tick for 0.9 s

    slow_on_tenth_tick.count = 0  # type: ignore[attr-defined]
    core.subscribe(slow_on_tenth_tick)
    publisher = _run_with(clock, core, caplog)
    (stall,) = publisher.stats.stalls
    assert stall.cause.startswith("the previous tick's own work 0.8")
    assert "garbage" not in stall.cause
    # The listener slept on the clock, it did not compute: the tick's time is told apart from its CPU time.
    assert "(0.00 s of it on the processor, the rest waiting inside the tick" in stall.cause
    assert any("publish tick 0.8" in r.getMessage() for r in caplog.records)
