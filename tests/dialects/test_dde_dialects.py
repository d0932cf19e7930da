"""Orbitron, WXtrack and SatPC32 DDE dialects on the fake transport, parsed as their clients parse them.

Expected forms come from the trackers' descriptions (issue 15, DESIGN 5b) and the public clients'
parsing code; values from skyfield.
"""

from __future__ import annotations

import re
from datetime import datetime, timedelta, timezone

import pytest
from skyfield.api import wgs84

from nfwserver.core.publisher import run_virtual
from nfwserver.dialects.base import DialectView
from nfwserver.dialects.dde_service import DialectServer
from nfwserver.dialects.orbitron import ORBITRON, format_tracking_data, format_tracking_data_ex, orbitron_name
from nfwserver.dialects.satpc32 import NO_SATELLITE, SATPC32, format_satpc32
from nfwserver.dialects.wxtrack import WXTRACK
from nfwserver.radio.defaults import DEFAULT_CHANNELS
from nfwserver.tracking.doppler import SPEED_OF_LIGHT_KM_S as C
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER, make_station
from tests.tracking.skyfield_oracle import TS, skyfield_look_angles, skyfield_satellite

FM = DEFAULT_CHANNELS[ISS]


def get_field(source: str, label: str) -> str:
    """Field lookup the way Orbitron driver clients do it: ' LABEL' then up to the next blank."""
    m = re.search(r"(?:^| )" + label + r"(\S*)", source)
    return m.group(1) if m else ""


def _station_with(dialect, start, **server_args):
    dut1 = float(skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, [start])[4][0])
    station = make_station(start=start, ut1_utc=dut1, channels={ISS: FM})
    server = DialectServer(dialect, station.core, **server_args)
    server.attach(station.system.server_transport())
    return station, server


