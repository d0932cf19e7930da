"""The console at 80x24, judged by what is on the screen (#34 item 15).

At 80x24 the header's Downlink and Antenna/Radio lines wrapped, each Nova string in F1 took two rows, HELP
went to the 40-column F3 pane (cut at "list th"), the "!" on pass rows had no legend and stale elements were
not flagged in the top panel.  A real ``rigctld -m 1`` tunes; the simulated rotor follows.
"""

from __future__ import annotations

import asyncio
import re
from dataclasses import replace
from datetime import timedelta

import pytest

from nfwserver.app.devices import make_rotor
from nfwserver.channels.channel import Channel
from nfwserver.commands.help_text import help_lines
from nfwserver.commands.table import Face
from nfwserver.config.schema import RotorConfig
from nfwserver.console.app import NfwConsole
from nfwserver.console.state_view import realtime, realtime_lines, satellite_line
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.radio.defaults import DEFAULT_CHANNELS
from nfwserver.radio.rigctld_backend import RigctldBackend
from nfwserver.radio.tuning import DopplerTuner
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from tests.app.console_helpers import log_text, off_screen, screen_text, settle, static_text
from tests.conftest import DATA
from tests.dde.conftest import ISS, ISS_PASS, NOVA, make_station

pytestmark = pytest.mark.hamlib

STAMP = r"\d\d:\d\d:\d\d "


def _words(text: str) -> str:
    """``text``'s words in order, borders and padding left out."""
    return " ".join(text.replace("│", " ").split())


def _run(rigctld, scenario, stale_days: float = 10_000.0) -> None:
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=30), channels=DEFAULT_CHANNELS)
    station.core.set_feed(True)
    rotor = make_rotor(RotorConfig(backend="sim"), station.core, station.clock)
    station.core.rotor = rotor
    tuner = DopplerTuner(DEFAULT_CHANNELS[ISS], RigctldBackend(station.clock, port=rigctld.port))
    radio = RadioCoupling(tuner, station.core.state, station.clock)
    station.core.subscribe(radio.process)
    station.core.set_doppler(True)
    station.core.command("TRACK ON")
    station.run(1.0)
    assert radio.last_result is not None  # the radio is tuned: the Radio line shows RX and TX

    async def body() -> None:
        app = NfwConsole(station.core, favourites=(ISS,), rotor=rotor, radio=radio, stale_days=stale_days)
        async with app.run_test(size=(80, 24)) as pilot:
            await settle(app, pilot, until=lambda: "Next pass: searching" not in static_text(app, "state"))
            await scenario(app, pilot, station)

    try:
        asyncio.run(body())
    finally:
        tuner.backend.close()


def test_no_header_line_wraps_at_80x24(rigctld) -> None:
    async def scenario(app, pilot, station) -> None:
        state = app.query_one("#state")
        lines = static_text(app, "state").splitlines()
        assert any(line.startswith("Downlink 437.8") for line in lines), lines
        assert any("RX 437.8" in line and "TX 145.9" in line for line in lines), lines  # the tuned radio
        assert any(line.startswith("Rotor:") for line in lines), lines
        # One row per line: as many rows as lines, none longer than the pane.
        assert max(len(line) for line in lines) <= state.content_region.width, lines
        assert state.content_region.height == len(lines), (state.content_region, lines)
        assert not off_screen(app), off_screen(app)
        screen = screen_text(app)
        assert re.search(r"path loss \d+\.\d dB", screen) and "Status 0x" in screen  # whole on screen

    _run(rigctld, scenario)


def test_each_nova_string_is_one_row_in_f1_at_80x24(rigctld) -> None:
    async def scenario(app, pilot, station) -> None:
        await pilot.press("f1")
        station.run(1.0)
        await settle(app, pilot, until=lambda: "F1 outgoing" in screen_text(app)
                     and len(log_text(app, "outgoing").splitlines()) >= 3)
        assert not off_screen(app), off_screen(app)
        rows = [row for row in log_text(app, "outgoing").splitlines() if row.strip()]
        for row in rows:  # each row a whole string: stamp, then Nova's string as the spec gives it
            assert re.match(STAMP, row) and NOVA.match(row[9:].split(" -> ")[0]), rows
        shown = [row for row in screen_text(app).splitlines() if re.search(r"│" + STAMP, row)]
        assert len(shown) >= 3 and all("AH:" in row for row in shown), shown  # on screen: one row each

    _run(rigctld, scenario)


def test_help_is_readable_in_full_at_80x24_and_escape_closes_it(rigctld) -> None:
    async def scenario(app, pilot, station) -> None:
        await pilot.press(*"HELP", "enter")
        await settle(app, pilot, until=lambda: "ANTEL=" in screen_text(app))
        assert not off_screen(app), off_screen(app)
        screen = _words(screen_text(app))
        for line in help_lines(Face.CONSOLE):
            assert _words(line) in screen, (line, screen_text(app))
        await pilot.press("escape")
        await settle(app, pilot, until=lambda: "ANTEL=" not in screen_text(app))
        await pilot.press(*"TUNE OFF", "enter")  # the command line has the focus again
        await settle(app, pilot, until=lambda: not station.core.state.snapshot().feed_on)

    _run(rigctld, scenario)


def test_pass_marks_are_explained_and_stale_elements_flagged_at_the_top(rigctld) -> None:
    async def scenario(app, pilot, station) -> None:
        await settle(app, pilot, until=lambda: "ISS " in static_text(app, "passes"))
        screen = screen_text(app)
        assert not off_screen(app), off_screen(app)
        rows = [row for row in screen.splitlines() if re.search(r"│ ISS +\d\d-\d\d", row)]
        assert rows and "*" in rows[0] and "!" in rows[0], screen  # in progress, stale
        assert "* in progress" in screen and "! old elements" in screen, screen  # the legend, on screen
        state = static_text(app, "state")
        age = station.core.state.catalog.get(ISS).age_days(station.clock.now())
        assert f"Elements {age:.0f} days old (over 1)" in state, state  # the top panel says it

    _run(rigctld, scenario, stale_days=1.0)


def test_long_names_are_shortened_not_wrapped() -> None:
    # A 24-character satellite name and a 40-character channel name, the pane 76 columns wide: the names are
    # cut (with an ellipsis), and what follows them (TUNE/TRACK/clients, Doppler and path loss) stays whole.
    long_name = "INTERNATIONAL SPACE STAT"
    catalog = Catalog([replace(s, name=long_name) if s.catalog_number == ISS else s
                       for s in load_element_file(DATA / "visual.txt").sets])
    channel = Channel(name="a downlink channel with a forty-char name", downlink_hz=437_800_000.0)
    station = make_station(start=ISS_PASS.tca, channels={ISS: channel}, catalog=catalog)
    snap = station.core.snapshot()
    line = satellite_line(snap, station.core, (1, 1), 76).plain
    assert len(line) <= 76 and line.startswith("Satellite ISS (25544) INTERN") and "\u2026" in line, line
    assert line.endswith("TUNE OFF  TRACK OFF  clients 1 (1 advise)"), line
    values, why = realtime(station.core, ISS, station.clock.now())
    downlink = next(t.plain for t in realtime_lines(values, why, station.core, ISS, True, 76)
                    if t.plain.startswith("Downlink"))
    assert len(downlink) <= 76 and "(a downlink" in downlink and "\u2026)" in downlink, downlink
    assert re.search(r"\) Doppler [+-][\d,]+ Hz  path loss \d+\.\d dB$", downlink), downlink
