"""PREDICT's UDP protocol over real loopback UDP: framing, reply formats byte for byte, values checked.

The expected forms come from PREDICT 2.2's ``socket_server`` in predict.c (KD2BD), quoted where used.
"""

from __future__ import annotations

import logging
import math
import re
import socket
from dataclasses import replace
from datetime import timedelta

import pytest
from skyfield.api import load

from nfwserver.clock import VirtualClock
from nfwserver.core.state import StationState
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.doppler import SPEED_OF_LIGHT_KM_S as C
from nfwserver.tracking.look_angles import LookAngleCalculator
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER
from tests.dialects.predict_client import END, predict_peer
from tests.tracking.skyfield_oracle import TS, skyfield_topos

F72 = r"-?\d+\.\d\d *"  # %-7.2f
SF62 = r"[+-]\d+\.\d\d *"  # %+-6.2f
# GET_SAT: sprintf(buff,"%s\n%-7.2f\n%+-6.2f\n%-7.2f\n%+-6.2f\n%ld\n%-7.2f\n%-7.2f\n%-7.2f\n%-7.2f\n%ld\n%c\n
#                        %-7.2f\n%-7.2f\n%-7.2f\n",...)
GET_SAT_FIELDS = [F72, SF62, F72, SF62, r"\d+", F72, F72, F72, F72, r"\d+", "[VDN]", F72, F72, F72]


@pytest.fixture
def predict():
    with predict_peer() as peer:
        yield peer


def test_get_sat_layout_and_values(predict) -> None:
    reply = predict.ask("GET_SAT ISS (ZARYA)")
    lines = reply.split("\n")
    assert reply.endswith("\n") and len(lines) == 16
    for line, expected in zip(lines, [r"ISS \(ZARYA\)", *GET_SAT_FIELDS]):
        assert re.fullmatch(expected, line), (line, expected)
    assert all(len(lines[i]) >= 7 for i in (1, 3, 6, 7, 8, 9)) and len(lines[2]) >= 6
    la = LookAngleCalculator(OBSERVER).compute(CATALOG.get(ISS).satrec, predict.clock.now())
    assert float(lines[3]) == pytest.approx(la.azimuth_deg, abs=0.006)
    assert float(lines[4]) == pytest.approx(la.elevation_deg, abs=0.006)
    assert float(lines[7]) == pytest.approx(la.range_km, abs=0.006)
    assert 350 < float(lines[8]) < 450 and 7.0 < float(lines[9]) < 8.0
    assert int(lines[5]) == int(ISS_PASS.los.timestamp())  # during the pass the next event is LOS
    assert predict.ask("GET_SAT 25544") == reply
    assert predict.ask("GET_SAT NOSUCHSAT") == "Huh?\n"


def test_doppler_tle_list_qth_time_version_reload(predict) -> None:
    doppler = predict.ask("GET_DOPPLER 25544")
    la = LookAngleCalculator(OBSERVER).compute(CATALOG.get(ISS).satrec, predict.clock.now())
    assert re.fullmatch(r"-?\d+\.\d{6}\n", doppler)  # sprintf(buff,"%f\n",doppler[i])
    assert float(doppler) == pytest.approx(-100e6 * la.range_rate_km_s / C, abs=1e-6)
    sat = CATALOG.get(ISS)
    assert predict.ask("GET_TLE ISS (ZARYA)") == f"ISS (ZARYA)\n{sat.elements.line1}\n{sat.elements.line2}\n"
    listing = predict.ask("GET_LIST")
    assert listing.split("\n")[:3] == ["ISS (ZARYA)", "ATLAS CENTAUR 2", ""] and listing.count("\n") == 24
    assert predict.ask("GET_QTH") == "G0XYZ\n52.2053\n359.878\n20\n"  # "%s\n%g\n%g\n%d\n"
    assert predict.ask("GET_TIME") == f"{int(predict.clock.now().timestamp())}\n"
    assert re.fullmatch(r"\w{3} \w{3} \d\d \d\d:\d\d:\d\d \d{4}\n", predict.ask("GET_TIME$"))
    assert re.fullmatch(r"\S+\n", predict.ask("GET_VERSION"))
    predict.send(b"RELOAD_TLE")
    assert predict.client.recvfrom(100)[0] == b"" and predict.reloads == ["x"]
    for junk in (b"HELLO", b"\xff\xfe\x00garbage", b"get_sat iss", b"", b"\x00GET_TIME"):
        assert predict.ask(junk) == "Huh?\n"


