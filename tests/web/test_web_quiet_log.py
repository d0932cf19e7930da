"""Pages coming and going do not fill the station's log (#44 item 5): 72.6 KB/h of the issue's soak were web
connect/disconnect lines (four pages reconnecting every minute), so log rotation would first happen after
about three days.  A page's event stream opening and closing is logged at debug level now; a stream the
server drops stays a warning."""

from __future__ import annotations

import logging

from tests.waiting import wait_for
from tests.web.web_helpers import connect, running_web


def _tick(core) -> bool:
    """A new frame for the stream to write (which finds the page gone)."""
    core.clock.advance(0.2)
    core.tick(core.clock.now())
    return True


def test_a_page_connecting_and_leaving_writes_nothing_at_info(caplog) -> None:
    with caplog.at_level(logging.DEBUG, logger="nfwserver.web"), running_web() as (core, web):
        for _ in range(3):
            with connect(web) as page:
                page.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
                wait_for(lambda: web.stats.streams == 1, what="the page's event stream")
                assert page.recv(1024).startswith(b"HTTP/1.0 200")
            wait_for(lambda: _tick(core) and web.stats.streams == 0, what="the stream to end with its page")
    pages = [r for r in caplog.records if r.getMessage().startswith("web page ")]
    assert len(pages) == 6  # still there, for --verbose ...
    assert all(r.levelno == logging.DEBUG for r in pages)  # ... but not in the station's log at INFO
