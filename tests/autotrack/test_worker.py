"""The runtime on a real station core's ticks (AutotrackWorker), selecting through the core, on virtual time."""

from __future__ import annotations

from datetime import timedelta

from nfwserver.autotrack import AutotrackRuntime, AutotrackSettings, StationPlanner
from nfwserver.autotrack.worker import AutotrackWorker
from nfwserver.clock import VirtualClock
from nfwserver.core.station_core import StationCore
from nfwserver.tracking.horizon import HorizonTable
from tests.autotrack.test_runtime import OBSERVER, SIX, START, _catalog
from tests.waiting import wait_for


def test_the_worker_follows_the_cores_ticks_and_selects_through_it() -> None:
    clock = VirtualClock(START + timedelta(hours=2, minutes=10))  # ISS 02:03-02:14 under way; SO-50 next
    core = StationCore(_catalog(), OBSERVER, clock, satellite=7530)
    planner = StationPlanner(lambda: core.state.catalog, lambda: (OBSERVER, HorizonTable(), 0.0),
                             lambda: AutotrackSettings(tuple(SIX)))

    def select(number: int) -> str | None:
        return None if core.select_satellite(number, source="autotrack") else f"satellite {number} is not known"

    worker = AutotrackWorker(AutotrackRuntime(planner, select, on=True), clock)
    unsubscribe = core.subscribe(worker.on_tick)
    worker.start()
    try:
        core.tick(clock.now())
        wait_for(lambda: core.state.catalog_number == 25544, 10.0, "ISS, whose pass is under way")
        assert core.selected_by == "autotrack"
        clock.advance(5 * 60)  # past the ISS pass's LOS (02:14:22)
        core.tick(clock.now())
        wait_for(lambda: core.state.catalog_number == 27607, 10.0, "SO-50, the next scheduled pass")
        wait_for(lambda: worker.processed_time == clock.now(), 10.0, "the worker to finish the tick")
    finally:
        unsubscribe()
        worker.stop()
