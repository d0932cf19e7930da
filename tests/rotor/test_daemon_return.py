"""A rotor whose daemon returns is sent its target again at once, and a rotor that is neither where it was
sent nor moving there is shown as ``off-target``, never ``ok`` (#34 item 1).

A real ``rotctld -m 1`` on a loopback port: the dummy rotor turns at about 6 deg/s in real time and comes back
from a restart at 0/0, having forgotten its target, as the issue measured.  The driver runs on a virtual
clock, one service call per 0.2 virtual seconds (the station's 5 Hz tick).
"""

from __future__ import annotations

from datetime import datetime, timezone

import pytest

from nfwserver.app.status_fields import device_status
from nfwserver.clock import VirtualClock
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.rotctld_backend import RotctldBackend
from tests.hamlib_daemons import HamlibDaemon
from tests.waiting import wait_for

pytestmark = pytest.mark.hamlib
GEOMETRY = RotorGeometry(-180.0, 450.0, 0.0, 90.0)  # rotctld's default limits for the dummy
START = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)
TICK_S = 0.2


def _position(daemon: HamlibDaemon) -> tuple[float, float]:
    az, el = daemon.query("p", 2)
    return float(az), float(el)


def _driver(daemon: HamlibDaemon, clock: VirtualClock, stall_timeout_s: float | None = 15.0) -> KctDriver:
    backend = RotctldBackend(clock, GEOMETRY, port=daemon.port, timeout_s=0.5)
    return KctDriver(clock, backend, GEOMETRY, stall_timeout_s=stall_timeout_s)


def test_a_still_target_is_sent_again_as_soon_as_rotctld_returns() -> None:
    """The issue: a still target (GEO), rotctld restarted; the station sent nothing for 20.9 s and then took
    the motionless rotor for a stalled one.  Now the first reading after the return sends the target."""
    with HamlibDaemon("rotctld") as daemon:
        clock = VirtualClock(START)
        driver = _driver(daemon, clock)
        driver.service()
        assert driver.set_target(azimuth_deg=20.0, elevation_deg=10.0)
        wait_for(lambda: abs(_position(daemon)[0] - 20.0) < 1.0, 15.0, "the dummy at 20 deg", interval_s=0.05)
        driver.service()
        assert driver.link_state() == "ok"
        daemon.restart()  # back at 0/0, its target forgotten
        assert _position(daemon) == (0.0, 0.0)
        for _ in range(15):  # the station's ticks for 3 virtual seconds after the return
            clock.advance(TICK_S)
            driver.service()
        assert driver.link_state() != "unreachable", "no reconnection within 3 s of the daemon's return"
        # No more service calls: whatever moves the dummy now was sent by then.
        wait_for(lambda: _position(daemon)[0] > 1.0, 5.0, "the target sent again (the dummy moving)", interval_s=0.05)
        assert driver.health.ok and not driver.stalled


def test_a_rotor_neither_on_target_nor_moving_there_is_off_target_not_ok() -> None:
    """The dummy is stopped behind the station's back (``S`` on the test's own connection): the station's
    STATUS must not say ``ok`` while it sits short of its target, and it is no stall until the timeout."""
    with HamlibDaemon("rotctld") as daemon:
        clock = VirtualClock(START)
        driver = _driver(daemon, clock)
        coupling = RotorCoupling(driver, lambda when: None, lambda when: None)
        status = device_status(coupling, None, None)
        driver.service()
        assert driver.set_target(azimuth_deg=80.0, elevation_deg=40.0)
        wait_for(lambda: _position(daemon)[0] > 2.0, 5.0, "the dummy moving", interval_s=0.05)
        assert daemon.command("S").strip() == "RPRT 0"  # the rotor stops short of 80
        stopped = _position(daemon)
        assert stopped[0] < 70.0
        clock.advance(TICK_S)
        driver.service()
        for _ in range(20):  # 4 virtual seconds: past the grace, well before the 15 s stall timeout
            clock.advance(TICK_S)
            driver.service()
        assert _position(daemon) == stopped
        assert status()["rotor"] == "off-target"
        assert not driver.stalled
        driver.set_target(azimuth_deg=stopped[0], elevation_deg=stopped[1])  # told where it is: on target
        clock.advance(TICK_S)
        driver.service()
        assert status()["rotor"] == "ok"


def test_four_outages_within_a_minute_each_get_their_lost_and_recovered_lines(caplog) -> None:
    """#34 item 9, with a real rotctld killed four times within one (virtual) minute: the log lines were
    limited per link, so only the first outage was written."""
    import logging

    from nfwserver.hamlib.commands import GET_POSITION
    from nfwserver.hamlib.connection import HamlibConnection, HamlibUnavailable

    with HamlibDaemon("rotctld") as daemon:
        clock = VirtualClock(START)
        link = HamlibConnection("127.0.0.1", daemon.port, clock, name="rotctld")
        with caplog.at_level(logging.INFO, logger="nfwserver.hamlib.connection"):
            for _ in range(4):
                assert len(link.call(GET_POSITION)) == 2
                daemon.kill()
                for _ in range(40):  # 8 s out, polled at 5 Hz
                    with pytest.raises(HamlibUnavailable):
                        link.call(GET_POSITION)
                    clock.advance(TICK_S)
                daemon.start()
                clock.advance(2.0)  # past the back-off
                assert len(link.call(GET_POSITION)) == 2 and link.health.ok
                clock.advance(4.0)
        lines = [r.getMessage() for r in caplog.records]
        assert sum("rotctld at 127.0.0.1" in line and " lost (" in line for line in lines) == 4, lines
        assert sum("rotctld: recovered after" in line for line in lines) == 4, lines
