"""The console's input line goes through the command table too (issue 24): HELP lists what it takes (in a screen
of its own, #34 item 15),
FLIP without a rotor says so, SAT= by a unique name works, TRACK ON without a rotor warns."""

from __future__ import annotations

import asyncio

from nfwserver.commands.help_text import help_lines
from nfwserver.commands.table import Face
from nfwserver.console.app import NfwConsole
from nfwserver.console.help_screen import HelpScreen
from tests.app.console_helpers import log_text, screen_text, searched, settle
from tests.dde.conftest import ISS, make_station


def test_console_help_flip_name_and_track_warning() -> None:
    station = make_station()
    station.core.rotor_configured = False

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=(ISS,))
        async with app.run_test(size=(120, 40)) as pilot:
            await settle(app, pilot, until=lambda: searched(app), what="the first pass search")
            await pilot.press(*"help", "enter")
            await settle(app, pilot, until=lambda: isinstance(app.screen, HelpScreen) and "PARK" in screen_text(app))
            on_screen = " ".join(screen_text(app).replace("│", " ").split())
            for line in help_lines(Face.CONSOLE):
                assert " ".join(line.split()) in on_screen
            await pilot.press("escape")
            await settle(app, pilot, until=lambda: not isinstance(app.screen, HelpScreen))
            for text in ("flip on", "SAT=oao 2", "TRACK ON"):
                shown = len(log_text(app, "incoming").splitlines())
                await pilot.press(*text, "enter")
                await settle(app, pilot, until=lambda shown=shown: len(log_text(app, "incoming").splitlines()) > shown)
            shown = " ".join(log_text(app, "incoming").split())
            assert "no rotor is configured" in shown
            assert "warning: TRACK ON with no rotor configured" in shown
            assert station.core.state.catalog_number == 3597

    asyncio.run(scenario())
