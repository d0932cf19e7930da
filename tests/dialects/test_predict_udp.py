"""PREDICT's UDP protocol over real loopback UDP: reply formats byte for byte, values checked."""

from __future__ import annotations

import math
import re
import socket
from collections.abc import Iterator
from datetime import timedelta

import pytest
from skyfield.api import load

from nfwserver.clock import VirtualClock
from nfwserver.core.state import StationState
from nfwserver.dialects.predict_udp import PredictContext, PredictUdpServer
from nfwserver.tracking.doppler import SPEED_OF_LIGHT_KM_S as C
from nfwserver.tracking.look_angles import LookAngleCalculator
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER
from tests.tracking.skyfield_oracle import TS, skyfield_topos

F72 = r"-?\d+\.\d\d *"  # %-7.2f
SF62 = r"[+-]\d+\.\d\d *"  # %+-6.2f


@pytest.fixture
def predict() -> Iterator[tuple[socket.socket, tuple[str, int], VirtualClock, list[str]]]:
    clock = VirtualClock(ISS_PASS.tca)
    reloads: list[str] = []
    ctx = PredictContext(StationState(CATALOG, OBSERVER), clock, lambda: [ISS, 27607], mode=lambda: "ISS\n",
                         callsign="G0XYZ", on_reload=lambda: reloads.append("x"))
    server = PredictUdpServer(ctx, "127.0.0.1", 0)
    server.start()
    client = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    client.settimeout(5.0)
    yield client, server.address, clock, reloads
    client.close()
    server.stop()


def ask(client, address, text: str | bytes) -> str:
    client.sendto(text if isinstance(text, bytes) else text.encode("ascii"), address)
    return client.recvfrom(65536)[0].decode("ascii")


def test_get_sat_layout_and_values(predict) -> None:
    client, address, clock, _ = predict
    reply = ask(client, address, "GET_SAT ISS (ZARYA)")
    lines = reply.split("\n")
    assert reply.endswith("\n") and len(lines) == 16
    pattern = [r"ISS \(ZARYA\)", F72, SF62, F72, SF62, r"\d+", F72, F72, F72, F72, r"\d+", "[VDN]", F72, F72, F72]
    for line, expected in zip(lines, pattern):
        assert re.fullmatch(expected, line), (line, expected)
    assert all(len(lines[i]) >= 7 for i in (1, 3, 6, 7, 8, 9)) and len(lines[2]) >= 6
    la = LookAngleCalculator(OBSERVER).compute(CATALOG.get(ISS).satrec, clock.now())
    assert float(lines[3]) == pytest.approx(la.azimuth_deg, abs=0.006)
    assert float(lines[4]) == pytest.approx(la.elevation_deg, abs=0.006)
    assert float(lines[7]) == pytest.approx(la.range_km, abs=0.006)
    assert 350 < float(lines[8]) < 450 and 7.0 < float(lines[9]) < 8.0
    assert int(lines[5]) == int(ISS_PASS.los.timestamp())  # during the pass the next event is LOS
    assert ask(client, address, "GET_SAT 25544") == reply
    assert ask(client, address, "GET_SAT NOSUCHSAT") == "Huh?\n"


def test_doppler_tle_list_qth_time_version_mode_reload(predict) -> None:
    client, address, clock, reloads = predict
    doppler = ask(client, address, "GET_DOPPLER 25544")
    la = LookAngleCalculator(OBSERVER).compute(CATALOG.get(ISS).satrec, clock.now())
    assert re.fullmatch(r"-?\d+\.\d{6}\n", doppler)
    assert float(doppler) == pytest.approx(-100e6 * la.range_rate_km_s / C, abs=1e-6)
    sat = CATALOG.get(ISS)
    assert ask(client, address, "GET_TLE ISS (ZARYA)") == f"ISS (ZARYA)\n{sat.elements.line1}\n{sat.elements.line2}\n"
    listing = ask(client, address, "GET_LIST")
    assert listing.split("\n")[:2] == ["ISS (ZARYA)", "SAUDISAT 1C (SO-50)"] or listing.count("\n") == 24
    assert listing.count("\n") == 24
    assert ask(client, address, "GET_QTH") == "G0XYZ\n52.2053\n359.878\n20\n"
    assert ask(client, address, "GET_TIME") == f"{int(clock.now().timestamp())}\n"
    assert re.fullmatch(r"\w{3} \w{3} \d\d \d\d:\d\d:\d\d \d{4}\n", ask(client, address, "GET_TIME$"))
    assert re.fullmatch(r"\S+\n", ask(client, address, "GET_VERSION"))
    assert ask(client, address, "GET_MODE") == "ISS\n"
    client.sendto(b"RELOAD_TLE", address)
    assert client.recvfrom(100)[0] == b"" and reloads == ["x"]
    for junk in (b"HELLO", b"\xff\xfe\x00garbage", b"get_sat iss", b""):
        assert ask(client, address, junk) == "Huh?\n"


def test_sun_and_moon_against_skyfield(predict) -> None:
    from skyfield_data import get_skyfield_data_path

    client, address, clock, _ = predict
    eph = load.__class__(get_skyfield_data_path())("de421.bsp")
    for hours in (0, 7, 13):
        clock.set(ISS_PASS.tca + timedelta(hours=hours))
        t = TS.from_datetime(clock.now())
        here = eph["earth"] + skyfield_topos(OBSERVER)
        for command, body, tolerance in (("GET_SUN", "sun", 0.05), ("GET_MOON", "moon", 0.5)):
            lines = ask(client, address, command).split("\n")
            assert len(lines) == 6 and re.fullmatch(F72, lines[0]) and re.fullmatch(SF62, lines[1])
            alt, az, _ = here.at(t).observe(eph[body]).apparent().altaz()
            horizontal = abs(math.cos(math.radians(alt.degrees)))  # azimuth error scales with 1/cos(el)
            assert abs((float(lines[0]) - az.degrees + 180) % 360 - 180) * horizontal < tolerance
            assert abs(float(lines[1]) - alt.degrees) < tolerance
