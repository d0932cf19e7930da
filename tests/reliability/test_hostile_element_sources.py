"""Hostile element sources on real loopback HTTP (issue 18 item 1): a bad set or a broken reply never
stops ``elements update``; the good sets are stored, the bad ones reported, no traceback."""

from __future__ import annotations

import http.server
import json
import subprocess
import sys
import threading
from collections.abc import Iterator

import pytest

from nfwserver.app.element_sources import fetch_all
from nfwserver.tracking.elements import load_element_file
from tests.tracking.test_hostile_elements import GOOD, NEIGHBOUR

BAD_OMM = json.dumps([{**GOOD, "BSTAR": float("inf")}, NEIGHBOUR]).encode()


class _Handler(http.server.BaseHTTPRequestHandler):
    def do_GET(self) -> None:
        if self.path == "/omm.json":
            self.send_response(200)
            self.send_header("Content-Length", str(len(BAD_OMM)))
            self.end_headers()
            self.wfile.write(BAD_OMM)
        elif self.path == "/short":  # promises more than it sends: http.client.IncompleteRead
            self.send_response(200)
            self.send_header("Content-Length", "100000")
            self.end_headers()
            self.wfile.write(b"1 25544U")
            self.close_connection = True
        else:  # not HTTP at all
            self.wfile.write(b"\x00garbage\r\n\r\n")
            self.close_connection = True

    def log_message(self, *args: object) -> None:
        pass


@pytest.fixture
def base_url() -> Iterator[str]:
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def test_broken_http_replies_are_reported_not_raised(base_url: str) -> None:
    result = fetch_all(urls=(f"{base_url}/short", f"{base_url}/garbage", f"{base_url}/omm.json"),
                       use_bundled=False, timeout_s=5.0)
    assert [s.catalog_number for s in result.sets] == [43017]
    assert len(result.failed) == 2 and len(result.rejected) == 1
    assert all(f.isprintable() for f in result.failed)  # one line each, whatever the server sent


def test_elements_update_from_a_url_with_an_infinite_bstar(base_url: str, tmp_path) -> None:
    store = tmp_path / "elements.txt"
    proc = subprocess.run([sys.executable, "-m", "nfwserver", "elements", "update", f"{base_url}/omm.json",
                           "--store", str(store)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr and "BSTAR inf" in proc.stderr
    assert [s.catalog_number for s in load_element_file(store).sets] == [43017]
