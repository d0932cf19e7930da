"""The operator is never locked out of the TCP tools (issue 42 items 3 and 4): over a cap the quietest connection
goes (a blank line or an idle WATCH is not doing something), the station's own addresses keep a reserve other
addresses cannot take, and ``nfwserver watch`` is never closed for another address.  Real sockets on loopback;
127.0.0.2-9 stand for other hosts, 127.0.0.1 is where the operator's tools connect from."""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Iterator

import pytest

from nfwserver.cli.watch_command import StationWatcher
from nfwserver.cli.watch_view import WatchUpdate
from nfwserver.tcp.client import ask
from nfwserver.tcp.server import NovaTcpServer
from tests.dde.conftest import Station, make_station
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient
from tests.waiting import wait_for

GREETING = b"Hello, this is Nova for Windows.\r\n"


@pytest.fixture
def served() -> Iterator[tuple[Station, NovaTcpServer, list[LineClient]]]:
    """A station whose TCP server has the defaults (32 per address, 256 in all); the clients are closed after."""
    station = make_station()
    server = NovaTcpServer(station.core, dataclasses.replace(LOOPBACK_ONLY, allow=("127.0.0.0/8",)))
    server.start()
    clients: list[LineClient] = []
    try:
        yield station, server, clients
    finally:
        for c in clients:
            c.close()
        server.stop()


def _status(server: NovaTcpServer) -> str:
    """``nfwserver status``'s question, asked as it asks it (a new connection from 127.0.0.1)."""
    assert server.address is not None
    return ask("127.0.0.1", server.address[1], "STATUS", timeout_s=5.0)


def _send_quietly(c: LineClient, data: bytes) -> bool:
    """Send ``data``; False when the server has closed the connection meanwhile."""
    try:
        c.send(data)
        return True
    except OSError:
        return False


def _closed(c: LineClient) -> bool:
    """The server closed ``c`` (read past what it was sent); False when it stays open 5 s."""
    try:
        while c.read_line(timeout=5.0) != b"":
            pass
    except OSError:
        return False
    return True


def test_blank_lines_every_half_second_do_not_lock_out_status(served) -> None:
    """32 connections from 127.0.0.1 sending a blank line every 0.5 s made ``status`` fail with "ERROR too many
    connections": a blank line counted as activity.  Now the quietest of them makes room."""
    station, server, clients = served
    crowd: list[LineClient] = []
    for _ in range(LOOPBACK_ONLY.max_per_address):
        crowd.append(LineClient(server.address))
        clients.append(crowd[-1])
        assert crowd[-1].read_line() == GREETING
        station.run(0.2)  # each connected a little later than the one before
    assert crowd[0].ask("SUMMARY") is not None  # the first sent a real command: it is not the quietest
    for _ in range(6):  # 3 s of the station's clock
        for c in crowd:
            c.send(b"\r\n")
        station.run(0.5)
        server.wake()
    assert _status(server).startswith("satellite=")
    assert server.stats.evicted == 1 and server.stats.refused == 0
    assert crowd[1].read_line() == b""  # the first to connect of those that never sent a command made room
    assert crowd[0].ask("STATUS").startswith("satellite=")  # the one that did keeps its connection


def test_a_crowd_of_watch_subscribers_does_not_lock_out_status(served) -> None:
    """32 ``WATCH`` connections from 127.0.0.1 made ``status`` fail: a WATCH was never closed to make room.  Now
    the WATCH that has been quiet longest goes, each time a tool needs the room."""
    station, server, clients = served
    crowd = [LineClient(server.address) for _ in range(LOOPBACK_ONLY.max_per_address)]
    clients += crowd
    for c in crowd:
        assert c.read_line() == GREETING and c.ask("WATCH") == "OK"
        station.run(0.2)  # each subscribed a little later than the one before
    for k in range(3):
        assert _status(server).startswith("satellite="), k
        assert _closed(crowd[k])  # the quietest WATCH: the first to subscribe
        crowd.append(LineClient(server.address))  # the crowd fills the room again
        clients.append(crowd[-1])
        assert crowd[-1].read_line() == GREETING and crowd[-1].ask("WATCH") == "OK"
    assert server.stats.evicted == 3 and server.stats.refused == 0
    assert server.watcher_count() == LOOPBACK_ONLY.max_per_address


