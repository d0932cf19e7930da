"""The in-process DDE transport and the event log stay bounded under hostile clients (issue 18 item 11):
huge refused pokes are recorded truncated, conversations per service are capped with a clear
refusal, and the tick cost no longer grows with abandoned clients."""

from __future__ import annotations

import gc
import tracemalloc

import pytest

from nfwserver.core.events import MAX_EVENT_TEXT, Direction, EventLog
from nfwserver.fake_dde import DMLERR_NO_CONV_ESTABLISHED, DdeError, FakeDdeSystem
from tests.dde.conftest import make_station


def test_refused_one_megabyte_pokes_hold_kilobytes_not_gigabytes() -> None:
    station = make_station()
    conv = station.system.connect("NFW32", "NFW_DATA")
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for k in range(120):
            with pytest.raises(DdeError):
                conv.poke("NFW_SERVER", f"{k} " + "X" * 1_000_000)
        gc.collect()
        held = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    pokes = [e for e in station.core.events.recent() if e.kind == "poke"]
    assert len(pokes) == 120 and all(e.accepted is False for e in pokes)
    assert all(len(e.text) <= MAX_EVENT_TEXT + 40 and e.text.endswith("more characters]") for e in pokes)
    assert pokes[7].text.startswith("7 XXX")  # what was sent stays recognisable
    assert held < 4 * 2**20, f"{held / 2**20:.1f} MiB held"  # unbounded, 120 pokes held 230 MiB


def test_event_text_and_detail_are_truncated_and_short_ones_kept() -> None:
    events = EventLog(capacity=10)
    from datetime import datetime, timezone

    now = datetime(2026, 1, 1, tzinfo=timezone.utc)
    short = events.add(now, Direction.IN, "poke", "TUNE ON", detail="ok")
    assert (short.text, short.detail) == ("TUNE ON", "ok")
    long = events.add(now, Direction.IN, "poke", "A" * 5000, detail="B" * 5000)
    assert long.text == "A" * MAX_EVENT_TEXT + f"... [{5000 - MAX_EVENT_TEXT} more characters]"
    assert long.detail.startswith("B" * MAX_EVENT_TEXT) and len(long.detail) < MAX_EVENT_TEXT + 40


def test_conversations_per_service_are_capped_with_a_clear_refusal() -> None:
    station = make_station()
    system: FakeDdeSystem = station.system
    cap = system.max_conversations_per_service
    convs = [system.connect("NFW32", "NFW_DATA") for _ in range(cap)]
    with pytest.raises(DdeError, match="already has 256 conversations; connect refused") as refused:
        system.connect("NFW32", "NFW_DATA")
    assert refused.value.code == DMLERR_NO_CONV_ESTABLISHED and system.refused_connects == 1
    convs[0].disconnect()  # a place is free again
    system.connect("nfw32", "nfw_data").start_advise("NFW_SERVER")
    assert system.conversation_count() == cap


def test_tick_cost_is_bounded_with_twenty_thousand_abandoned_hot_clients() -> None:
    station = make_station()
    station.core.set_feed(True)
    system = station.system
    opened = 0
    for _ in range(20_000):
        try:
            system.connect("NFW32", "NFW_DATA").start_advise("NFW_SERVER")  # never read, never closed
            opened += 1
        except DdeError:
            pass
    assert opened == system.max_conversations_per_service and system.refused_connects == 20_000 - opened
    ticks = station.run(20.0)
    # Each tick serves one advise loop per accepted conversation, however many clients tried; the time
    # this takes is measured by ``python -m bench dde`` (docs/BENCHMARKS.md), not asserted here.
    publishes = [e for e in station.core.events.recent() if e.kind == "publish"]
    assert len(publishes) == ticks and {e.detail for e in publishes} == {f"{opened} advise loop(s)"}
    assert all(len(c.client.received) == ticks for c in system._conversations.values())


def test_a_clients_record_is_bounded() -> None:
    station = make_station()
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.start_advise("NFW_SERVER")
    station.core.set_feed(True)
    station.run(3000.0)  # 15,000 ticks at 5 Hz, never read
    assert len(conv.received) == station.system.received_capacity == 10_000


def test_advise_loops_are_served_only_to_their_item_and_forgotten_on_stop_and_disconnect() -> None:
    station = make_station()
    system = station.system
    a, b = system.connect("NFW32", "NFW_DATA"), system.connect("NFW32", "NFW_DATA")
    a.start_advise("NFW_SERVER")
    b.start_advise("NFW_SERVER")
    station.core.set_feed(True)
    station.run(1.0)
    b.stop_advise("NFW_SERVER")
    station.run(1.0)
    a.disconnect()
    station.run(1.0)
    assert len(a.texts()) == 2 * len(b.texts()) > 0
    assert system.advise_loop_count() == 0 and not system._advised
