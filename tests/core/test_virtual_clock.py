"""The virtual clock's waits: a waiting thread wakes when the clock passes its deadline, and ``waiting`` tells a
test that a loop has reached its wait (so the test advances the clock then, instead of pausing for it)."""

from __future__ import annotations

import threading
from datetime import datetime, timezone

from nfwserver.clock import VirtualClock
from tests.waiting import wait_for


def test_waiting_counts_the_threads_waiting_for_a_moment_still_ahead() -> None:
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    stop = threading.Event()
    woke: list[float] = []

    def loop() -> None:
        while not clock.wait(stop, 5.0):
            woke.append(clock.monotonic())

    assert clock.waiting == 0
    worker = threading.Thread(target=loop, daemon=True)
    worker.start()
    try:
        wait_for(lambda: clock.waiting == 1, 5.0, "the loop to wait")
        assert clock.is_waiting(worker) and not clock.is_waiting(threading.current_thread())
        clock.advance(4.0)  # not yet: still waiting for the same moment
        assert clock.waiting == 1 and woke == [] and clock.is_waiting(worker)
        clock.advance(1.0)  # its moment: it wakes, then waits for the next one
        wait_for(lambda: woke == [5.0] and clock.waiting == 1, 5.0, "the loop to wake once and wait again")
        clock.advance(12.0)  # past two deadlines at once: one wake, as a late wake-up
        wait_for(lambda: woke == [5.0, 17.0] and clock.waiting == 1, 5.0, "one more wake")
    finally:
        stop.set()
        worker.join(5.0)
    assert not worker.is_alive() and clock.waiting == 0 and not clock.is_waiting(worker)
