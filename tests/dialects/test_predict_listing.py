"""PREDICT's ``GET_SAT_POS`` and ``PREDICT`` over real loopback UDP, against predict.c and skyfield.

predict.c's server runs ``predict -f``/``-p`` and sends the output file line by line (``fgets(buff,80,fd)``),
after appending ``fprintf(fd,"%c\\n",26)``; each line is printed by QuickFind/QuickPredict with
``"%ld %s %4d %4d %4d %4d %4d %6ld %6ld %c\\n"`` (time, Daynum2String, iel, iaz, ma256, isplat, isplong, irk,
rv, findsun).  Expected lines are rebuilt here with that printf format from skyfield's values.
"""

from __future__ import annotations

import math
import re
import time
from datetime import datetime, timedelta, timezone

import pytest
from skyfield.api import load, wgs84

from nfwserver.clock import VirtualClock
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER
from tests.dialects.predict_client import END, predict_peer
from tests.tracking.skyfield_oracle import TS, skyfield_satellite, skyfield_topos

PRINTF = "%ld %s %4d %4d %4d %4d %4d %6ld %6ld %c\n".replace("%ld", "%d").replace("%6ld", "%6d")
LINE = re.compile(r"(\d+) (\w{3} \d\d\w{3}\d\d \d\d:\d\d:\d\d) ([ \d-]{4}) ([ \d-]{4}) ([ \d-]{4}) ([ \d-]{4}) "
                  r"([ \d-]{4}) ([ \d-]{6}) ([ \d-]{6}) ([+* ])\n")
ELEMENTS = CATALOG.get(ISS).elements
SAT = skyfield_satellite(ELEMENTS)
TOPOS = skyfield_topos(OBSERVER)


@pytest.fixture(scope="module")
def eph():
    from skyfield_data import get_skyfield_data_path

    return load.__class__(get_skyfield_data_path())("de421.bsp")


def daynum2string(unix: int) -> str:
    """predict.c's Daynum2String for daynum = unix/86400.0 - 3651.0, from C's asctime(gmtime(&t))."""
    t = int(86400.0 * ((unix / 86400.0 - 3651.0) + 3651.0))
    s = time.asctime(time.gmtime(t))
    s = s[:8] + "0" + s[9:] if s[8] == " " else s
    return s[0:4] + s[8:10] + s[4:7] + s[22:24] + " " + s[11:19]


def parse(datagram: bytes) -> list:
    match = LINE.fullmatch(datagram.decode("ascii"))
    assert match, datagram
    return [int(match[1]), match[2], *(int(g) for g in match.groups()[2:9]), match[10]]


def check_against_skyfield(datagram: bytes, eph, rounded_time: bool = False) -> list:
    """One -f/-p line: layout byte for byte and every value against skyfield (or the elements for phase/orbit)."""
    fields = parse(datagram)
    unix, _, el, az, phase, lat, lon_w, rng, orbit, light = fields
    assert datagram.decode() == PRINTF % tuple(fields)
    assert fields[1] == daynum2string(unix) or rounded_time
    when = datetime.fromtimestamp(unix, tz=timezone.utc)
    t = TS.from_datetime(when)
    alt, azi, dist = (SAT - TOPOS).at(t).altaz()
    slack = 0.5 + (0.6 if rounded_time else 0.02)  # rint, plus the second PREDICT's %.0f floor drops
    assert abs(el - alt.degrees) <= slack
    assert abs((az - azi.degrees + 180) % 360 - 180) <= slack / max(math.cos(alt.radians), 0.05)
    assert abs(rng - dist.km) <= 0.5 + (8.0 if rounded_time else 0.3)
    geo = SAT.at(t)
    sub = wgs84.latlon_of(geo)
    assert abs(lat - sub[0].degrees) <= slack and abs((lon_w - (360.0 - sub[1].degrees % 360.0) + 180) % 360 - 180) \
        <= slack
    age = (when - ELEMENTS.epoch).total_seconds() / 86400.0
    turns = ELEMENTS.mean_anomaly_deg / 360.0 + ELEMENTS.mean_motion_rev_per_day * age \
        + float(ELEMENTS.line1[33:43]) * age * age
    assert abs((phase - 256.0 * (turns % 1.0) + 128) % 256 - 128) <= 1.0 + (0.2 if rounded_time else 0.0)
    assert orbit - (ELEMENTS.rev_number + math.floor(turns)) in ((0,) if 0.01 < turns % 1.0 < 0.99 else (-1, 0, 1))
    sunlit = bool(geo.is_sunlit(eph))
    sun_el = (eph["earth"] + TOPOS).at(t).observe(eph["sun"]).apparent().altaz()[0].degrees
    if not sunlit:
        assert light == " "
    elif abs(sun_el + 12.0) > 0.3 and abs(alt.degrees + 0.5) > 0.3:
        assert light == ("+" if sun_el <= -12.0 and round(alt.degrees) >= 0 else "*")
    return fields


@pytest.fixture
def predict():
    with predict_peer(clock=VirtualClock(ISS_PASS.aos - timedelta(minutes=30))) as peer:
        yield peer


def test_get_sat_pos_one_position_at_start(predict, eph) -> None:
    start = int(ISS_PASS.tca.timestamp())
    reply = predict.ask_listing(f"GET_SAT_POS 25544 {start}")
    assert len(reply) == 2 and reply[-1] == END
    fields = check_against_skyfield(reply[0], eph)
    assert fields[0] == start and fields[2] > 80
    assert predict.ask_listing(f'GET_SAT_POS "ISS (ZARYA)" {start}\n') == reply  # the shell's quotes
    assert predict.ask_listing(f"GET_SAT_POS ISS {start}\x00") == reply  # the DDE name
    now = predict.ask_listing("GET_SAT_POS 25544")  # start 0 means now
    assert parse(now[0])[0] == int(predict.clock.now().timestamp()) and now[1] == END


