"""The Textual console, driven by Textual's test pilot: assertions on what is on screen."""

from __future__ import annotations

import asyncio
from datetime import timedelta

from nfwserver.console.app import NfwConsole
from tests.app.console_helpers import log_text, searched, settle, static_text
from tests.dde.conftest import ISS_PASS, make_station


def test_pokes_outgoing_strings_and_state_changes_show() -> None:
    station = make_station(start=ISS_PASS.tca - timedelta(seconds=5))

    async def scenario() -> None:
        app = NfwConsole(station.core, "fake transport note", "set your observer", favourites=(25544,),
                         clients=station.nova.client_count)
        async with app.run_test(size=(140, 40)) as pilot:
            await pilot.press(*"TUNE ON", "enter")
            await pilot.pause()
            assert "TUNE ON ok" in log_text(app, "incoming")
            assert "TUNE ON" in static_text(app, "state")
            station.run(2.0)  # 11 ticks at 5 Hz of virtual time
            await settle(app, pilot, until=lambda: sum(" ISS AZ:" in line for line in log_text(app, "outgoing")
                                                       .splitlines()) >= 11 and "AZ " in static_text(app, "state"))
            outgoing = [line for line in log_text(app, "outgoing").splitlines() if " ISS AZ:" in line]
            assert len(outgoing) == 11  # one per tick (each may wrap onto a second line in the pane)
            assert "AZ " in static_text(app, "state") and "ISS (25544)" in static_text(app, "state")
            await pilot.press(*"SAT=99999", "enter")
            await pilot.pause()
            assert "SAT=99999 REFUSED" in log_text(app, "incoming")
            await pilot.press(*"TUNE OFF", "enter")
            await settle(app, pilot, until=lambda: "TUNE OFF" in static_text(app, "state"))
            assert "TUNE OFF" in static_text(app, "state")
            shown = static_text(app, "state")
            station.run(1.0)
            await settle(app, pilot, until=lambda: static_text(app, "state") != shown)  # the second drawn
            assert sum(" ISS AZ:" in line for line in log_text(app, "outgoing").splitlines()) == 11  # none new
            client = station.system.connect("NFW32", "NFW_DATA")
            client.poke("NFW_SERVER", "TRACK ON")
            await settle(app, pilot, until=lambda: "TRACK ON ok" in log_text(app, "incoming")
                         and "clients 1" in static_text(app, "state") and "TRACK ON" in static_text(app, "state")
                         and searched(app), what="the DDE client's TRACK ON")
            assert "[conv 1 NFW32/NFW_DATA] TRACK ON ok" in log_text(app, "incoming")
            state = static_text(app, "state")
            assert "TRACK ON" in state and "clients 1 (0 advise)" in state
            assert "Pass in progress: max" in state  # the clock is 5 s before the pass's TCA
            assert "note: set your observer" in log_text(app, "incoming")
            sky = static_text(app, "sky")
            assert "N" in sky and "@" in sky and "." in sky  # the pass track and the satellite now
            assert "ISS" in static_text(app, "passes")
            # The satellite picker (F2) switches the AutoTracking satellite.
            await pilot.press("f2")
            await pilot.pause()
            await pilot.press("down", "enter")
            await settle(app, pilot, until=lambda: station.core.state.catalog_number != 25544
                         and "ok" in log_text(app, "incoming").splitlines()[-1])
            picked = station.core.snapshot()
            assert picked.catalog_number != 25544 and f"({picked.catalog_number})" in static_text(app, "state")
            assert f"SAT={picked.catalog_number} ok" in log_text(app, "incoming")

    asyncio.run(scenario())
