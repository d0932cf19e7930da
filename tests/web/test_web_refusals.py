"""Refusals as an attacker makes them: whatever the request says, one log line and one event a minute per
peer address; and every answer, the standard library's errors included, carries the security headers.
Real sockets on loopback (127.0.0.2 and 127.0.0.3 play other hosts), raw HTTP."""

from __future__ import annotations

import json
import logging

import pytest

from nfwserver.web.request_head import SECURITY_HEADERS
from tests.web.conftest import TOKEN
from tests.web.web_helpers import body, command_request, connect, exchange, read_all, running_web, status


def _refusal_lines(caplog, address: str) -> list[str]:
    return [r.getMessage() for r in caplog.records if "refused" in r.getMessage() and address in r.getMessage()]


def test_refusals_are_logged_once_a_minute_per_address_whatever_the_headers_say(caplog) -> None:
    """Issue 42: 600 refused POSTs from one address, each with a different Origin, wrote 600 log lines and
    196 of the page's last 200 events (the rate limit was keyed on the refusal's text)."""
    caplog.set_level(logging.WARNING, "nfwserver.web")
    with running_web() as (core, web):
        before = core.events.recent(5000)[-1].seq if core.events.recent(5000) else -1
        for n in range(600):
            reply = exchange(web, command_request(web, "TRACK ON", headers={"Origin": f"http://evil{n}.example"}),
                             "127.0.0.2")
            assert status(reply) == 403
        for n in range(50):  # other kinds of refusal from the same address: still the same burst
            exchange(web, command_request(web, "TRACK ON", token=f"guess-{n}-0123"), "127.0.0.2")
            exchange(web, f"GET /api/state HTTP/1.1\r\nHost: rebound{n}.example\r\n\r\n".encode(), "127.0.0.2")
        assert len(_refusal_lines(caplog, "127.0.0.2")) == 1, _refusal_lines(caplog, "127.0.0.2")[:5]
        exchange(web, command_request(web, "TRACK ON", headers={"Origin": "http://evil.example"}), "127.0.0.3")
        assert len(_refusal_lines(caplog, "127.0.0.3")) == 1  # another address has its own line
        notes = [e for e in core.events.recent(5000) if e.seq > before and not e.accepted]
        assert len(notes) == 2, [(e.client, e.text, e.detail) for e in notes]
        assert not core.state.snapshot().tracking
        assert web.stats.refused >= 700


#: what Python's http.server answers itself (an HTML page before issue 42), and what our own code refuses
STANDARD_LIBRARY_ERRORS = {
    "OPTIONS (501)": b"OPTIONS /api/command HTTP/1.1\r\nHost: 127.0.0.1\r\nOrigin: http://evil.example\r\n"
                     b"Access-Control-Request-Method: POST\r\n\r\n",
    "150 headers (431)": b"GET /api/help HTTP/1.1\r\nHost: 127.0.0.1\r\n" + b"X-A: b\r\n" * 150 + b"\r\n",
    "an unknown method (501)": b"BREW /pot HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
    "DELETE (501)": b"DELETE /api/state HTTP/1.0\r\n\r\n",
    "a bad version number (400)": b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".replace(b"1.1", b"1.0.1", 1),
}
OUR_ERRORS = {
    "wrong Host (421)": b"GET /api/state HTTP/1.1\r\nHost: evil.example\r\n\r\n",
    "head over 32 KiB (431)": b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX: " + b"a" * 40000 + b"\r\n\r\n",
    "HTTP/0.9 (505)": b"GET /api/state\r\n",
    "not a request line (400)": b"hello there you\r\n\r\n",
    "no such path (404)": b"GET /nothing HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n",
    "no body length (411)": b"POST /api/command HTTP/1.0\r\nHost: 127.0.0.1\r\n"
                            b"Content-Type: application/json\r\n\r\n",
    "a body over 4 KiB (413)": b"POST /api/command HTTP/1.0\r\nHost: 127.0.0.1\r\nContent-Type: application/json"
                               b"\r\nContent-Length: 9999\r\n\r\n",
    "cross-site command (403)": b"POST /api/command HTTP/1.0\r\nHost: 127.0.0.1\r\nContent-Type: text/plain\r\n"
                                b"Content-Length: 2\r\n\r\n{}",
}


def _headers(reply: bytes) -> dict[str, str]:
    head = reply.split(b"\r\n\r\n", 1)[0].decode("latin-1").split("\r\n")[1:]
    return {name.strip().lower(): value.strip() for name, _, value in (line.partition(":") for line in head)}


@pytest.mark.parametrize("request_bytes", [*STANDARD_LIBRARY_ERRORS.values(), *OUR_ERRORS.values()],
                         ids=[*STANDARD_LIBRARY_ERRORS, *OUR_ERRORS])
def test_every_error_carries_the_security_headers_and_a_small_json_body(request_bytes: bytes) -> None:
    """Issue 42: the 431 (150 headers) and 501 (OPTIONS) answers were the standard library's HTML pages,
    without the Content-Security-Policy or nosniff that docs/WEB.md promises for every response."""
    with running_web() as (_core, web):
        reply = exchange(web, request_bytes)
        assert 400 <= status(reply) < 600, reply[:300]
        headers = _headers(reply)
        for name, value in SECURITY_HEADERS:
            assert headers.get(name.lower()) == value, (name, reply[:600])
        assert headers.get("content-type") == "application/json" and b"<html" not in reply.lower()
        answer = json.loads(body(reply))
        assert answer["ok"] is False and len(body(reply)) < 512, answer


def test_a_connection_refused_at_a_cap_carries_the_security_headers_too() -> None:
    with running_web(max_per_address=1, max_streams=64) as (_core, web):
        with connect(web) as held:
            held.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
            assert held.recv(100).startswith(b"HTTP/1.0 200")
            with connect(web) as second:
                reply = read_all(second)
        assert status(reply) == 503, reply
        headers = _headers(reply)
        assert all(headers.get(name.lower()) == value for name, value in SECURITY_HEADERS), reply
        assert TOKEN.encode() not in reply
