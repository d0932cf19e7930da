"""The console on a small terminal, its times, pass table and realtime values (Textual pilot).

Realtime values are checked against skyfield (an independent SGP4 + topocentric implementation)
and hand formulas: Doppler = -f * range_rate / c at the satellite's own channel, free-space path
loss = 20 log10(4 pi d f / c), and the Maidenhead locator of skyfield's sub-satellite point.
"""

from __future__ import annotations

import asyncio
import math
import re
from datetime import timedelta
from zoneinfo import ZoneInfo

from skyfield.api import EarthSatellite, load, wgs84

from nfwserver.channels.channel import Channel
from nfwserver.console.app import NfwConsole
from tests.app.console_helpers import log_text, off_screen, screen_text, searched, settle, static_text
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER, dead_iss_text, make_station

LONG_HINT = ("no observer configured: using 0.000000,0.000000 (Greenwich). Set [observer] location in "
             "/home/someone/.config/nfwserver/config.toml (`nfwserver config init` writes a starting file).")
C_KM_S = 299792.458


def test_80x24_notes_wrap_footer_shows_ctrl_d_and_every_pane_is_there() -> None:
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=5))

    async def scenario() -> None:
        app = NfwConsole(station.core, "serving on the in-process transport, for clients in this process only",
                         LONG_HINT, favourites=(ISS,), clients=station.nova.client_count)
        async with app.run_test(size=(80, 24)) as pilot:
            # the footer is drawn after the panes: under load a first read can find its row still blank
            await settle(app, pilot, until=lambda: "^d Doppler" in screen_text(app).splitlines()[-1],
                         what="Ctrl+D in the footer")
            screen = screen_text(app)
            rows = screen.splitlines()
            assert len(rows) == 24 and not off_screen(app), off_screen(app)
            assert "^d Doppler" in rows[-1]  # Ctrl+D in the footer from the start
            assert "Satellite ISS (25544)" in screen and "Passes (UTC)" in screen
            assert "Satellite Date  AOS   Max LOS" in screen
            # Every word of the long note is on screen, wrapped inside the pane (nothing cut at its edge).
            incoming = log_text(app, "incoming")
            width = app.query_one("#incoming").scrollable_content_region.width
            assert width < 60 and all(len(line) <= width for line in incoming.splitlines())
            expected = "note: serving on the in-process transport, for clients in this process only note: " + LONG_HINT
            assert "".join(incoming.split()).startswith("".join(expected.split()))  # long words are folded
            # F1 shows the outgoing pane instead of the incoming one on a narrow terminal.
            await pilot.press("f1")
            await pilot.pause()
            assert "F1 outgoing" in screen_text(app) and "F3 incoming" not in screen_text(app)

    asyncio.run(scenario())


def test_ctrl_d_without_a_radio_explains_itself() -> None:
    station = make_station()
    station.core.radio_configured = False  # as the station sets it from [radio]

    async def scenario() -> None:
        app = NfwConsole(station.core, config_file="/etc/nfw/station.toml")
        async with app.run_test(size=(120, 30)) as pilot:
            assert "Ctrl+D explains" in static_text(app, "state")
            await pilot.press("ctrl+d")
            await pilot.pause()
            assert station.core.state.doppler_on
            note = " ".join(log_text(app, "incoming").split())
            assert "no radio configured: nothing is tuned" in note
            assert 'backend = "rigctld"' in note and "/etc/nfw/station.toml" in note
            assert "tuning ON" in static_text(app, "state")

    asyncio.run(scenario())


