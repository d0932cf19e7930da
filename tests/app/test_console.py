"""The Textual console, driven by Textual's test pilot: assertions on what is on screen."""

from __future__ import annotations

import asyncio
from datetime import timedelta

from textual.widgets import RichLog, Static

from nfwserver.console.app import NfwConsole
from tests.dde.conftest import ISS_PASS, make_station


def _log_text(app: NfwConsole, pane: str) -> str:
    log = app.query_one(f"#{pane}", RichLog)
    return "\n".join(strip.text for strip in log.lines)


def _state(app: NfwConsole) -> str:
    return str(app.query_one("#state", Static).render())


def test_pokes_outgoing_strings_and_state_changes_show() -> None:
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=5))

    async def scenario() -> None:
        app = NfwConsole(station.core, "fake transport note", "set your observer", favourites=(25544,),
                         clients=station.nova.client_count)
        async with app.run_test(size=(140, 40)) as pilot:
            await pilot.press(*"TUNE ON", "enter")
            await pilot.pause()
            assert "TUNE ON ok" in _log_text(app, "incoming")
            assert "TUNE ON" in _state(app)
            station.run(2.0)  # 11 ticks at 5 Hz of virtual time
            await pilot.pause(0.3)
            outgoing = _log_text(app, "outgoing").splitlines()
            assert len(outgoing) == 11 and all(" ISS AZ:" in line for line in outgoing)
            assert "AZ " in _state(app) and "ISS (25544)" in _state(app)
            await pilot.press(*"SAT=99999", "enter")
            await pilot.pause()
            assert "SAT=99999 REFUSED" in _log_text(app, "incoming")
            await pilot.press(*"TUNE OFF", "enter")
            await pilot.pause(0.3)
            assert "TUNE OFF" in _state(app)
            station.run(1.0)
            await pilot.pause(0.3)
            assert len(_log_text(app, "outgoing").splitlines()) == 11  # nothing new after TUNE OFF
            client = station.system.connect("NFW32", "NFW_DATA")
            client.poke("NFW_SERVER", "TRACK ON")
            await pilot.pause(0.3)
            assert "[conv 1 NFW32/NFW_DATA] TRACK ON ok" in _log_text(app, "incoming")
            assert "TRACK ON" in _state(app)
            assert "next pass" in _state(app)
            assert "note: set your observer" in _log_text(app, "incoming")
            sky = str(app.query_one("#sky", Static).render())
            assert "N" in sky and "@" in sky and "." in sky  # the pass track and the satellite now
            assert "ISS" in str(app.query_one("#passes", Static).render())
            # The satellite picker (F2) switches the AutoTracking satellite.
            await pilot.press("f2")
            await pilot.pause()
            await pilot.press("down", "enter")
            await pilot.pause(0.3)
            picked = station.core.snapshot()
            assert picked.catalog_number != 25544 and f"({picked.catalog_number})" in _state(app)
            assert f"SAT={picked.catalog_number} ok" in _log_text(app, "incoming")

    asyncio.run(scenario())
