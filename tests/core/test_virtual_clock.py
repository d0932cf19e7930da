"""The virtual clock's waits: a waiting thread wakes when the clock passes its deadline, and ``is_waiting`` tells a
test that a loop has reached its wait (so the test advances the clock then, instead of pausing for it)."""

from __future__ import annotations

import threading
from datetime import datetime, timezone

from nfwserver.clock import VirtualClock
from tests.waiting import wait_for


def test_is_waiting_tells_a_thread_waiting_for_a_moment_still_ahead() -> None:
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    stop = threading.Event()
    woke: list[float] = []

    def loop() -> None:
        while not clock.wait(stop, 5.0):
            woke.append(clock.monotonic())

    worker = threading.Thread(target=loop, daemon=True)
    worker.start()
    try:
        wait_for(lambda: clock.is_waiting(worker), 5.0, "the loop to wait")
        assert not clock.is_waiting(threading.current_thread())
        clock.advance(4.0)  # not yet: still waiting for the same moment
        assert clock.is_waiting(worker) and woke == []
        clock.advance(1.0)  # its moment: it wakes, then waits for the next one
        wait_for(lambda: woke == [5.0] and clock.is_waiting(worker), 5.0, "the loop to wake once and wait again")
        clock.advance(12.0)  # past two deadlines at once: one wake, as a late wake-up
        wait_for(lambda: woke == [5.0, 17.0] and clock.is_waiting(worker), 5.0, "one more wake")
    finally:
        stop.set()
        worker.join(5.0)
    assert not worker.is_alive() and not clock.is_waiting(worker)