def test_z_toggles_utc_and_local_time_with_the_zone_always_named() -> None:
    station = make_station(start=ISS_PASS.aos - timedelta(minutes=30))
    sydney = ZoneInfo("Australia/Sydney")

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS,), local_zone=sydney)
        async with app.run_test(size=(120, 36)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the pass search")
            now = station.clock.now()
            utc_aos = ISS_PASS.aos.strftime("%m-%d %H:%M")
            assert f"{now:%m-%d %H:%M:%S} UTC" in static_text(app, "state")
            assert utc_aos in static_text(app, "passes") and "Passes (UTC)" in screen_text(app)
            assert f"Next pass {ISS_PASS.aos:%m-%d} AOS {ISS_PASS.aos:%H:%M:%S}" in static_text(app, "state")
            await pilot.press("f4")
            await settle(app, pilot, until=lambda: "UTC" not in static_text(app, "state"))
            local, local_aos = now.astimezone(sydney), ISS_PASS.aos.astimezone(sydney)
            zone = local.tzname()
            assert zone == "AEST"
            assert f"{local:%m-%d %H:%M:%S} {zone}" in static_text(app, "state")
            assert local_aos.strftime("%m-%d %H:%M") in static_text(app, "passes")
            assert f"Passes ({zone})" in screen_text(app)
            # InstantTrack's Z, typed on the command line, and F4 toggle back and forth.
            await pilot.press("Z", "enter")
            await settle(app, pilot, until=lambda: f"{now:%m-%d %H:%M:%S} UTC" in static_text(app, "state"))
            assert f"{now:%m-%d %H:%M:%S} UTC" in static_text(app, "state")
            await pilot.press("f3", "f4")
            await settle(app, pilot, until=lambda: "UTC" not in static_text(app, "state"))
            assert zone in static_text(app, "state")

    asyncio.run(scenario())


def test_pass_table_has_headers_dates_and_marks_a_pass_in_progress() -> None:
    station = make_station(start=ISS_PASS.tca)

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS, 27607))
        async with app.run_test(size=(120, 36)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the pass search")
            table = static_text(app, "passes").splitlines()
            assert table[0].split() == ["Satellite", "Date", "AOS", "Max", "LOS"]
            first = table[1].split()
            assert first[:3] == ["ISS", ISS_PASS.aos.strftime("%m-%d"), ISS_PASS.aos.strftime("%H:%M")]
            assert first[3] == f"{ISS_PASS.max_elevation_deg:.0f}" and first[-1] == "*"  # in progress now
            assert all(re.match(r"^\S+\s+\d\d-\d\d \d\d:\d\d +\d+ \d\d:\d\d( \*)?$", row) for row in table[1:])

    asyncio.run(scenario())


def _locator(lat: float, lon: float) -> str:
    """Maidenhead, 6 characters, written from the definition (fields 20x10 deg, squares 2x1, subsquares 5'x2.5')."""
    lon, lat = lon + 180.0, lat + 90.0
    return (chr(65 + int(lon // 20)) + chr(65 + int(lat // 10)) + str(int(lon % 20 // 2)) + str(int(lat % 10))
            + chr(97 + int(lon % 2 * 12)) + chr(97 + int(lat % 1 * 24)))


def test_realtime_values_use_the_satellites_own_downlink_and_agree_with_skyfield() -> None:
    beacon = 437_800_000
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=40),
                           channels={ISS: Channel("test downlink", beacon)})

    async def scenario() -> None:
        app = NfwConsole(station.core, schedules={ISS: "000A128B"})
        async with app.run_test(size=(120, 36)) as pilot:
            await settle(app, pilot, until=lambda: all(
                word in static_text(app, "state") for word in ("Doppler", "path loss", "Sub-sat", "AH Y")))
            state = static_text(app, "state")
            now = station.clock.now()
        ts = load.timescale(builtin=True)
        sat = CATALOG.get(ISS)
        sky = EarthSatellite(sat.elements.line1, sat.elements.line2, "ISS", ts)
        t = ts.from_datetime(now)
        here = wgs84.latlon(OBSERVER.latitude_deg, OBSERVER.longitude_deg, OBSERVER.altitude_m)
        _, _, distance, _, _, range_rate = (sky - here).at(t).frame_latlon_and_rates(here)
        rr = range_rate.km_per_s
        doppler = -beacon * rr / C_KM_S
        shown = float(re.search(r"Doppler ([+-][\d,]+) Hz", state).group(1).replace(",", ""))
        assert abs(shown - doppler) < 15, (shown, doppler)  # 15 Hz at 437.8 MHz is 10 m/s
        assert "Downlink 437.8000 MHz (test downlink)" in state
        loss = 20 * math.log10(4 * math.pi * distance.km * beacon / C_KM_S)
        assert abs(float(re.search(r"path loss ([\d.]+) dB", state).group(1)) - loss) < 0.1
        point = wgs84.subpoint_of(sky.at(t))
        m = re.search(r"Sub-sat ([\d.]+)([NS]) ([\d.]+)([EW]) (\w{6})", state)
        lat = float(m.group(1)) * (1 if m.group(2) == "N" else -1)
        lon = float(m.group(3)) * (1 if m.group(4) == "E" else -1)
        assert abs(lat - point.latitude.degrees) < 0.02 and abs(lon - point.longitude.degrees) < 0.02
        assert m.group(5) == _locator(point.latitude.degrees, point.longitude.degrees)
        phase = int(re.search(r"phase (\d+)", state).group(1))
        assert f"mode {'A' if phase < 128 else 'B'}" in state
        assert re.search(r"orbit \d{5}", state) and re.search(r"\b(sunlit|eclipsed)\b", state)
        assert "AH Y" in state

    asyncio.run(scenario())


def test_the_pass_list_names_a_favourite_whose_position_cannot_be_computed() -> None:
    """A favourite SGP4 refuses now (decayed) is left out of the search and named under the list, instead of
    vanishing from it without a word."""
    from nfwserver.tracking.catalog import Catalog
    from nfwserver.tracking.elements import load_elements

    dead = load_elements(dead_iss_text()).sets[0]
    error = dead.satrec.sgp4(*_jd(ISS_PASS.tca))[0]
    assert error != 0  # the library's own verdict
    station = make_station(start=ISS_PASS.tca, catalog=Catalog([*(s.elements for s in CATALOG), dead]))

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS, 99901))
        async with app.run_test(size=(120, 36)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the pass search")
            table = static_text(app, "passes").splitlines()
            assert table[1].split()[0] == "ISS"
            assert table[-1] == "! left out, position cannot be computed now: DEAD"

    asyncio.run(scenario())


def _jd(when) -> tuple[float, float]:
    from sgp4.api import jday

    return jday(when.year, when.month, when.day, when.hour, when.minute, when.second + when.microsecond / 1e6)
