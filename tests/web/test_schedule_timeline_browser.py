"""The dashboard's autotrack timeline (issue 43, item 6) in real Chromium: every candidate pass of the next 12 h
drawn from AOS to LOS in its satellite's lane, scheduled ones in their priority's colour, left-out ones grey with
their reason on hover.

The page is served by a real WebServer over a station core at 02:00 UTC on 2026-05-08 (JO02ae, the bundled
elements); its schedule is the one ``nfwserver schedule`` prints for that window, read here from the command's
CSV (an oracle independent of the page's feed) and handed to the server as the autotrack schedule.
"""

from __future__ import annotations

import csv
import io
from datetime import datetime, timedelta, timezone

import pytest
from selenium.webdriver.common.by import By

from nfwserver.autotrack import AutotrackSettings, plan_schedule
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.schema import WebConfig
from nfwserver.core.station_core import StationCore
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import parse_observer
from nfwserver.web import WebServer
from nfwserver.web.server import StationParts
from tests.conftest import ROOT
from tests.waiting import wait_for
from tests.web.conftest import console_errors

START = datetime(2026, 5, 8, 2, tzinfo=timezone.utc)
AMATEUR = ROOT / "nfwserver" / "data" / "amateur.txt"
SIX = ["ISS", "SO-50", "AO-91", "AO-7", "RS-44", "FO-29"]

READ_TIMELINE = """
const box = document.getElementById("timeline"), note = document.querySelector('[data-testid="schedule-note"]');
const span = box.querySelector(".tl-track").getBoundingClientRect();
return {note: note.offsetParent !== null,
        lanes: [...box.querySelectorAll(".tl-lane")].map(l => l.querySelector(".tl-name").textContent),
        bars: [...box.querySelectorAll(".tl-bar")].map(b => {
          const r = b.getBoundingClientRect();
          return {lane: b.closest(".tl-lane").dataset.catalogNumber, aos: b.dataset.aos, cls: b.className,
                  title: b.title, color: getComputedStyle(b).backgroundColor,
                  left: (r.left - span.left) / span.width, right: (r.right - span.left) / span.width};
        })};
"""


def _oracle_rows(capsys: pytest.CaptureFixture[str]) -> list[dict[str, str]]:
    sats = [arg for name in SIX for arg in ("--sat", name)]
    assert main(["schedule", "--elements", str(AMATEUR), "--observer", "JO02ae", "--start", START.isoformat(),
                 "--hours", "12", *sats, "--format", "csv"]) == 0
    return list(csv.DictReader(io.StringIO(capsys.readouterr().out)))


def test_the_timeline_shows_each_pass_scheduled_or_left_out(browser, capsys) -> None:
    rows = _oracle_rows(capsys)
    catalog = Catalog(load_element_file(AMATEUR).sets)
    observer = parse_observer("JO02ae")
    schedule = plan_schedule(catalog, observer, None, 0.0, AutotrackSettings(tuple(SIX)), START,
                             START + timedelta(hours=24))
    clock = VirtualClock(START)
    core = StationCore(catalog, observer, clock, satellite=25544, rate_hz=5.0)
    web = WebServer(core, WebConfig(enabled=True, port=0), StationParts(autotrack_schedule=lambda: schedule))
    web.start()
    try:
        def tick() -> bool:
            core.tick(clock.now())
            return web.board.version >= 1

        wait_for(tick, 20.0, "the first pass board")
        browser.get_log("browser")
        browser.get(web.url)
        page = wait_for(lambda: browser.execute_script("return document.querySelector('.tl-bar') !== null")
                        and browser.execute_script(READ_TIMELINE), what="the timeline")
    finally:
        web.stop()
    assert not page["note"]
    numbers = {r["catalog_number"]: r["name"] for r in rows}
    assert len(page["bars"]) == len(rows) > 5
    assert page["lanes"] == [n for n in ["ISS", "SO-50", "AO-91", "AO-7", "RS-44", "FO-29"]
                             if any(schedule.names[int(k)] == n for k in numbers)]
    colours_by_priority: dict[int, set[str]] = {}
    for row in rows:
        bar = next(b for b in page["bars"] if b["aos"] == row["aos_utc"] and b["lane"] == row["catalog_number"])
        aos, los = (datetime.fromisoformat(row[k].replace("Z", "+00:00")) for k in ("aos_utc", "los_utc"))
        assert bar["left"] == pytest.approx((aos - START) / timedelta(hours=12), abs=0.003)
        assert bar["right"] == pytest.approx(min(1.0, (los - START) / timedelta(hours=12)), abs=0.003)
        if row["scheduled"] == "Y":
            assert "scheduled" in bar["cls"] and "left-out" not in bar["cls"] and bar["title"].endswith(", scheduled")
            priority = SIX.index(next(n for n in SIX if schedule.names[int(row["catalog_number"])] == n))
            colours_by_priority.setdefault(priority, set()).add(bar["color"])
        else:
            assert "left-out" in bar["cls"] and bar["title"].endswith(": left out, " + row["reason"])
            assert row["reason"].startswith("overlaps ")
    assert all(len(c) == 1 for c in colours_by_priority.values())  # one colour per priority
    assert len({next(iter(c)) for c in colours_by_priority.values()}) == len(colours_by_priority)  # all different
    greys = {b["color"] for b in page["bars"] if "left-out" in b["cls"]}
    assert len(greys) == 1 and not greys & {next(iter(c)) for c in colours_by_priority.values()}
    assert console_errors(browser) == []


def test_no_schedule_no_timeline(web_station, browser) -> None:
    from tests.web.conftest import open_page

    open_page(browser, web_station)
    wait_for(lambda: web_station.get("/api/passes")["version"] >= 1, what="the first pass search")
    assert web_station.get("/api/passes")["schedule"] is None
    card = browser.find_element(By.CSS_SELECTOR, '[data-testid="schedule"]')
    note = card.find_element(By.CSS_SELECTOR, '[data-testid="schedule-note"]')
    assert wait_for(lambda: note.is_displayed(), what="the note") and not card.find_elements(By.CSS_SELECTOR, ".tl-bar")
    assert note.text.startswith("no autotrack schedule")
