"""Pages on other origins, in real headless Chromium, against the station's web face.

A hostile page is served from a second loopback server (another port is another origin); a rebinding
name is made by Chromium's own resolver rule (``evil.example`` -> 127.0.0.1), as an attacker's DNS does.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

from tests.web.conftest import TOKEN, make_browser, wait_for

ATTACK = """<!doctype html><title>waiting</title><script>
const results = {};
const body = JSON.stringify({command: "TRACK ON", token: "%(token)s"});
const send = (name, options) => fetch("%(station)sapi/command", Object.assign({method: "POST", body}, options))
  .then(r => { results[name] = "answered " + r.status + " " + r.type; }, e => { results[name] = "failed"; });
Promise.all([
  send("no-cors text", {mode: "no-cors"}),
  send("no-cors json", {mode: "no-cors", headers: {"Content-Type": "application/json"}}),
  send("cors json", {headers: {"Content-Type": "application/json"}}),
  send("no-referrer", {mode: "no-cors", referrerPolicy: "no-referrer"}),
]).then(() => { window.results = results; document.title = "done"; });
</script>"""


@contextmanager
def hostile_site(page: str) -> Iterator[str]:
    """A page served from another origin (its own loopback port); yields its URL."""
    class Handler(BaseHTTPRequestHandler):
        def do_GET(self) -> None:  # noqa: N802
            data = page.encode()
            self.send_response(200)
            self.send_header("Content-Type", "text/html; charset=utf-8")
            self.send_header("Content-Length", str(len(data)))
            self.end_headers()
            self.wfile.write(data)

        def log_message(self, *args: object) -> None:
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()


def test_a_page_on_another_origin_cannot_send_a_command(browser, web_station) -> None:
    """6ca6bee: a no-cors fetch from another origin switched TRACK on (even with the token, which an
    attacker may have from a shoulder or a screenshot: the browser must not be a way in)."""
    core = web_station.station.core
    assert not core.state.snapshot().tracking
    with hostile_site(ATTACK % {"token": TOKEN, "station": web_station.url}) as url:
        browser.get(url)
        wait_for(lambda: browser.title == "done", what="the hostile page's requests")
        results = browser.execute_script("return window.results")
    assert results["cors json"] == "failed", results  # the preflight is never granted
    web_station.advance(0.4)
    assert not core.state.snapshot().tracking, results
    # every refusal is counted; the event stream gets one per address a minute, whichever request came first
    # (the preflight's 501 or a command's 403: the browser sends them in any order)
    assert web_station.station.web.stats.refused >= 3, results
    refused = [e for e in core.events.recent(50) if "refused" in (e.detail or "")]
    assert refused, "the refusals are recorded"


def test_a_rebound_name_reads_nothing() -> None:
    """DNS rebinding in the browser itself: evil.example resolves to the station's loopback address."""
    from tests.web.conftest import config_text, start_station

    web = start_station(config_text())
    driver = make_browser(extra_args=("--host-resolver-rules=MAP evil.example 127.0.0.1",))
    try:
        port = web.url.rsplit(":", 1)[1].strip("/")
        driver.get(f"http://evil.example:{port}/api/state")
        text = driver.find_element("tag name", "body").text
        assert "observer" not in text and "nova" not in text and "not a name of this station" in text, text
        driver.get(web.url + "api/state")  # the station's own address still reads it
        assert '"observer"' in driver.find_element("tag name", "body").text
    finally:
        driver.quit()
        web.station.stop()