def test_other_addresses_cannot_take_the_reserve_nor_close_the_operators_connections() -> None:
    """Other addresses hold at most ``max_clients`` - reserve connections; over that a newcomer from another
    address displaces one of theirs, never one from the station's own address."""
    station = make_station()
    config = dataclasses.replace(LOOPBACK_ONLY, allow=("127.0.0.0/8",), max_clients=6, max_per_address=6)
    server = NovaTcpServer(station.core, config)  # reserve: min(8, 6 // 2) = 3 slots for 127.0.0.1 and ::1
    server.start()
    clients: list[LineClient] = []
    try:
        for _ in range(6):
            clients.append(LineClient(server.address, bind="127.0.0.2"))
            assert clients[-1].read_line() == GREETING
        assert wait_for(lambda: server.client_count() == 3)  # the other three made room among 127.0.0.2's own
        mine = [LineClient(server.address) for _ in range(3)]
        clients += mine
        assert all(c.read_line() == GREETING for c in mine)
        evicted = server.stats.evicted
        assert evicted == 3 and server.client_count() == 6  # the reserve was free: nobody closed for mine
        late = LineClient(server.address, bind="127.0.0.3")
        clients.append(late)
        assert late.read_line() == GREETING
        assert server.stats.evicted == evicted + 1  # one of 127.0.0.2's, not one of mine
        for c in mine:
            assert c.ask("STATUS").startswith("satellite=")
    finally:
        for c in clients:
            c.close()
        server.stop()


def test_the_operators_watch_survives_other_addresses_filling_the_cap() -> None:
    """``nfwserver watch`` polls, so it looked idle: another address filling the global cap closed it, and
    every retry was refused.  Now no connection from the station's own address is closed for another one."""
    station = make_station()
    config = dataclasses.replace(LOOPBACK_ONLY, allow=("127.0.0.0/8",), max_clients=24, max_per_address=3)
    server = NovaTcpServer(station.core, config)
    server.start()
    assert server.address is not None
    updates: list[WatchUpdate] = []
    stop = threading.Event()
    watcher = StationWatcher("127.0.0.1", server.address[1], updates.append, clock=station.clock,
                             interval_s=2.0, stop=stop)
    thread = threading.Thread(target=watcher.run, name="test-watch", daemon=True)
    crowd: list[LineClient] = []
    try:
        thread.start()
        assert wait_for(lambda: watcher.answers >= 1)
        for _ in range(16):  # 8 s of the station's clock: each other address connects again every 0.5 s
            for host in range(2, 10):
                crowd.append(LineClient(server.address, bind=f"127.0.0.{host}"))
            crowd = [c for c in crowd if _send_quietly(c, b"\r\n")]  # the rest keep "talking" (blank lines)
            station.run(0.5)
            server.wake()
        answers = watcher.answers

        def polled_again() -> bool:  # the station's clock moves on until the watch has asked twice more
            station.run(0.5)
            return watcher.answers >= answers + 2

        assert wait_for(polled_again), watcher.answers
        assert server.stats.evicted > 0  # the crowd did reach the cap
        assert [u for u in updates if not u.connected] == []  # the watch never lost its connection
    finally:
        stop.set()
        station.clock.advance(10.0)
        thread.join(5.0)
        for c in crowd:
            c.close()
        server.stop()


def test_the_operators_watch_holds_a_watch_and_outlasts_a_watch_crowd_from_its_own_address(served) -> None:
    """``nfwserver watch`` holds a real WATCH between its questions (so no idle timeout closes it), and when a
    crowd of idle WATCH subscribers from 127.0.0.1 fills the cap, ``status`` closes one of the crowd, not it."""
    station, server, clients = served
    assert server.address is not None
    updates: list[WatchUpdate] = []
    stop = threading.Event()
    watcher = StationWatcher("127.0.0.1", server.address[1], updates.append, clock=station.clock,
                             interval_s=1.0, stop=stop)
    thread = threading.Thread(target=watcher.run, name="test-watch", daemon=True)
    try:
        thread.start()
        assert wait_for(lambda: watcher.answers >= 1 and server.watcher_count() == 1)  # between two questions
        crowd: list[LineClient] = []
        for _ in range(LOOPBACK_ONLY.max_per_address):  # one too many: with the watch, over the cap
            crowd.append(LineClient(server.address))
            clients.append(crowd[-1])
            assert crowd[-1].read_line() == GREETING and crowd[-1].ask("WATCH") == "OK"
            station.run(0.2)  # each subscribed a little later than the one before
        assert _closed(crowd[0]) and server.stats.evicted == 1  # the last one took the first one's place
        crowd.pop(0)
        answers = watcher.answers

        def polled_again() -> bool:  # the station's clock moves on until the watch has asked twice more
            station.run(0.25)
            return watcher.answers >= answers + 2

        assert wait_for(polled_again)
        for k in range(3):
            assert _status(server).startswith("satellite="), k
            assert _closed(crowd[k])
            crowd.append(LineClient(server.address))  # the crowd fills the room again
            clients.append(crowd[-1])
            assert crowd[-1].read_line() == GREETING and crowd[-1].ask("WATCH") == "OK"
        assert wait_for(polled_again)
        assert [u for u in updates if not u.connected] == [] and server.stats.evicted == 4
    finally:
        stop.set()
        station.clock.advance(10.0)
        thread.join(5.0)