@pytest.mark.parametrize(("dialect", "service", "topic", "item"),
                         [(ORBITRON, "orbitron", "TRACKING", "TrackingData"),
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
    assert orbitron_name("BAD\x01NAME\t2") == "BAD_NAME_2"  # control characters never shift fields


def _view(**changes) -> DialectView:
    base = dict(name="ISS (ZARYA)", dde_name="ISS", azimuth_deg=182.14, elevation_deg=36.26,
                range_rate_km_s=-1.2345, above_horizon=True, downlink_hz=145_801_000, uplink_hz=145_199_000,
                downlink_mode="FM", uplink_mode="FM", phase=52.64, range_km=650.04,
                time=datetime(2026, 5, 8, 12, 3, 4, tzinfo=timezone.utc),
                local_time=datetime(2026, 5, 8, 14, 3, 4, tzinfo=timezone(timedelta(hours=2))),
                subpoint=(51.234, -1.5, 420.06))
    base.update(changes)
    return DialectView(**base)


def test_tracking_data_exact_form() -> None:
    # "SN<name with spaces as _> AZ... EL... DN<Hz> UP<Hz> [DM...] [UM...], empty when nothing is tracked"
    assert format_tracking_data(_view()) == "SNISS_ZARYA AZ182.1 EL36.3 DN145801000 UP145199000 DMFM UMFM"
    no_modes = _view(downlink_mode=None, uplink_mode=None, uplink_hz=None, elevation_deg=-0.04,
                     azimuth_deg=359.97)
    assert format_tracking_data(no_modes) == "SNISS_ZARYA AZ0.0 EL0.0 DN145801000 UP0"
    assert format_tracking_data(None) == ""


def test_tracking_data_ex_exact_form() -> None:
    # 'SN"ISS ZARYA" (quoted name, spaces kept) followed by AZ, EL, DN, UP, DM, UM, RA (range), RR (range
    # rate), LO, LA, AL (sub-satellite longitude, latitude, altitude), TU/TL (UTC/local time), each field
    # followed by a space; when nothing is tracked, either empty or only AOS"name" for the next satellite.'
    assert format_tracking_data_ex(_view()) == (
        'SN"ISS ZARYA" AZ182.1 EL36.3 DN145801000 UP145199000 DMFM UMFM RA650.0 RR-1.234 LO-1.50 LA51.23 '
        "AL420.1 TU20260508120304 TL20260508140304 ")
    assert format_tracking_data_ex(_view(above_horizon=False)) == 'AOS"ISS ZARYA"'
    assert format_tracking_data_ex(None) == ""
    no_modes = format_tracking_data_ex(_view(downlink_mode=None, uplink_mode=None, uplink_hz=None))
    assert " UP0 DM UM RA" in no_modes


def _index_of_parse(text: str) -> dict[str, str]:
    """The public .NET client's parse: skip lines starting with 'A'; quoted name; IndexOf(label) up to a blank."""
    if text[0] == "A":  # (it indexes the first character, so an empty reply would crash it)
        return {}
    s1 = text.index('"')
    out = {"SN": text[s1 + 1 : text.index('"', s1 + 1)]}
    for label in ("AZ", "EL", "DN", "UP", "DM", "UM", "RA", "RR", "LA"):
        s1 = text.index(label)
        out[label] = text[s1 + 2 : text.index(" ", s1 + 1)]
    return out


def test_tracking_data_ex_values_against_skyfield() -> None:
    zone = timezone(timedelta(hours=-5))
    station, server = _station_with(ORBITRON, ISS_PASS.tca - timedelta(seconds=30), local_zone=zone)
    conv = station.system.connect("Orbitron", "Tracking")
    conv.start_advise("TrackingDataEx")
    stamps = []
    conv.on_receive = lambda r: stamps.append((station.clock.now(), r.text))
    run_virtual(station.core, station.clock, 20)
    assert len(stamps) > 50
    times = [t for t, _ in stamps]
    es = CATALOG.get(ISS).elements
    az, el, rng, rr, _ = skyfield_look_angles(es, OBSERVER, times)
    sub = wgs84.subpoint_of(skyfield_satellite(es).at(TS.from_datetimes(times)))
    height = wgs84.height_of(skyfield_satellite(es).at(TS.from_datetimes(times))).km
    for k, (when, text) in enumerate(stamps):
        fields = _index_of_parse(text)
        assert fields["SN"] == "ISS ZARYA" and text.endswith(" ")
        assert abs((float(fields["AZ"]) - az[k] + 180) % 360 - 180) <= 0.05 + 1e-3
        assert abs(float(fields["EL"]) - el[k]) <= 0.05 + 1e-3
        assert abs(float(fields["RA"]) - rng[k]) <= 0.05 + 0.01
        assert abs(float(fields["RR"]) - rr[k]) <= 0.0005 + 1e-4
        assert abs(int(fields["DN"]) - FM.downlink_hz * (1 - rr[k] / C)) <= 1.0
        assert abs(float(fields["LA"]) - sub.latitude.degrees[k]) <= 0.005 + 0.01
        assert abs(float(get_field(text, "LO")) - sub.longitude.degrees[k]) <= 0.005 + 0.01
        assert abs(float(get_field(text, "AL")) - height[k]) <= 0.05 + 0.5
        assert get_field(text, "TU") == when.strftime("%Y%m%d%H%M%S")
        assert get_field(text, "TL") == (when - timedelta(hours=5)).strftime("%Y%m%d%H%M%S")
    assert server.text("TrackingData").startswith("SNISS_ZARYA AZ")  # the other item, from the same view


def test_satpc32_by_field_order_and_no_satellite() -> None:
    station, server = _station_with(SATPC32, ISS_PASS.aos - timedelta(seconds=20))
    conv = station.system.connect("SatPC32", "SatPcDdeConv")
    conv.start_advise("SatPcDdeItem")
    run_virtual(station.core, station.clock, 10)
    # "** NO SATELLITE ** when nothing is tracked (clients test for the ** prefix), lines end in CR LF"
    assert conv.request_text("SatPcDdeItem") == "** NO SATELLITE **\r\n" == NO_SATELLITE + "\r\n"  # before AOS
    run_virtual(station.core, station.clock, 50)
    up = [t for t in conv.texts() if not t.startswith("**")]
    assert up and station.clock.now() > ISS_PASS.aos
    assert up[-1].endswith("\r\n")
    fields = up[-1][:-2].split(" ")
    labels = [f[:2] for f in fields]
    assert labels == ["SN", "AZ", "EL", "UP", "UM", "DN", "DM", "MA"]  # "field order SN AZ EL UP UM DN DM MA"
    assert fields[0] == "SNISS" and 0 <= float(fields[7][2:]) < 256
    assert int(fields[3][2:]) > 145_000_000 and int(fields[5][2:]) > 437_000_000
    assert server.text() == up[-1]
    station.core.clear_satellite()
    station.core.tick()
    assert conv.request_text("SatPcDdeItem").startswith("**")


def test_satpc32_exact_form_and_empty_modes() -> None:
    # "field order SN AZ EL UP UM DN DM MA (then optional RR), empty UM/DM allowed"
    view = _view(name="FO-29", dde_name="FO-29", azimuth_deg=56.74, elevation_deg=6.81, uplink_hz=145_951_275,
                 uplink_mode="LSB", downlink_hz=435_853_062, downlink_mode="USB", phase=52.61)
    assert format_satpc32(view) == "SNFO-29 AZ56.7 EL6.8 UP145951275 UMLSB DN435853062 DMUSB MA52.6\r\n"
    bare = _view(dde_name="AO 7", uplink_hz=None, uplink_mode=None, downlink_mode=None)
    assert format_satpc32(bare) == "SNAO_7 AZ182.1 EL36.3 UP0 UM DN145801000 DM MA52.6\r\n"
    assert format_satpc32(_view(above_horizon=False)) == "** NO SATELLITE **\r\n"


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
    from nfwserver.config.loader import parse_config
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
            assert client.recvfrom(100)[0] == b""  # PREDICT: empty until something is tracked
            station.core.set_feed(True, source="test")
            client.sendto(b"GET_MODE", station.predict.address)
            assert client.recvfrom(100)[0] == b"ISS (ZARYA)\n"
    finally:
        station.stop()
