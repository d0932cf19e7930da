"""The console on an 80x24 terminal, resized, keyboard only (issue 25 item 5)."""

from __future__ import annotations

import asyncio

from textual.widgets import Input

from nfwserver.console.app import NfwConsole
from tests.app.console_helpers import log_text, off_screen, screen_text, searched, settle, static_text
from tests.dde.conftest import ISS, make_station


def _run(scenario) -> None:
    station = make_station()
    station.core.set_feed(True)
    station.run(1.0)

    async def body() -> None:
        app = NfwConsole(station.core, favourites=(ISS,))
        async with app.run_test(size=(80, 24)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the first pass search")
            await scenario(app, pilot, station)

    asyncio.run(body())


def test_typed_commands_still_reach_the_station_after_f1_and_f3() -> None:
    async def scenario(app, pilot, station) -> None:
        await pilot.press("f1")
        await pilot.press(*"TUNE OFF", "enter")
        await settle(app, pilot, until=lambda: not station.core.state.snapshot().feed_on)
        assert not station.core.state.snapshot().feed_on
        await pilot.press("f3")
        await pilot.press(*"TUNE ON", "enter")
        await settle(app, pilot, until=lambda: station.core.state.snapshot().feed_on)
        assert station.core.state.snapshot().feed_on
        assert isinstance(app.focused, Input)

    _run(scenario)


def test_the_outgoing_pane_shows_whole_nova_strings_one_row_each() -> None:
    async def scenario(app, pilot, station) -> None:
        station.run(1.0)
        await pilot.press("f1")
        nova = station.core.current_text()
        # The pane's title, and its log drawn with the string published (the title can come first).
        await settle(app, pilot, until=lambda: "F1 outgoing" in screen_text(app) and nova in screen_text(app),
                     what="the outgoing pane with the published string")
        assert not off_screen(app), off_screen(app)
        pane = app.query_one("#outgoing")
        width = pane.scrollable_content_region.width
        rows = log_text(app, "outgoing").splitlines()
        assert rows and all(len(row) <= width for row in rows)  # inside the pane
        assert any(row.endswith(nova) for row in rows), rows  # whole, on one row
        assert nova in screen_text(app)  # and on screen, not cut at the pane's edge

    _run(scenario)


def test_page_keys_scroll_the_shown_log_while_typing_stays_possible() -> None:
    async def scenario(app, pilot, station) -> None:
        for k in range(60):
            station.core.command(f"ANTAZ={k}", source="test")
        await pilot.press("f3")
        incoming = app.query_one("#incoming")
        await settle(app, pilot, until=lambda: "ANTAZ=59" in log_text(app, "incoming") and incoming.max_scroll_y > 0
                     and incoming.scroll_y == incoming.max_scroll_y, what="the 60th command, scrolled to")
        bottom = incoming.scroll_y
        assert bottom > 0
        await pilot.press("pageup")
        await settle(app, pilot, until=lambda: incoming.scroll_y < bottom)
        assert incoming.scroll_y < bottom
        await pilot.press("pagedown", "pagedown")
        await settle(app, pilot, until=lambda: incoming.scroll_y == bottom)
        assert incoming.scroll_y == bottom
        assert isinstance(app.focused, Input)

    _run(scenario)


def test_the_footer_shows_every_key_at_80_columns() -> None:
    async def scenario(app, pilot, station) -> None:
        # under load the first frame can come before the footer is drawn: wait for it (not for its contents)
        await settle(app, pilot, until=lambda: screen_text(app).splitlines()[-1].strip() != "")
        footer = screen_text(app).splitlines()[-1]
        for label in ("Out", "Sats", "In", "Zone", "Tune", "Doppler", "Flip", "Quit"):
            assert label in footer, footer

    _run(scenario)


def _fitted(app) -> bool:
    """The state pane has been redrawn for its present width: one row per line, as wide as the pane at most."""
    state = app.query_one("#state")
    lines = static_text(app, "state").splitlines()
    return (bool(lines) and max(len(line) for line in lines) <= state.content_region.width
            and state.content_region.height == len(lines))


def test_the_header_fits_again_when_the_terminal_is_resized() -> None:
    async def scenario(app, pilot, station) -> None:
        await pilot.resize_terminal(140, 40)
        await settle(app, pilot, until=lambda: app.query_one("#state").size.width > 100 and _fitted(app),
                     what="the header refitted to 140 columns")
        assert not off_screen(app), off_screen(app)
        state = app.query_one("#state")
        # Fitted to the new width: one row per line, none longer than the pane.
        lines = static_text(app, "state").splitlines()
        assert max(len(line) for line in lines) <= state.content_region.width
        assert state.content_region.height == len(lines), (state.content_region, lines)
        await pilot.resize_terminal(80, 24)
        await settle(app, pilot, until=lambda: app.query_one("#state").size.width < 100 and _fitted(app),
                     what="the header refitted to 80 columns")
        lines = static_text(app, "state").splitlines()
        assert max(len(line) for line in lines) <= state.content_region.width, lines
        assert state.content_region.height == len(lines), (state.content_region, lines)

    _run(scenario)
