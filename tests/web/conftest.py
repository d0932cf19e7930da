"""A real station with the web dashboard on a free loopback port, and a real headless Chromium.

The station runs on a :class:`~nfwserver.clock.VirtualClock` during an ISS pass over Cambridge (the
data of tests/dde); the browser is Debian's ``chromium`` driven by ``chromium-driver`` through selenium
(.ci/run installs both).  Pages are read with one script call per check, so every value compared comes
from the same frame.
"""

from __future__ import annotations

import json
import shutil
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path

import pytest

from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from tests.conftest import DATA
from tests.dde.conftest import ISS_PASS

TOKEN = "test-token-0123"
CHROMIUM = ("/usr/bin/chromium", "chromium")
CHROMEDRIVER = ("/usr/bin/chromedriver", "chromedriver")


def config_text(elements: Path = DATA / "visual.txt", *, control: bool = True, extra: str = "",
                favourites: str = "[25544, 694, 733, 877, 2802, 3230, 3597]") -> str:
    web = f'[web]\nenabled = true\nport = 0\ncontrol = {"true" if control else "false"}\n' \
          + (f'token = "{TOKEN}"\n' if control else "") + extra
    return ('[observer]\nlocation = "52.2053,0.1218,20"\n'
            f'[elements]\nfiles = ["{elements}"]\nuse_bundled = false\n'
            '[server]\nsatellite = 25544\ntune = true\nstate_file = "none"\n'
            f'[satellites]\nfavourites = {favourites}\n' + web)


@dataclass
class WebStation:
    station: Station
    clock: VirtualClock

    @property
    def url(self) -> str:
        assert self.station.web is not None
        return self.station.web.url

    def advance(self, seconds: float, step_s: float = 0.2) -> None:
        """Move the station's clock on; its threads (publisher, frames, passes) follow each step."""
        steps = round(seconds / step_s)
        for _ in range(steps):
            self.clock.advance(step_s)
            time.sleep(0.003)

    def get(self, path: str) -> dict:
        with urllib.request.urlopen(self.url + path.lstrip("/"), timeout=5) as reply:
            return json.load(reply)

    def post(self, body: object) -> tuple[int, dict]:
        request = urllib.request.Request(self.url + "api/command", data=json.dumps(body).encode(), method="POST",
                                         headers={"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=5) as reply:
                return reply.status, json.load(reply)
        except urllib.error.HTTPError as exc:
            return exc.code, json.load(exc)


def start_station(text: str, start: datetime | None = None) -> WebStation:
    clock = VirtualClock(start or ISS_PASS.aos + timedelta(seconds=200))
    station = Station(parse_config(text), clock, transport=FakeDdeSystem().server_transport())
    station.start()
    web = WebStation(station, clock)
    web.advance(1.0)
    return web


@pytest.fixture
def web_station() -> Iterator[WebStation]:
    web = start_station(config_text())
    try:
        yield web
    finally:
        web.station.stop()


def _which(candidates: tuple[str, ...]) -> str | None:
    for name in candidates:
        found = shutil.which(name)
        if found:
            return found
    return None


def make_browser(width: int = 1280, height: int = 900, extra_args: tuple[str, ...] = ()):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    binary, driver = _which(CHROMIUM), _which(CHROMEDRIVER)
    if binary is None or driver is None:
        pytest.fail("the web tests need Debian's chromium and chromium-driver (apt-get install chromium "
                    "chromium-driver; .ci/run installs them)")
    options = webdriver.ChromeOptions()
    options.binary_location = binary
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--no-first-run", "--disable-extensions", f"--window-size={width},{height}", *extra_args):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    browser = webdriver.Chrome(options=options, service=Service(driver))
    browser.set_page_load_timeout(20)
    return browser


@pytest.fixture(scope="module")
def browser():
    driver = make_browser()
    try:
        yield driver
    finally:
        driver.quit()


READ_PAGE = """
const t = id => { const el = document.querySelector(`[data-testid="${id}"]`); return el ? el.textContent : null; };
const sat = document.querySelector('[data-testid="sat-marker"]');
return {frames: Number(document.body.dataset.frames || 0), connection: t("connection"), nova: t("nova-string"),
        az: t("az"), el: t("el"), rr: t("rr"), range: t("range"), ah: t("ah"), name: t("sat-name"),
        number: t("sat-number"), full: t("sat-full"), tune: t("tune-state"), track: t("track-state"),
        status: t("status-word"), countdown: t("countdown"), countdown_label: t("countdown-label"),
        marker: sat ? {cx: sat.getAttribute("cx"), cy: sat.getAttribute("cy"), az: sat.getAttribute("data-az"),
                       el: sat.getAttribute("data-el"), hidden: sat.classList.contains("hidden")} : null};
"""


def read_page(browser) -> dict:
    return browser.execute_script(READ_PAGE)


def wait_for(predicate, timeout_s: float = 15.0, what: str = "condition"):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def open_page(browser, web: WebStation) -> dict:
    browser.get_log("browser")  # forget what an earlier page logged
    browser.get(web.url)
    return wait_for(lambda: (page := read_page(browser))["frames"] > 0 and page["connection"] == "live" and page,
                    what="the first frame")


def console_errors(browser) -> list[dict]:
    return [entry for entry in browser.get_log("browser") if entry.get("level") == "SEVERE"]
