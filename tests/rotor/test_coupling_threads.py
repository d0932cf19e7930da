"""The flip mode is set from other threads (TCP, console) while the rotor thread processes ticks."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from datetime import datetime, timedelta

from nfwserver.core.publisher import run_virtual
from nfwserver.rotor.geometry import RotorGeometry
from tests.dde.conftest import ISS_PASS
from tests.rotor.conftest import rotor_station


def _from_another_thread(call: Callable[[], None]) -> None:
    """Run ``call`` on a thread of its own (as the TCP or console thread would) and wait for it."""
    failures: list[BaseException] = []

    def run() -> None:
        try:
            call()
        except BaseException as exc:  # handed back to the test's thread
            failures.append(exc)

    thread = threading.Thread(target=run, name="tcp-like")
    thread.start()
    thread.join(10.0)
    assert not thread.is_alive() and not failures


def test_a_flip_change_from_another_thread_never_drives_the_rotor_from_that_thread() -> None:
    # A stalled rotor is tried again on an operator's action; that try is a rotor command (a rotctld
    # conversation), which must come from the coupling's own thread, not interleave with it from TCP's.
    geometry = RotorGeometry.preset("overlap-450")
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.aos + timedelta(seconds=60), geometry)
    run_virtual(server, clock, 5)
    rotor.az_stalled = True
    run_virtual(server, clock, 1)
    assert driver.stalled
    sent = len(rotor.commands)
    _from_another_thread(lambda: coupling.set_flip_mode("off"))
    assert coupling.flip_mode == "off" and not coupling.flip_state  # the choice is visible at once
    assert len(rotor.commands) == sent  # ... but the rotor was not touched from the caller's thread
    server.tick(clock.now())  # the coupling's next tick, on the thread that owns the rotor
    assert len(rotor.commands) > sent


def test_a_flip_change_during_a_tick_is_not_overwritten_by_that_tick() -> None:
    # The rotor thread is inside planning a pass (in flip mode auto) when the console forces flip on:
    # the tick must not put back the decision it planned with the old mode, and the next tick re-plans.
    geometry = RotorGeometry.preset("overlap-450+flip")
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.aos + timedelta(seconds=60), geometry,
                                                              after_los="stay")
    plain_track = coupling.pass_track
    flips: list[str] = []

    def pass_track(when: datetime) -> Sequence[tuple[datetime, float, float]] | None:
        if not flips:
            flips.append("on")
            _from_another_thread(lambda: coupling.set_flip_mode("on"))
        return plain_track(when)

    coupling.pass_track = pass_track
    coupling.set_flip_mode("auto")  # planned at the next tick
    server.tick(clock.now())
    assert flips == ["on"] and coupling.flip_mode == "on"
    assert coupling.flip_state  # what 7E reports follows the newest choice, not the stale plan
    run_virtual(server, clock, 5)
    assert coupling.plan is not None and coupling.plan.flipped and coupling.flip_state
    assert rotor.commands[-1][1] > 90.0
