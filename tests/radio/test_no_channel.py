"""A radio while the selected satellite has no radio channel: one truthful state (#34 item 8).

STATUS showed ``radio=ok radio_rx=437799248``, the ISS's stale value, after ``SAT=`` of a satellite without a
channel.  A real ``rigctld -m 1``; the station core on a virtual clock; STATUS's device fields as the TCP
server builds them."""

from __future__ import annotations

from datetime import timedelta

import pytest

from nfwserver.app.status_fields import device_status
from nfwserver.core.publisher import run_virtual
from nfwserver.core.station_core import StationCore
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.radio.defaults import DEFAULT_CHANNELS
from nfwserver.radio.rigctld_backend import RigctldBackend
from nfwserver.radio.tuning import DopplerTuner
from nfwserver.web.station_parts import radio_part
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER

pytestmark = pytest.mark.hamlib


def test_a_satellite_without_a_channel_is_no_channel_with_no_stale_frequency(rigctld) -> None:
    from nfwserver.clock import VirtualClock

    clock = VirtualClock(ISS_PASS.tca - timedelta(seconds=30))
    core = StationCore(CATALOG, OBSERVER, clock, satellite=ISS, rate_hz=5, channels=DEFAULT_CHANNELS)
    tuner = DopplerTuner(DEFAULT_CHANNELS[ISS], RigctldBackend(clock, port=rigctld.port))
    radio = RadioCoupling(tuner, core.state, clock)
    core.subscribe(radio.process)
    core.set_doppler(True)
    status = device_status(None, radio, None)
    run_virtual(core, clock, 1.0)
    assert status()["radio"] == "ok" and 437_790_000 < int(status()["radio_rx"]) < 437_810_000
    other = next(s.catalog_number for s in CATALOG if s.catalog_number not in DEFAULT_CHANNELS)
    assert core.command(f"SAT={other}").ok
    # At once, before any tick: the state says why nothing is tuned, and no frequency of the ISS is shown.
    assert status() == {"radio": "no-channel"}
    part = radio_part(radio, True)  # what the web page gets, at once too
    assert part is not None and part["state"] == "no-channel" and part["rx_hz"] is None and part["tx_hz"] is None
    run_virtual(core, clock, 1.0)
    assert status() == {"radio": "no-channel"} and radio.last_result is None
    core.set_doppler(False)  # tuning off: nothing is expected of the radio
    assert status()["radio"] == "ok"
    core.set_doppler(True)
    assert core.command(f"SAT={ISS}").ok
    run_virtual(core, clock, 1.0)
    assert status()["radio"] == "ok" and 437_790_000 < int(status()["radio_rx"]) < 437_810_000
