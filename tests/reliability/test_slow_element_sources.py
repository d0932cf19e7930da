"""Element downloads have a deadline for the whole transfer, redirects stay on http(s), a redirect loop is one
line, and a station stops at once during a download (#34 item 11).  A real HTTP server on loopback that
trickles, redirects and loops."""

from __future__ import annotations

import http.server
import threading
import time
from collections.abc import Iterator
from datetime import datetime, timezone

import pytest

from nfwserver.app.element_sources import SourceError, fetch_url
from nfwserver.app.station import Station
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from tests.conftest import advance_until

TRICKLE_S = 0.2  # one byte every TRICKLE_S real seconds, TRICKLE_BYTES of them
TRICKLE_BYTES = 100
requested = threading.Event()


class _Handler(http.server.BaseHTTPRequestHandler):
    def do_GET(self) -> None:
        requested.set()
        if self.path == "/trickle":  # a body of one byte at a time
            self.send_response(200)
            self.end_headers()
            for _ in range(TRICKLE_BYTES):
                self.wfile.write(b"#")
                self.wfile.flush()
                time.sleep(TRICKLE_S)
        elif self.path == "/trickle-head":  # the headers themselves, one byte at a time
            for byte in b"HTTP/1.0 200 OK\r\nX-Slow: " + b"x" * TRICKLE_BYTES:
                self.wfile.write(bytes([byte]))
                self.wfile.flush()
                time.sleep(TRICKLE_S)
        elif self.path == "/to-ftp":
            self.send_response(302)
            self.send_header("Location", "ftp://127.0.0.1:1/elements.txt")
            self.end_headers()
        elif self.path == "/loop":
            self.send_response(302)
            self.send_header("Location", "/loop")
            self.end_headers()
        else:
            self.send_error(404)
        self.close_connection = True

    def log_message(self, *args: object) -> None:
        pass


@pytest.fixture
def base_url() -> Iterator[str]:
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Handler)
    server.daemon_threads = True
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


@pytest.mark.parametrize("path", ["/trickle", "/trickle-head"])
def test_a_trickling_server_is_cut_at_the_deadline_for_the_whole_transfer(base_url: str, path: str) -> None:
    """``--timeout 3`` of a URL that sent one byte a second ran for over 45 s: the timeout was per read."""
    started = time.monotonic()
    with pytest.raises(SourceError) as info:
        fetch_url(base_url + path, timeout_s=1.0)
    took = time.monotonic() - started
    assert str(info.value) == f"cannot fetch {base_url}{path}: the whole transfer did not end within 1 s"
    assert took < TRICKLE_S * TRICKLE_BYTES / 2  # not the whole trickle (20 s): cut at the deadline


def test_a_redirect_to_ftp_is_not_followed(base_url: str) -> None:
    with pytest.raises(SourceError) as info:
        fetch_url(base_url + "/to-ftp", timeout_s=5.0)
    assert str(info.value) == (f"cannot fetch {base_url}/to-ftp: redirected to 'ftp://127.0.0.1:1/elements.txt', "
                               "which is not http(s)")


def test_a_redirect_loop_is_one_line(base_url: str) -> None:
    with pytest.raises(SourceError) as info:
        fetch_url(base_url + "/loop", timeout_s=5.0)
    assert str(info.value) == f"cannot fetch {base_url}/loop: too many redirects (HTTP 302; a redirect loop?)"


def _station(url: str) -> tuple[Station, VirtualClock]:
    config = parse_config(f'[observer]\nlocation = "JO02ae"\n[elements]\nurls = ["{url}"]\nstore = "none"\n'
                          '[server]\nstate_file = "none"\n')
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    return Station(config, clock, transport=FakeDdeSystem().server_transport()), clock


def test_a_station_stops_at_once_during_a_download(base_url: str) -> None:
    """A station whose element URL trickled took 5 s to stop (the refresher's join timed out) and left the
    download running."""
    requested.clear()
    station, _ = _station(base_url + "/trickle")
    station.start()
    try:
        assert requested.wait(10.0)
        fetching = station.refresher._thread
        assert fetching is not None and fetching.is_alive()
    finally:
        station.stop()
    fetching.join(1.0)
    assert not fetching.is_alive()


def test_a_failing_element_source_is_a_fault_in_status(base_url: str) -> None:
    """The station showed ``faults=none`` while its element URL could not be read."""
    station, clock = _station(base_url + "/missing")
    station.start()
    try:
        assert advance_until(clock, lambda: "elements" in station.core.health.faults(), limit_s=5.0)
        assert "HTTP 404" in station.core.health.faults()["elements"]
    finally:
        station.stop()
