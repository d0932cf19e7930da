"""The console with the whole catalog as favourites: the pass list searches on a worker thread while keys
are handled (Textual's pilot; keys are posted directly, since the pilot's own presses wait for the whole
process to go idle, which it does not while a search runs)."""

from __future__ import annotations

import asyncio
import math
from datetime import timedelta

from sgp4.api import jday
from textual import events
from textual.widgets import Input
from textual.worker import WorkerState

from nfwserver.console.app import NfwConsole
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from tests.app.console_helpers import settle, spin_until, static_text
from tests.conftest import DATA
from tests.dde.conftest import ISS_PASS, make_station


def test_a_whole_catalog_pass_list_leaves_the_keys_working() -> None:
    catalog = Catalog(load_element_file(DATA / "active.txt").sets)
    station = make_station(start=ISS_PASS.aos - timedelta(minutes=30), catalog=catalog)
    everything = tuple(s.catalog_number for s in catalog.element_sets())

    def searching(app: NfwConsole) -> bool:
        return any(w.group == "passes" and w.state == WorkerState.RUNNING for w in app.workers)

    async def scenario() -> None:
        app = NfwConsole(station.core, favourites=everything)
        async with app.run_test(size=(140, 40)) as pilot:
            typed = app.query_one(Input)
            await spin_until(lambda: searching(app), 5.0, "the whole catalog's pass search")
            handled_while_searching = 0
            for key in "TUNE ON":
                before = typed.value
                app.post_message(events.Key(key.lower() if key == " " else key, key))
                for _ in range(500):
                    if typed.value != before:
                        break
                    await asyncio.sleep(0.002)
                if searching(app):  # the key is handled and the search still runs
                    handled_while_searching += 1
            assert typed.value == "TUNE ON"
            assert handled_while_searching >= 3  # the keys did not wait for the search
            await settle(app, pilot, until=lambda: "searching" not in static_text(app, "passes"), limit_s=60.0)
            table = static_text(app, "passes").splitlines()
            assert table[0].startswith("Satellite") and len(table) == 10  # the header, eight passes, and:
            # the catalog's sets SGP4 cannot compute now, judged by the sgp4 library itself (an error code, or a
            # position that is not finite or over 1.5 million km from the Earth's centre)
            now = station.clock.now()
            jd, fr = jday(now.year, now.month, now.day, now.hour, now.minute, now.second + now.microsecond / 1e6)

            def computable(satrec) -> bool:
                error, r, _ = satrec.sgp4(jd, fr)
                return error == 0 and all(math.isfinite(x) for x in r) and math.dist(r, (0, 0, 0)) <= 1.5e6

            unusable = [es.catalog_number for es in catalog.element_sets() if not computable(es.transient_satrec())]
            assert unusable
            names = ", ".join(catalog.dde_names_of(sorted(unusable)[:5])) + (", ..." if len(unusable) > 5 else "")
            assert table[-1] == f"! left out, position cannot be computed now: {names}"

    asyncio.run(scenario())