def test_terminators_nothing_nul_and_lf_are_equivalent_and_cr_stays_in_the_name(predict) -> None:
    # Spec: "commands arrive terminated by nothing, NUL or LF (all equivalent; a CR stays part of the name,
    # as in PREDICT)" -- predict.c copies the name up to buf[j]!='\n' && buf[j]!=0.
    bare = predict.ask("GET_TLE ISS (ZARYA)")
    for ending in (b"\x00", b"\n", b"\x00junk after the NUL", b"\nGET_TIME", b"\n\x00"):
        assert predict.ask(b"GET_TLE ISS (ZARYA)" + ending) == bare
        assert predict.ask(b"GET_SAT ISS (ZARYA)" + ending).split("\n")[0] == "ISS (ZARYA)"
    assert predict.ask(b"GET_TLE ISS (ZARYA)\r") == "Huh?\n"
    assert predict.ask(b"GET_TLE ISS (ZARYA)\r\n") == "Huh?\n"
    assert predict.ask(b"GET_TLE 25544\r\n") == bare  # atol("25544\r") is 25544
    assert predict.ask(b"GET_TIME" + b"x" * 3000) == f"{int(predict.clock.now().timestamp())}\n"


def test_commands_match_by_prefix_in_predicts_order(predict) -> None:
    # if ((strncmp("GET_SAT",buf,7)==0) && (strncmp("GET_SAT_POS",buf,11)!=0)) ... strncmp("GET_TIME$",buf,9)
    # ... buf[0]=0 ... strncmp("GET_TIME",buf,8): every test is a prefix test, in this order.
    assert predict.ask("GET_SATELLITE 25544").startswith("ISS (ZARYA)\n")
    assert predict.ask("GET_LISTS").count("\n") == 24
    assert predict.ask("GET_TIMEZONE") == f"{int(predict.clock.now().timestamp())}\n"
    assert re.fullmatch(r"\w{3} \w{3} \d\d \d\d:\d\d:\d\d \d{4}\n", predict.ask("GET_TIME$NOW"))
    assert predict.ask_listing("PREDICTABLE") == [END]  # PREDICT with the unknown satellite "" after no blank
    assert predict.ask("GET_MOONS").count("\n") == 5 and predict.ask("GET_SUNDAY").count("\n") == 5
    assert predict.ask("GET_QTHX").startswith("G0XYZ\n")
    assert predict.ask("GET") == "Huh?\n"


def test_replies_go_to_the_senders_address_and_port() -> None:
    with predict_peer() as peer, socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as other:
        other.bind(("127.0.0.1", 0))
        other.settimeout(5.0)
        other.sendto(b"GET_TLE 694", peer.address)
        peer.send("GET_TLE 25544")
        assert peer.client.recvfrom(1000) == (peer.ask("GET_TLE 25544").encode(), peer.address)
        reply, source = other.recvfrom(1000)
        assert reply.startswith(b"ATLAS CENTAUR 2\n") and source == peer.address


def test_get_mode_is_empty_before_any_tracking_then_the_name_then_none() -> None:
    # tracking_mode is a zeroed global until a tracking mode runs: sendto(sock,tracking_mode,strlen(...)) sends 0
    # bytes; single tracking sets sprintf(tracking_mode, "%s\n%c",sat[indx].name,0), leaving it "NONE\n%c".
    state = StationState(CATALOG, OBSERVER)
    with predict_peer(state) as peer:
        assert peer.ask("GET_MODE") == ""
        state.select(ISS)
        assert peer.ask("GET_MODE") == ""  # selected but neither published nor followed
        state.set_feed(True)
        assert peer.ask("GET_MODE") == "ISS (ZARYA)\n"
        state.set_feed(False)
        state.set_tracking(True)
        assert peer.ask("GET_MODE") == "ISS (ZARYA)\n"
        state.set_tracking(False)
        assert peer.ask("GET_MODE") == "NONE\n"


