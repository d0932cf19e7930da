"""A sample handed to a tick worker while it takes the previous one is processed, not lost (issue 36 item 8)."""

from __future__ import annotations

import threading

from nfwserver.core.tick_worker import TickWorker
from tests.dde.conftest import make_station
from tests.waiting import wait_for


class Interleaved(TickWorker):
    """Records what it processes; the first time the worker reads the pending sample, the publisher hands over
    the next one from its own thread at that very moment (as a tick arriving mid-hand-over does)."""

    thread_name = "test-worker"

    def __init__(self, first, second) -> None:
        self.first, self.second, self.seen = first, second, []
        self._arrive = True
        super().__init__()

    def process(self, sample) -> None:
        self.seen.append(sample)

    @property
    def _pending(self):
        value = self.__dict__.get("_slot")
        if value is self.first and self._arrive:
            self._arrive = False
            publisher = threading.Thread(target=self.on_tick, args=(self.second,))
            publisher.start()
            publisher.join(0.2)  # done at once unless the hand-over holds it back until the first is taken
        return value

    @_pending.setter
    def _pending(self, value) -> None:
        self.__dict__["_slot"] = value


def test_a_sample_arriving_during_the_hand_over_is_processed() -> None:
    station = make_station()
    first, second = station.core.tick(), station.core.tick()
    worker = Interleaved(first, second)
    worker.start()
    try:
        worker.on_tick(first)
        wait_for(lambda: len(worker.seen) == 2, 5.0, lambda: f"the second sample (processed: {len(worker.seen)})")
        assert worker.seen == [first, second]
    finally:
        worker.stop()
