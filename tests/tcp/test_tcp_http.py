"""HTTP on Nova's TCP port is closed before anything in it runs (issue 42 item 1), and refused or closed peers
are on record once a minute per address whatever they vary (item 5).  Real sockets on loopback; the requests
are written as RFC 9112 describes them and as Chromium sends them (tests/tcp/test_tcp_http_browser.py sends
one from a real page)."""

from __future__ import annotations

import logging

import pytest

from nfwserver.core.events import Direction
from nfwserver.core.station_core import StationCore
from nfwserver.tcp.http_guard import http_line
from nfwserver.tcp.server import NovaTcpServer
from nfwserver.tcp.status_line import parse_status
from tests.dde.conftest import ISS
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient

GREETING = b"Hello, this is Nova for Windows.\r\n"
#: What Chromium sends for ``fetch(url, {method: 'POST', mode: 'no-cors', body: '\r\nSAT=27607\r\nTRACK ON\r\n'})``
#: (headers as in its request; the body's lines are the attack).
CHROMIUM_POST = (b"POST / HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: keep-alive\r\nContent-Length: 24\r\n"
                 b"sec-ch-ua-platform: \"Linux\"\r\nUser-Agent: Mozilla/5.0 (X11; Linux x86_64) HeadlessChrome\r\n"
                 b"Content-Type: text/plain;charset=UTF-8\r\nAccept: */*\r\nOrigin: http://127.0.0.1:8000\r\n"
                 b"Sec-Fetch-Site: same-site\r\nSec-Fetch-Mode: no-cors\r\nReferer: http://127.0.0.1:8000/\r\n"
                 b"Accept-Encoding: gzip, deflate, br\r\n\r\n\r\nSAT=27607\r\nTRACK ON\r\n")


def _unchanged(core: StationCore) -> bool:
    state = core.state.snapshot()
    return state.catalog_number == ISS and not state.tracking


@pytest.mark.parametrize("line", [
    b"POST / HTTP/1.1", b"GET /index.html?a=b HTTP/1.0", b"OPTIONS * HTTP/1.1", b"PRI * HTTP/2.0",
    b"get / http/1.1", b"Host: 127.0.0.1:8090", b"host:evil.example", b"Origin: http://evil.example",
    b"Content-Type: text/plain;charset=UTF-8", b"User-Agent: Mozilla/5.0", b"Sec-Fetch-Mode: no-cors",
    b"Referer: http://evil.example/", b"Content-Length: 24", b"Accept: */*", b"Connection: keep-alive",
])
def test_request_and_header_lines_are_http(line: bytes) -> None:
    assert http_line(line) is not None


@pytest.mark.parametrize("line", [
    b"SAT=27607", b"TRACK ON", b"TUNE OFF", b"STATUS", b"WATCH", b"SUMMARY", b"QUIT", b"ANTAZ=120.5", b"HELP",
    b"FLIP AUTO", b"PARK", b"", b"   ", b"SAT=ISS (ZARYA)", b"HTTP", b"POST", b"Note: not a header we know",
])
def test_nova_commands_and_junk_are_not_http(line: bytes) -> None:
    assert http_line(line) is None


def test_a_browsers_post_runs_nothing_and_is_closed(http_station) -> None:
    """The request of issue 42 item 1, in one write: its body's lines used to run (satellite=27607)."""
    station, server = http_station
    attacker = LineClient(server.address)
    assert attacker.read_line() == GREETING
    attacker.send(CHROMIUM_POST % server.address[1])
    assert attacker.read_line() == b""  # closed, not one reply
    assert _unchanged(station.core)
    assert server.stats.http_closed == 1
    operator = LineClient(server.address)
    assert operator.read_line() == GREETING
    status = parse_status(operator.ask("STATUS"))
    assert status["satellite"] == str(ISS) and status["track"] == "off" and status["tcp_http_closed"] == "1"
    operator.close()


@pytest.mark.parametrize("write", [
    b"STATUS\r\nHost: x\r\nSAT=27607\r\n",  # a command before it in the same read does not run either
    b"Origin: http://evil.example\r\n\r\nSAT=27607\r\n",  # a header line alone is enough
])
def test_nothing_in_a_read_with_http_runs(http_station, write: bytes) -> None:
    station, server = http_station
    c = LineClient(server.address)
    assert c.read_line() == GREETING
    c.send(write)
    assert c.read_line() == b""
    assert _unchanged(station.core) and server.stats.http_closed == 1
    assert not [e for e in station.core.events.recent(50) if e.direction is Direction.IN and e.kind == "request"]


def test_a_request_line_in_its_own_read_closes_before_the_next_arrives(http_station) -> None:
    station, server = http_station
    c = LineClient(server.address)
    assert c.read_line() == GREETING
    c.send(b"POST / HTTP/1.1\r\n")
    assert c.read_line() == b""  # closed before the rest was even sent
    try:
        c.send(b"\r\nSAT=27607\r\n")
    except OSError:
        pass
    assert _unchanged(station.core) and server.stats.http_closed == 1


def test_a_flood_of_http_varying_everything_is_one_log_line_and_one_event_a_minute(http_station, caplog) -> None:
    """Item 5: 200 requests from one address, each with another Origin and path, cost one log line and one
    event; the next minute's first one says how many were left out."""
    station, server = http_station
    caplog.set_level(logging.WARNING, logger="nfwserver.tcp.server")
    for k in range(200):
        c = LineClient(server.address, bind="127.0.0.2")
        c.send(b"POST /%d HTTP/1.1\r\nOrigin: http://evil%d.example\r\n\r\n" % (k, k))
        while c.read_line() != b"":  # the greeting, then the close
            pass
        c.close()
    assert server.stats.http_closed == 200
    logged = [r.getMessage() for r in caplog.records if "127.0.0.2" in r.getMessage()]
    events = [e for e in station.core.events.recent(1000) if "127.0.0.2" in (e.client or "")]
    assert len(logged) == 1 and len(events) == 1, (logged, events)  # no connect or disconnect events either
    station.run(61.0)
    c = LineClient(server.address, bind="127.0.0.2")
    c.send(b"GET / HTTP/1.1\r\n")
    while c.read_line() != b"":
        pass
    c.close()
    logged = [r.getMessage() for r in caplog.records if "127.0.0.2" in r.getMessage()]
    assert len(logged) == 2 and "199 more like this" in logged[1], logged
    assert "199 more from 127.0.0.2" in [e for e in station.core.events.recent(5) if e.kind == "note"][-1].text


def test_refused_peers_are_one_log_line_and_one_event_a_minute_per_address(http_station, caplog) -> None:
    """Item 5: 100 connections from outside ``[tcp] allow`` (each on another port) cost one line and one event."""
    station, _ = http_station
    server = NovaTcpServer(station.core, LOOPBACK_ONLY)  # 127.0.0.1 only
    server.start()
    caplog.set_level(logging.WARNING, logger="nfwserver.tcp.server")
    try:
        for _ in range(100):
            c = LineClient(server.address, bind="127.0.0.3")
            assert c.read_line() == b""
            c.close()
    finally:
        server.stop()
    assert server.stats.refused == 100
    assert len([r for r in caplog.records if "127.0.0.3" in r.getMessage()]) == 1
    assert len([e for e in station.core.events.recent(1000) if "127.0.0.3" in (e.client or "")]) == 1
