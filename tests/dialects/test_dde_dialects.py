"""Orbitron, WXtrack and SatPC32 DDE dialects on the fake transport, parsed as their clients parse them."""

from __future__ import annotations

import re
from datetime import timedelta

import pytest

from nfwserver.core.publisher import run_virtual
from nfwserver.dialects.dde_service import DialectServer
from nfwserver.dialects.orbitron import ORBITRON, orbitron_name
from nfwserver.dialects.satpc32 import NO_SATELLITE, SATPC32
from nfwserver.dialects.wxtrack import WXTRACK
from nfwserver.radio.defaults import DEFAULT_CHANNELS
from nfwserver.tracking.doppler import SPEED_OF_LIGHT_KM_S as C
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER, make_station
from tests.tracking.skyfield_oracle import skyfield_look_angles

FM = DEFAULT_CHANNELS[ISS]


def get_field(source: str, label: str) -> str:
    """Field lookup the way Orbitron driver clients do it: ' LABEL' then up to the next blank."""
    m = re.search(r"(?:^| )" + label + r"(\S*)", source)
    return m.group(1) if m else ""


def _station_with(dialect, start):
    dut1 = float(skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, [start])[4][0])
    station = make_station(start=start, ut1_utc=dut1, channels={ISS: FM})
    server = DialectServer(dialect, station.core)
    server.attach(station.system.server_transport())
    return station, server


@pytest.mark.parametrize(("dialect", "service", "topic", "item"),
                         [(ORBITRON, "orbitron", "TRACKING", "TrackingData"),
                          (ORBITRON, "Orbitron", "Tracking", "TrackingDataEx"),
                          (WXTRACK, "WXtrack", "tracking", "Tracking")])
def test_orbitron_format_values_against_skyfield(dialect, service, topic, item) -> None:
    station, _ = _station_with(dialect, ISS_PASS.tca - timedelta(seconds=30))
    conv = station.system.connect(service, topic)
    conv.start_advise(item)
    stamps = []
    conv.on_receive = lambda r: stamps.append((station.clock.now(), r.text))
    run_virtual(station.core, station.clock, 60)
    assert len(stamps) > 250
    times = [t for t, _ in stamps]
    az, el, _, rr, _ = skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, times)
    for k, (_, text) in enumerate(stamps):
        assert get_field(text, "SN") == "ISS_ZARYA"
        assert abs((float(get_field(text, "AZ")) - az[k] + 180) % 360 - 180) <= 0.05 + 1e-3
        assert abs(float(get_field(text, "EL")) - el[k]) <= 0.05 + 1e-3
        assert abs(int(get_field(text, "DN")) - FM.downlink_hz * (1 - rr[k] / C)) <= 1.0
        assert abs(int(get_field(text, "UP")) - FM.uplink_hz * (1 + rr[k] / C)) <= 1.0
        assert get_field(text, "DM") == "FM" and get_field(text, "UM") == "FM"
    assert conv.request_text(item) == stamps[-1][1]


def test_orbitron_names() -> None:
    assert orbitron_name("ISS (ZARYA)") == "ISS_ZARYA"
    assert orbitron_name("SAUDISAT 1C (SO-50)") == "SAUDISAT_1C_SO-50"


def test_satpc32_by_field_order_and_no_satellite() -> None:
    station, server = _station_with(SATPC32, ISS_PASS.aos - timedelta(seconds=20))
    conv = station.system.connect("SatPC32", "SatPcDdeConv")
    conv.start_advise("SatPcDdeItem")
    run_virtual(station.core, station.clock, 10)
    assert conv.request_text("SatPcDdeItem") == NO_SATELLITE  # before AOS
    run_virtual(station.core, station.clock, 50)
    up = [t for t in conv.texts() if not t.startswith("**")]
    assert up and station.clock.now() > ISS_PASS.aos
    fields = up[-1].split(" ")
    labels = [f[:2] for f in fields]
    assert labels == ["SN", "AZ", "EL", "UP", "UM", "DN", "DM", "MA"]
    assert fields[0] == "SNISS" and 0 <= float(fields[7][2:]) < 256
    assert int(fields[3][2:]) > 145_000_000 and int(fields[5][2:]) > 437_000_000
    assert server.text() == up[-1]
    station.core.clear_satellite()
    station.core.tick()
    assert conv.request_text("SatPcDdeItem") == NO_SATELLITE


def test_dialects_take_no_commands_and_refuse_unknown_items() -> None:
    from nfwserver.fake_dde import DdeError

    station, _ = _station_with(ORBITRON, ISS_PASS.tca)
    conv = station.system.connect("Orbitron", "Tracking")
    with pytest.raises(DdeError):
        conv.poke("TrackingData", "anything")
    with pytest.raises(DdeError):
        conv.start_advise("Nonsense")
    # Nova's own service is still served next to it.
    nova = station.system.connect("NFW32", "NFW_DATA")
    nova.poke("NFW_SERVER", "TUNE ON")
    station.core.tick()
    assert nova.request_text("NFW_SERVER").startswith("ISS AZ:")


def test_station_serves_the_configured_dialects_next_to_nova() -> None:
    import socket as _socket

    from nfwserver.app.station import Station
    from nfwserver.clock import VirtualClock
    from nfwserver.config import parse_config
    from nfwserver.fake_dde import FakeDdeSystem

    config = parse_config('[observer]\nlocation = "52.2053,0.1218,20"\n[dialects]\ndde = ["orbitron", "satpc32"]\n'
                          'predict_udp = true\npredict_port = 0\n')
    system = FakeDdeSystem()
    station = Station(config, VirtualClock(ISS_PASS.tca), transport=system.server_transport())
    station.start()
    try:
        station.core.tick()
        assert get_field(system.connect("Orbitron", "Tracking").request_text("TrackingData"), "SN") == "ISS_ZARYA"
        assert system.connect("SatPC32", "SatPcDdeConv").request_text("SatPcDdeItem").startswith("SNISS ")
        with _socket.socket(_socket.AF_INET, _socket.SOCK_DGRAM) as client:
            client.settimeout(5)
            client.sendto(b"GET_MODE", station.predict.address)
            assert client.recvfrom(100)[0] == b"ISS\n"
    finally:
        station.stop()
