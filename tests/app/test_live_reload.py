"""One live state: a changed observer reaches every output on the next tick (DDE, PREDICT, rotor, console).

The station runs on a virtual clock with its real threads (publisher, rotor worker, PREDICT listener);
expected values come from skyfield at the new site, never from our own output.
"""

from __future__ import annotations

import asyncio
import socket
from dataclasses import replace

from textual.widgets import Static

from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.console.app import NfwConsole
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.observer import parse_observer
from tests.app.console_helpers import settle
from tests.conftest import DATA, advance_until
from tests.dde.conftest import CATALOG, ISS, ISS_PASS
from tests.tracking.skyfield_oracle import skyfield_look_angles

OLD, NEW = "JO02ae", "JO62qm"  # Cambridge, then Berlin: the ISS is up at both during this pass


def _config(location: str):
    return parse_config(
        f'[observer]\nlocation = "{location}"\n[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = false\n'
        'store = "none"\n[server]\nstate_file = "none"\nsatellite = 25544\ntune = true\nrate_hz = 5\n'
        '[dialects]\npredict_udp = true\npredict_port = 0\n'
        '[rotor]\nbackend = "sim"\ngeometry = "overlap-450"\nmax_lead_s = 0\n')


def _predict(address, text: str) -> str:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as client:
        client.settimeout(5.0)
        client.sendto(text.encode(), address)
        return client.recvfrom(4096)[0].decode()


def test_a_new_observer_reaches_dde_predict_rotor_and_console_on_the_next_tick() -> None:
    clock = VirtualClock(ISS_PASS.tca)
    system = FakeDdeSystem()
    station = Station(_config(OLD), clock, transport=system.server_transport())
    station.start()
    try:
        conv = system.connect("NFW32", "NFW_DATA")
        assert advance_until(clock, lambda: conv.request_text("NFW_SERVER").startswith("ISS "))
        new_site = parse_observer(NEW)
        assert _predict(station.predict.address, "GET_QTH").split("\n")[1] != f"{new_site.latitude_deg:g}"

        station.apply_config(replace(_config(NEW), dialects=station.config.dialects))
        changed_at = clock.now()
        assert advance_until(clock, lambda: (s := station.core.tracker.last_sample) is not None
                             and s.time > changed_at)
        sample = station.core.tracker.last_sample
        az, el, *_ = skyfield_look_angles(CATALOG.get(ISS).elements, new_site, [sample.time])
        # DDE: the string of the tick after the change is the new site's view.
        text = conv.request_text("NFW_SERVER")
        assert text == sample.text
        fields = dict(f.split(":") for f in text.split()[1:])
        assert abs(float(fields["AZ"]) - float(az[0])) <= 0.051 and abs(float(fields["EL"]) - float(el[0])) <= 0.051
        # PREDICT: GET_QTH reports the new site (longitude west-positive, as PREDICT does).
        qth = _predict(station.predict.address, "GET_QTH").split("\n")
        assert float(qth[1]) == float(f"{new_site.latitude_deg:g}")
        assert float(qth[2]) == float(f"{(-new_site.longitude_deg) % 360:g}")
        # Rotor: its aim comes from the new site.
        aim = station.rotor.predict(sample.time)
        assert aim is not None and abs(aim[0] - float(az[0])) < 1e-3 and abs(aim[1] - float(el[0])) < 1e-3
        # Console: the state pane shows the new site's azimuth.
        console_text = asyncio.run(_console_state(station))
        assert f"AZ {float(az[0]):6.1f}" in console_text or f"AZ {sample.look_angles.azimuth_deg:6.1f}" in console_text
    finally:
        station.stop()


async def _console_state(station: Station) -> str:
    app = NfwConsole(station.core, favourites=(ISS,), clients=station.nova.client_count)
    async with app.run_test(size=(140, 40)) as pilot:
        await settle(app, pilot, until=lambda: "AZ " in str(app.query_one("#state", Static).render()))
        return str(app.query_one("#state", Static).render())
