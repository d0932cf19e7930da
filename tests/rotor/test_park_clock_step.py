"""PARK ignores only samples computed before it (issue 36 item 8): once a later sample has been seen, a clock
stepped back (an NTP correction) does not make a new TRACK ON look like a sample from before the PARK."""

from __future__ import annotations

from datetime import timedelta

from nfwserver.core.publisher import run_virtual
from nfwserver.rotor.geometry import RotorGeometry
from tests.dde.conftest import ISS_PASS
from tests.rotor.conftest import rotor_station


def test_track_on_after_a_clock_step_back_is_followed() -> None:
    clock, core, _, driver, coupling, _ = rotor_station(ISS_PASS.tca, RotorGeometry(-180.0, 450.0, 0.0, 90.0))
    assert driver.set_parking(0, 180, 10)
    run_virtual(core, clock, 1.0)
    core.set_track(False, "test")
    coupling.request_park()
    run_virtual(core, clock, 2.0)  # parked; later samples seen
    assert driver.positions()[2:] == (10, 180)
    with clock._lock:  # the wall clock is stepped back a minute (NTP); monotonic time goes on
        clock._start -= timedelta(seconds=60)
    core.set_track(True, "test")
    run_virtual(core, clock, 1.0)
    target_el, target_az = driver.positions()[2:]
    la = core.tracker.last_sample.look_angles
    # following the satellite again (aimed a little ahead of it by the rotor's travel time)
    assert (target_el, target_az) != (10, 180) and abs(target_el - la.elevation_deg) < 10.0
