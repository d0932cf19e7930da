"""Clients coming and going do not fill the station's log (#44 item 5), as for the web face
(tests/web/test_web_quiet_log.py): a TCP client's connect and ordinary close are logged at debug level and
stay in the event stream; a close the server decided (idle, evicted, failed) stays at INFO."""

from __future__ import annotations

import dataclasses
import logging

from nfwserver.tcp.server import NovaTcpServer
from tests.dde.conftest import make_station
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient
from tests.waiting import wait_for


def _tcp_lines(caplog) -> list[logging.LogRecord]:
    return [r for r in caplog.records if r.getMessage().startswith("TCP client ")]


def _kinds(station) -> list[str]:
    return [e.kind for e in station.core.events.since(0, 1000)[0] if e.kind in ("connect", "disconnect")]


def test_a_client_connecting_and_leaving_writes_nothing_at_info(tcp_station, caplog) -> None:
    station, server = tcp_station
    with caplog.at_level(logging.DEBUG, logger="nfwserver.tcp"):
        for _ in range(3):
            c = LineClient(server.address)
            c.read_line()  # the greeting
            assert c.ask("STATUS").startswith("satellite=")  # its first line: now on record
            c.close()
        wait_for(lambda: len(_tcp_lines(caplog)) == 6, what="three connects and three disconnects")
        wait_for(lambda: _kinds(station).count("disconnect") == 3, what="the third disconnect event")
    lines = _tcp_lines(caplog)
    assert [r.getMessage().split()[-1] for r in lines].count("connected") == 3
    assert all(r.levelno == logging.DEBUG for r in lines)  # for --verbose, not the station's log at INFO
    assert _kinds(station).count("connect") == 3  # the event stream keeps every one


def test_a_close_the_server_decided_stays_at_info(caplog) -> None:
    station = make_station()
    server = NovaTcpServer(station.core, dataclasses.replace(LOOPBACK_ONLY, idle_timeout_s=30.0))
    server.start()
    c = LineClient(server.address)
    try:
        with caplog.at_level(logging.DEBUG, logger="nfwserver.tcp"):
            c.read_line()
            assert c.ask("STATUS").startswith("satellite=")
            station.run(31.0)  # no complete line for idle_timeout_s of the station's clock
            server.wake()
            assert c.read_line() == b""
            # the socket is closed before the line is logged: wait for it while DEBUG is still captured
            wait_for(lambda: any("disconnected" in r.getMessage() for r in _tcp_lines(caplog)), what="its log line")
    finally:
        c.close()
        server.stop()
    closes = [r for r in _tcp_lines(caplog) if "disconnected" in r.getMessage()]
    assert [r.levelno for r in closes] == [logging.INFO], [r.getMessage() for r in closes]
    assert "idle for 30 s" in closes[0].getMessage()