def test_get_sat_pos_lists_every_second_or_minute(predict, eph) -> None:
    start = int(ISS_PASS.aos.timestamp()) - 600
    reply = predict.ask_listing(f"GET_SAT_POS 25544 {start} +90m")
    assert reply[-1] == END and len(reply) == 92  # for (count=start; count<=end; count+=step), step=60
    times = [check_against_skyfield(d, eph)[0] for d in reply[:-1]]
    assert times == [start + 60 * k for k in range(91)]
    reply = predict.ask_listing(f"GET_SAT_POS 25544 {start} {start + 20}")
    assert [parse(d)[0] for d in reply[:-1]] == list(range(start, start + 21)) and reply[-1] == END
    now = int(predict.clock.now().timestamp())
    assert [parse(d)[0] for d in predict.ask_listing("GET_SAT_POS 25544 +10")[:-1]] == list(range(now, now + 11))
    assert [parse(d)[0] for d in predict.ask_listing("GET_SAT_POS 25544 +3m")[:-1]] == [now + 60 * k for k in range(4)]


def test_get_sat_pos_limits_as_predict_draws_them(predict) -> None:
    now = int(predict.clock.now().timestamp())
    # "if ((end-start)>86400) { start=now; end=now-1; }" for a + start:
    assert predict.ask_listing("GET_SAT_POS 25544 +1441m") == [END]
    assert len(predict.ask_listing("GET_SAT_POS 25544 +1440m")) == 1442
    # Our reading: the same 24-hour bound for an absolute end.
    assert predict.ask_listing(f"GET_SAT_POS 25544 {now} {now + 86401}") == [END]
    # "end=start+((long)step)*atol(endstr)" is computed before "if (start==0) start=now": 0 +5 lists nothing.
    assert predict.ask_listing("GET_SAT_POS 25544 0 +5") == [END]
    # A single position only "within one year" of now; further out it is the (empty) list from start to 0.
    assert predict.ask_listing(f"GET_SAT_POS 25544 {now + 31557601}") == [END]
    assert predict.ask_listing("GET_SAT_POS NOSUCHSAT 0") == [END]
    assert predict.ask_listing("GET_SAT_POS") == [END]
    # predict's option parser stops at an argument starting with '-': the start is then missing (now).
    assert parse(predict.ask_listing("GET_SAT_POS 25544 -5")[0])[0] == now


def test_predict_lists_the_next_pass_with_predicts_steps(predict, eph) -> None:
    start = int(predict.clock.now().timestamp())
    reply = predict.ask_listing(f"PREDICT 25544 {start}")
    assert reply[-1] == END and len(reply) > 8
    lines = [check_against_skyfield(d, eph, rounded_time=True) for d in reply[:-1]]
    t0 = TS.from_datetime(predict.clock.now())
    events_t, kinds = SAT.find_events(TOPOS, t0, TS.from_datetime(predict.clock.now() + timedelta(hours=2)), 0.0)
    rise = next(t for t, k in zip(events_t, kinds) if k == 0).utc_datetime().timestamp()
    setting = next(t for t, k in zip(events_t, kinds) if k == 2).utc_datetime().timestamp()
    assert abs(lines[0][0] - rise) < 3 and abs(lines[-1][0] - setting) < 3
    assert lines[0][2] == 0 and lines[-1][2] == 0 and all(line[2] >= 0 for line in lines)
    assert max(line[2] for line in lines) == pytest.approx(ISS_PASS.max_elevation_deg, abs=3.0)
    # daynum+=cos((sat_ele-1.0)*deg2rad)*sqrt(sat_alt)/25000.0 between lines inside the pass
    for before, after in zip(lines[:-2], lines[1:-1]):
        t = TS.from_datetime(datetime.fromtimestamp(before[0] + 0.5, tz=timezone.utc))
        el = (SAT - TOPOS).at(t).altaz()[0].degrees
        height = wgs84.height_of(SAT.at(t)).km
        step = math.cos(math.radians(el - 1.0)) * math.sqrt(height) / 25000.0 * 86400.0
        assert abs((after[0] - before[0]) - step) <= 2.0
    # From inside the pass, FindAOS steps back to the same AOS (to within its 0.03 degree).
    inside = [parse(d) for d in predict.ask_listing(f"PREDICT 25544 {int(ISS_PASS.tca.timestamp())}")[:-1]]
    assert abs(inside[0][0] - lines[0][0]) < 3 and abs(inside[-1][0] - lines[-1][0]) < 3
    assert predict.ask_listing("PREDICT NOSUCHSAT") == [END]


def test_listings_for_a_decayed_satellite_are_empty() -> None:
    with predict_peer(clock=VirtualClock(ELEMENTS.epoch + timedelta(days=3650))) as peer:
        assert peer.ask_listing("GET_SAT_POS 25544") == [END]
        assert peer.ask_listing("GET_SAT_POS 25544 +10m") == [END]
        assert peer.ask_listing("PREDICT 25544") == [END]


def test_a_long_listing_never_delays_get_sat(predict) -> None:
    import socket

    predict.send("GET_SAT_POS 25544 +86400")  # 86,401 lines: seconds of work on the listing thread
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as other:
        other.settimeout(5.0)
        for _ in range(5):
            began = time.monotonic()
            other.sendto(b"GET_SAT 25544", predict.address)
            assert other.recvfrom(1000)[0].startswith(b"ISS (ZARYA)\n")
            assert time.monotonic() - began < 0.5
    assert predict.client.recvfrom(100)[0] != END  # the listing is still streaming