def test_names_with_control_characters_never_shift_fields() -> None:
    # Issue 18.14: "Control characters in satellite names ... shift PREDICT reply fields (GET_SAT 16 lines
    # instead of 15)". Names are cleaned at load; the formatting guards too.
    iss = CATALOG.get(ISS).elements
    hostile = Catalog([replace(iss, name="EVIL\nNAME\x1b[31m\r\x00X\u00e9")])
    with predict_peer(StationState(hostile, OBSERVER)) as peer:
        lines = peer.ask("GET_SAT 25544").split("\n")
        assert len(lines) == 16 and lines[0] == "EVIL?NAME?[31m??X?"
        for line, expected in zip(lines[1:], GET_SAT_FIELDS):
            assert re.fullmatch(expected, line), (line, expected)
        assert peer.ask("GET_TLE 25544").split("\n")[0] == "EVIL?NAME?[31m??X?"
        assert peer.ask("GET_LIST").split("\n")[0] == "EVIL?NAME?[31m??X?"
        peer.state.select(ISS)
        peer.state.set_feed(True)
        assert peer.ask("GET_MODE") == "EVIL?NAME?[31m??X?\n"


def test_get_doppler_on_a_satellite_that_cannot_be_propagated_answers_like_get_sat(caplog) -> None:
    # Issue 18.9: "1,000 requests -> 14,000 log lines. Answer like GET_SAT does."
    clock = VirtualClock(CATALOG.get(ISS).elements.epoch + timedelta(days=3650))  # SGP4: "has decayed"
    caplog.set_level(logging.DEBUG, logger="nfwserver")
    with predict_peer(clock=clock) as peer:
        assert peer.ask("GET_SAT 25544") == "Huh?\n"
        for _ in range(1000):
            assert peer.ask("GET_DOPPLER 25544") == "Huh?\n"
    records = [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert 1 <= len(records) <= 2 and all(r.exc_info is None for r in caplog.records)
    assert "25544" in records[0].getMessage()


def test_without_a_station_location_requests_get_huh_and_one_warning(caplog) -> None:
    with predict_peer(StationState(CATALOG, None)) as peer:
        for command in ("GET_SAT 25544", "GET_DOPPLER 25544", "GET_QTH", "GET_SUN", "GET_MOON") * 20:
            assert peer.ask(command) == "Huh?\n"
        assert peer.ask_listing("GET_SAT_POS 25544") == [END]
        assert peer.ask("GET_TLE 25544").startswith("ISS (ZARYA)\n")
    warnings = [r for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warnings) == 1 and "location" in warnings[0].getMessage()


def test_sun_and_moon_against_skyfield(predict) -> None:
    from skyfield_data import get_skyfield_data_path

    eph = load.__class__(get_skyfield_data_path())("de421.bsp")
    for hours in (0, 7, 13):
        predict.clock.set(ISS_PASS.tca + timedelta(hours=hours))
        t = TS.from_datetime(predict.clock.now())
        here = eph["earth"] + skyfield_topos(OBSERVER)
        for command, body, tolerance in (("GET_SUN", "sun", 0.05), ("GET_MOON", "moon", 0.5)):
            lines = predict.ask(command).split("\n")
            assert len(lines) == 6 and re.fullmatch(F72, lines[0]) and re.fullmatch(SF62, lines[1])
            alt, az, _ = here.at(t).observe(eph[body]).apparent().altaz()
            horizontal = abs(math.cos(math.radians(alt.degrees)))  # azimuth error scales with 1/cos(el)
            assert abs((float(lines[0]) - az.degrees + 180) % 360 - 180) * horizontal < tolerance
            assert abs(float(lines[1]) - alt.degrees) < tolerance
