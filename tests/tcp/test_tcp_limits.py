"""Hostile and careless TCP peers (issue 23 items 5-9): none can crash a handler, flood the log, lock
other addresses out or make the accept loop spin.  Real sockets on loopback; 127.0.0.x addresses stand
for different hosts (Linux routes all of 127.0.0.0/8 to the loopback interface)."""

from __future__ import annotations

import dataclasses
import logging

import pytest

from nfwserver.tcp.server import NovaTcpServer
from tests.dde.conftest import make_station
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient

GREETING = b"Hello, this is Nova for Windows.\r\n"
LOOPBACK_NET = dataclasses.replace(LOOPBACK_ONLY, allow=("127.0.0.0/8",), max_per_address=3, max_clients=5,
                                   idle_timeout_s=30.0)


@pytest.fixture
def limited():
    station = make_station()
    server = NovaTcpServer(station.core, LOOPBACK_NET)
    server.start()
    clients: list[LineClient] = []

    def connect(bind: str) -> LineClient:
        c = LineClient(server.address, bind=bind)
        clients.append(c)
        return c

    try:
        yield station, server, connect
    finally:
        for c in clients:
            c.close()
        server.stop()


@pytest.mark.parametrize("junk", [b"\x0b", b"\x0c", b"\x1c", b"\x1d\x1e\x1f", b" \x0b\t\x0c "])
def test_a_line_of_vertical_tabs_or_separators_is_blank(limited, junk: bytes, caplog) -> None:
    """Item 5: such a line raised IndexError and logged a traceback per line; now it is blank: no reply."""
    _, server, connect = limited
    c = connect("127.0.0.1")
    assert c.read_line() == GREETING
    caplog.set_level(logging.WARNING)
    c.send(junk * 1 + b"\r\n" + junk + b"\n" + b"STATUS\r\n")
    assert c.text().startswith("satellite=")  # the next reply is STATUS's: the junk lines got none
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR or r.exc_info]


def test_one_address_cannot_lock_the_others_out(limited) -> None:
    """Item 6, as issue 42 changed it: over the per-address cap a newcomer displaces its own address's quietest
    connection; over the global cap, another address's quietest, never one from the station's own address;
    refused (one clear line) only when there is nobody it may displace."""
    _, server, connect = limited
    mine = [connect("127.0.0.1") for _ in range(3)]
    assert all(c.read_line() == GREETING for c in mine)
    assert mine[1].ask("STATUS").startswith("satellite=") and mine[2].ask("SUMMARY") is not None
    fourth = connect("127.0.0.1")
    assert fourth.read_line() == GREETING
    assert mine[0].read_line() == b""  # the quietest of 127.0.0.1's made room
    others = [connect("127.0.0.2"), connect("127.0.0.3")]
    assert all(c.read_line() == GREETING for c in others)
    assert others[0].ask("STATUS").startswith("satellite=")
    late = connect("127.0.0.4")
    assert late.read_line() == GREETING
    assert others[1].read_line() == b""  # another address's quietest (no command yet), not one of 127.0.0.1's
    for c in (mine[1], mine[2], fourth, others[0], late):
        assert c.ask("STATUS").startswith("satellite=")
    assert server.stats.evicted == 2 and server.stats.refused == 0


def test_a_newcomer_with_nobody_to_displace_gets_one_line() -> None:
    """When the station's own addresses hold every slot, another address is refused with one ERROR line."""
    station = make_station()
    server = NovaTcpServer(station.core, dataclasses.replace(LOOPBACK_NET, max_clients=2))
    server.start()
    clients = [LineClient(server.address) for _ in range(2)]
    try:
        assert all(c.read_line() == GREETING for c in clients)
        clients.append(LineClient(server.address, bind="127.0.0.2"))
        assert clients[-1].text() == "ERROR the station serves 2 connections at most; try again later"
        assert clients[-1].read_line() == b""
        assert server.stats.refused == 1 and all(c.ask("STATUS").startswith("satellite=") for c in clients[:2])
    finally:
        for c in clients:
            c.close()
        server.stop()


def test_connections_that_complete_no_line_are_closed_but_watchers_stay(limited) -> None:
    """Item 6: idle connections (connected and silent, or trickling a line that never ends) are closed
    after idle_timeout_s of the station's clock; a WATCH subscriber never is."""
    station, server, connect = limited
    silent, loris, poller, watcher = (connect(f"127.0.0.{k}") for k in (1, 2, 3, 4))
    for c in (silent, loris, poller, watcher):
        assert c.read_line() == GREETING
    station.core.set_feed(True)
    assert watcher.ask("WATCH") == "OK"
    for _ in range(4):  # 4 x 10 s: the poller completes a line every 10 s; the loris sends bytes, no line
        loris.send(b"S")
        assert poller.ask("STATUS").startswith("satellite=")
        station.run(10.0)
        server.wake()
    assert silent.read_line() == b"" and loris.read_line() == b""
    assert server.stats.idle_closed == 2
    assert (server.client_count(), server.watcher_count()) == (2, 1)
    assert poller.ask("STATUS").startswith("satellite=")
    assert watcher.text().startswith("ISS ")  # still streaming (every line it gets is a published string)


def test_refusals_are_rate_limited_per_address_across_reconnects(limited, caplog) -> None:
    """Item 7: reconnecting no longer starts the refusal log afresh."""
    _, _, connect = limited
    caplog.set_level(logging.WARNING, logger="nfwserver.core.station_core")
    for _ in range(5):
        c = connect("127.0.0.1")
        assert c.read_line() == GREETING
        assert c.ask("SAT=99999").startswith("ERROR satellite 99999 is not in the catalog")
        c.close()
    refused = [r for r in caplog.records if "refused command" in r.getMessage()]
    assert len(refused) == 1


def test_an_ipv4_mapped_peer_matches_ipv4_allow_entries() -> None:
    """Item 8: on a dual-stack listener an IPv4 client appears as ::ffff:127.0.0.1."""
    station = make_station()
    config = dataclasses.replace(LOOPBACK_ONLY, host="::", allow=("127.0.0.1",))
    server = NovaTcpServer(station.core, config)
    try:
        server.start()
    except OSError:
        pytest.skip("no IPv6 on this machine")
    try:
        c = LineClient(("127.0.0.1", server.address[1]))
        assert c.read_line() == GREETING
        assert c.ask("STATUS").startswith("satellite=")
        c.close()
    finally:
        server.stop()
