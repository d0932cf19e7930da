"""A request right after ``SAT=`` (or ``TUNE ON``) gets the new satellite's string, never "" (#34 item 5).

A client poked ``SAT=`` and then requested on a second conversation before the next tick: it got "" (README
documented it), which a client parses as garbage.  The in-process DDEML stands in for the real one; the
virtual clock is not advanced between the poke and the request, so no tick runs in between.  The string is
checked against skyfield at the clock's instant, as printed (one decimal, ten for the range rate).
"""

from __future__ import annotations

from datetime import timedelta

from tests.dde.conftest import CATALOG, ISS, ISS_PASS, NOVA, OBSERVER, make_station
from tests.tracking.skyfield_oracle import skyfield_look_angles


def _check_against_skyfield(text: str, catalog_number: int, when) -> None:
    sat = CATALOG.get(catalog_number)
    m = NOVA.match(text)
    assert m is not None, text
    assert m.group(1) == sat.dde_name
    az, el, _, rr, _ = skyfield_look_angles(sat.elements, OBSERVER, [when])
    assert abs((float(m.group(2)) - az[0] + 180.0) % 360.0 - 180.0) <= 0.05 + 1e-3
    assert abs(float(m.group(3)) - el[0]) <= 0.05 + 1e-3
    assert abs(float(m.group(4)) - rr[0]) <= 5e-11 + 1e-6
    assert m.group(5) == ("Y" if el[0] > 0 else "N")


def _station(start):
    """The station with skyfield's UT1-UTC for ``start``, so the oracle and the server share one time scale."""
    dut1 = float(skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, [start])[4][0])
    return make_station(start=start, ut1_utc=dut1)


def test_a_request_on_another_conversation_right_after_sat_gets_the_new_satellites_string() -> None:
    station = _station(ISS_PASS.tca)
    poker = station.system.connect("NFW32", "NFW_DATA", "poker")
    reader = station.system.connect("NFW_SERVER", "NFW_DATA", "reader")
    poker.poke("NFW_SERVER", "TUNE ON")
    station.run(1.0)
    assert reader.request_text("NFW_SERVER").startswith("ISS ")
    other = next(s.catalog_number for s in CATALOG if s.catalog_number != ISS)
    poker.poke("NFW_SERVER", f"SAT={other}")  # accepted (a refusal raises in the client)
    _check_against_skyfield(reader.request_text("NFW_SERVER"), other, station.clock.now())
    _check_against_skyfield(reader.request_text("NFW_DATA"), other, station.clock.now())


def test_a_request_right_after_tune_on_gets_the_string() -> None:
    station = _station(ISS_PASS.tca + timedelta(seconds=30))
    conv = station.system.connect("NFW32", "NFW_DATA")
    station.run(1.0)
    assert conv.request_text("NFW_SERVER") == ""  # before TUNE ON: empty, as Nova's feed is off
    conv.poke("NFW_SERVER", "TUNE ON")
    _check_against_skyfield(conv.request_text("NFW_SERVER"), ISS, station.clock.now())
    conv.poke("NFW_SERVER", "TUNE OFF")
    assert conv.request_text("NFW_SERVER") == ""
