"""Hostile and careless TCP peers (issue 23 items 5-9): none can crash a handler, flood the log, lock
other addresses out or make the accept loop spin.  Real sockets on loopback; 127.0.0.x addresses stand
for different hosts (Linux routes all of 127.0.0.0/8 to the loopback interface)."""

from __future__ import annotations

import dataclasses
import logging
import select

import pytest

from nfwserver.tcp.server import NovaTcpServer
from tests.dde.conftest import make_station
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient
from tests.waiting import wait_for

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
    """Item 6: a per-address cap under the global one, each refusal one clear line."""
    _, server, connect = limited
    mine = [connect("127.0.0.1") for _ in range(3)]
    assert all(c.read_line() == GREETING for c in mine)
    fourth = connect("127.0.0.1")
    assert fourth.text() == "ERROR too many connections from 127.0.0.1 (at most 3)"
    assert fourth.read_line() == b""
    others = [connect("127.0.0.2"), connect("127.0.0.3")]
    assert all(c.read_line() == GREETING for c in others)
    full = connect("127.0.0.4")
    assert full.text() == "ERROR the station serves 5 connections at most; try again later"
    assert full.read_line() == b""
    mine[0].close()
    assert wait_for(lambda: server.client_count() == 4)
    assert connect("127.0.0.4").read_line() == GREETING  # a place freed is served again


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


def test_idle_connections_never_lock_out_the_operators_tools() -> None:
    """#34 item 14: on the loopback default every local client shares one address, so 32 idle connections from
    127.0.0.1 made ``nfwserver status`` and ``poke`` fail for up to the 300 s idle timeout.  Over a cap, the
    connection idle longest (1 s or more, never a WATCH) now makes room; one that talks keeps its place."""
    station = make_station()
    server = NovaTcpServer(station.core, LOOPBACK_ONLY)  # the defaults: 32 per address
    server.start()
    flood: list[LineClient] = []
    try:
        watcher = LineClient(server.address)
        assert watcher.read_line() == GREETING and watcher.ask("WATCH") == "OK"
        for _ in range(LOOPBACK_ONLY.max_per_address - 1):
            flood.append(LineClient(server.address))
            assert flood[-1].read_line() == GREETING
        station.run(2.0)  # the flood has been idle for 2 s of the station's clock
        server.wake()
        tools = []
        for _ in range(3):  # the operator's tools, one connection each, as `status` and `poke` make them
            tools.append(LineClient(server.address))
            assert tools[-1].read_line() == GREETING
            assert tools[-1].ask("STATUS").startswith("satellite=")  # (still connected when the next comes)
        assert server.stats.evicted == 3 and server.watcher_count() == 1
        for tool in tools:
            tool.close()
        assert wait_for(lambda: server.client_count() == LOOPBACK_ONLY.max_per_address - 3)
        closed, _, _ = select.select([c.sock for c in flood], [], [], 1.0)  # idle ones closed for the tools
        assert len(closed) == 3 and all(sock.recv(1) == b"" for sock in closed)
        alive = [c for c in flood if c.sock not in closed]
        # Connections that keep talking are never closed for a newcomer: then the cap refuses, as before.
        busy = [LineClient(server.address) for _ in range(3)]
        assert all(c.read_line() == GREETING for c in busy)
        for c in (*alive, *busy):
            assert c.ask("STATUS").startswith("satellite=")
        late = LineClient(server.address)
        assert late.text() == f"ERROR too many connections from 127.0.0.1 (at most {LOOPBACK_ONLY.max_per_address})"
        late.close()
        for c in busy:
            c.close()
        watcher.close()
    finally:
        for c in flood:
            c.close()
        server.stop()
