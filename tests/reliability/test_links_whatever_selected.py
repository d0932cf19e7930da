"""Every link's state true whatever is selected (#44 item 2), with real ``rotctld`` and ``rigctld`` killed and
started again while the station runs on a virtual clock.

Before: with a satellite without a radio channel selected (CUTE-1, CO-55), nothing spoke to ``rigctld``, so
STATUS said ``faults=rigctld radio=unreachable`` until a satellite with a channel was selected (34 s after the
daemon was back in the soak of the issue), and an outage was noticed only after the daemon returned, logged
as "recovered after 0.3 s"."""

from __future__ import annotations

import logging
import re
from datetime import datetime, timezone

import pytest

from nfwserver.app.station import Station
from nfwserver.app.status_fields import device_status
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.console.state_view import radio_line, rotor_line
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.rotor.kct_status import KctStatusBit
from nfwserver.web.station_parts import radio_part, rotor_part
from tests.conftest import advance_until
from tests.hamlib_daemons import HamlibDaemon

pytestmark = pytest.mark.hamlib

START = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)
CO_55 = 27844  # no radio channel in the default channel table


def _views(station: Station) -> dict[str, object]:
    """What STATUS, the web page, the console and OrbitDRV's status word say about the two links."""
    fields = device_status(station.rotor, station.radio, None)()
    faults = station.core.health.faults()
    rotor = rotor_part(station.rotor)
    radio = radio_part(station.radio, True)
    assert rotor is not None and radio is not None and station.rotor is not None
    return {"rotor": fields["rotor"], "radio": fields["radio"], "rotctld_fault": "rotctld" in faults,
            "rigctld_fault": "rigctld" in faults, "web_rotor": rotor["state"], "web_radio": radio["state"],
            "card_absent": bool(station.rotor.driver.status().bits & KctStatusBit.CARD_ABSENT),
            "console_radio_unreachable": "radio unreachable" in radio_line(station.radio, True).plain,
            "console_kct_card_absent": "KCT 0x8" in rotor_line(station.rotor).plain}


def test_a_daemon_leaving_and_returning_shows_within_seconds_whatever_is_selected(caplog) -> None:
    with HamlibDaemon("rotctld") as rot, HamlibDaemon("rigctld") as rig:
        config = parse_config(
            '[observer]\nlocation = "JO02ae"\n'
            f'[server]\nrate_hz = 10\nstate_file = "none"\nsatellite = {CO_55}\n'
            f'[radio]\nbackend = "rigctld"\nport = {rig.port}\nenabled = true\n'
            f'[rotor]\nbackend = "rotctld"\nport = {rot.port}\ngeometry = "overlap-450"\n'
            '[tcp]\nenabled = false\n[web]\nenabled = false\n')
        clock = VirtualClock(START)
        station = Station(config, clock, transport=FakeDdeSystem().server_transport())
        with caplog.at_level(logging.INFO):
            station.start()
            try:
                assert station.core.state.catalog_number == CO_55 and CO_55 not in station.core.state.channels
                assert advance_until(clock, lambda: _views(station)["rotor"] != "unreachable", limit_s=5.0)
                well = _views(station)
                assert well["radio"] == "no-channel" and not well["rigctld_fault"] and not well["card_absent"]
                for _ in range(2):
                    rot.kill()
                    rig.kill()
                    gone = clock.monotonic()
                    assert advance_until(clock, lambda: _views(station)["radio"] == "unreachable"
                                         and _views(station)["rotor"] == "unreachable", step_s=0.1, limit_s=10.0)
                    assert clock.monotonic() - gone <= 3.0  # noticed while the daemons are away
                    down = _views(station)
                    assert down["rigctld_fault"] and down["rotctld_fault"] and down["card_absent"]
                    assert down["web_radio"] == "unreachable" and down["web_rotor"] == "unreachable"
                    assert down["console_radio_unreachable"] and down["console_kct_card_absent"]
                    assert advance_until(clock, lambda gone=gone: clock.monotonic() - gone >= 20.0, step_s=0.5)
                    rot.start()
                    rig.start()
                    back = clock.monotonic()
                    assert advance_until(clock, lambda: (v := _views(station))["radio"] == "no-channel"
                                         and not v["rigctld_fault"] and not v["rotctld_fault"]
                                         and not v["card_absent"], step_s=0.1, limit_s=10.0)
                    assert clock.monotonic() - back <= 3.0  # the return seen within seconds, with no channel
                    again = _views(station)
                    assert not again["console_radio_unreachable"] and not again["console_kct_card_absent"]
                    # well for 10 s: the next outage is an episode of its own, not a flap
                    assert advance_until(clock, lambda back=back: clock.monotonic() - back >= 10.0, step_s=0.5)
            finally:
                station.stop()
    for name in ("rigctld", "rotctld"):
        lost = [r for r in caplog.records
                if r.getMessage().startswith(f"{name}: {name} at ") and " lost" in r.getMessage()]
        recovered = [float(m.group(1)) for r in caplog.records
                     if (m := re.match(rf"{name}: recovered after ([\d.]+) s", r.getMessage()))]
        assert len(lost) == 2 and len(recovered) == 2, (name, [r.getMessage() for r in caplog.records])
        assert all(19.0 <= seconds <= 24.0 for seconds in recovered), (name, recovered)  # the true length, ~20 s
