"""Issue 42 item 1 in a real headless Chromium: a page on another origin POSTs Nova commands to the TCP port.

The page is served from its own loopback port (another origin, :func:`tests.web.test_dashboard_hostile_pages
.hostile_site`); the browser is the web suite's (:func:`tests.web.conftest.make_browser`).  Before the fix the
header lines were refused one by one and the body's lines ran: the station then tracked SO-50."""

from __future__ import annotations

from tests.dde.conftest import ISS
from tests.tcp.conftest import SO_50, LineClient
from tests.waiting import wait_for
from tests.web.conftest import make_browser
from tests.web.test_dashboard_hostile_pages import hostile_site

PAGE = """<!doctype html><title>waiting</title><script>
fetch("http://127.0.0.1:%(port)d/", {method: "POST", mode: "no-cors", body: "\\r\\nSAT=%(sat)d\\r\\nTRACK ON\\r\\n"})
  .then(r => { window.outcome = "answered " + r.type; }, e => { window.outcome = "failed"; })
  .finally(() => { document.title = "done"; });
</script>"""


def test_a_page_on_another_origin_cannot_steer_the_station_through_the_tcp_port(http_station) -> None:
    station, server = http_station
    assert server.address is not None
    browser = make_browser()
    try:
        with hostile_site(PAGE % {"port": server.address[1], "sat": SO_50}) as url:
            browser.get(url)
            wait_for(lambda: browser.title == "done", what="the page's fetch")
            outcome = browser.execute_script("return window.outcome")
    finally:
        browser.quit()
    operator = LineClient(server.address)  # anything the request carried has been read by now
    assert operator.read_line().startswith(b"Hello")
    assert operator.ask("STATUS").startswith(f"satellite={ISS} ")
    operator.close()
    state = station.core.state.snapshot()
    assert state.catalog_number == ISS and not state.tracking, outcome
    assert server.stats.http_closed >= 1, (outcome, server.stats)
    assert outcome == "failed"  # the connection was closed without an answer
