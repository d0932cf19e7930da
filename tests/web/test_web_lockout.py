"""The operator is never locked out of the dashboard: slow requests from other loopback addresses (127.0.0.2
to .9 play other hosts) or from the station's own address fill the caps, and the operator's request is still
answered at once, by evicting the connection that has done least for longest.  Real sockets, raw HTTP."""

from __future__ import annotations

import socket
import time

from tests.web.conftest import wait_for
from tests.web.test_web_bounds import GET_HELP, trickling
from tests.web.web_helpers import connect, exchange, read_all, running_web, status

OTHERS = tuple(f"127.0.0.{n}" for n in range(2, 10))


def _answered_at_once(web, source: str = "127.0.0.1") -> None:
    began = time.monotonic()
    reply = exchange(web, GET_HELP, source)
    assert status(reply) == 200, reply[:300]
    assert time.monotonic() - began < web.head_deadline_s / 2  # not by waiting for slow heads to time out


def _still_open(sock: socket.socket) -> bool:
    """Whether the server has not closed ``sock`` (what it sent so far is read and dropped)."""
    sock.settimeout(0.2)
    try:
        while sock.recv(65536):
            pass
    except TimeoutError:
        return True
    except OSError:
        return False
    return False


def test_slow_heads_from_eight_other_addresses_do_not_lock_the_operator_out() -> None:
    """Issue 42: 16 slow connections from each of 127.0.0.2-.9 filled the 128-connection cap, and 127.0.0.1
    got 503 on every check."""
    with running_web() as (_core, web):
        slow = [connect(web, source) for source in OTHERS for _ in range(web.max_per_address)]
        with trickling(slow, every_s=1.0):
            wait_for(lambda: web.stats.accepted >= len(slow), what="every slow connection taken in")
            for _ in range(5):
                _answered_at_once(web)
            _answered_at_once(web, "127.0.0.10")  # a phone on the network: the oldest slow head makes room
            assert web.stats.evicted >= 1


def test_slow_heads_from_the_operator_own_address_do_not_lock_it_out() -> None:
    """Issue 42: 16 slow connections from 127.0.0.1 itself locked the operator out through the cap per address."""
    with running_web() as (_core, web):
        slow = [connect(web, "127.0.0.1") for _ in range(web.max_per_address)]
        with trickling(slow, every_s=1.0):
            wait_for(lambda: web.stats.accepted >= len(slow), what="every slow connection taken in")
            for _ in range(5):
                _answered_at_once(web)
            evicted = read_all(slow[0])  # the oldest slow head made room: closed without an answer
            assert evicted == b"", evicted


def test_the_operator_event_streams_are_never_evicted_for_other_addresses() -> None:
    with running_web() as (_core, web):
        streams = [connect(web, "127.0.0.1") for _ in range(4)]
        for sock in streams:
            sock.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
        wait_for(lambda: web.stats.streams == 4, what="four streams")
        slow = [connect(web, source) for source in OTHERS for _ in range(2 * web.max_per_address)]
        with trickling(slow, every_s=1.0):
            wait_for(lambda: web.stats.accepted >= 4 + len(slow), what="every slow connection taken in")
            assert web.stats.evicted >= len(slow) - (web.max_clients - web.own_reserve)
            assert all(_still_open(sock) for sock in streams) and web.stats.streams == 4
            _answered_at_once(web)
        for sock in streams:
            sock.close()


def test_other_addresses_cannot_take_the_reserve_of_the_station_own_address() -> None:
    """Event streams are not evicted for another address, so they are what a crowd would hold on to."""
    with running_web(max_clients=8, own_reserve=2, max_per_address=4, max_streams=64) as (_core, web):
        held, answers = [], []
        for source in ("127.0.0.2", "127.0.0.3"):
            for _ in range(4):  # one after the other: each streaming (or refused) before the next asks
                sock = connect(web, source)
                sock.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
                sock.settimeout(5.0)
                answers.append(sock.recv(12))
                held.append(sock)
        assert answers == [b"HTTP/1.0 200"] * 6 + [b"HTTP/1.0 503"] * 2  # 8 - 2 reserved: two were refused
        assert web.stats.streams == 6
        third = exchange(web, GET_HELP, "127.0.0.4")
        assert status(third) == 503 and b"reserved" in third, third
        _answered_at_once(web)  # the reserve
        for sock in held:
            sock.close()


def test_other_addresses_event_streams_do_not_take_the_operator_page() -> None:
    """Event streams have their own cap (``max_streams``): a crowd that holds all of them made the operator's
    page answer 503 to its own event stream.  Now the station's own address takes the place of another
    address's oldest stream."""
    with running_web(max_streams=4) as (_core, web):
        crowd = [connect(web, "127.0.0.2") for _ in range(4)]
        for sock in crowd:
            sock.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
        for sock in crowd:  # each of them streaming
            sock.settimeout(5.0)
            assert sock.recv(12) == b"HTTP/1.0 200"
        mine = connect(web, "127.0.0.1")
        mine.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
        mine.settimeout(5.0)
        assert mine.recv(64).startswith(b"HTTP/1.0 200"), "the operator's event stream was refused"
        assert not _still_open(crowd[0])  # the oldest of the crowd's streams was ended
        wait_for(lambda: web.stats.streams == 4, what="the evicted stream counted out")
        assert all(_still_open(sock) for sock in crowd[1:])
        third = connect(web, "127.0.0.3")  # another address still meets the cap
        third.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
        assert status(read_all(third)) == 503
        for sock in (*crowd, mine, third):
            sock.close()


def test_another_site_page_cannot_hold_the_operator_event_streams() -> None:
    """A page of another site the operator visits may open the station's event stream (``fetch`` with
    ``no-cors`` reads on for ever): its connections come from 127.0.0.1, the station's own address, whose
    event streams are never taken, so a few such pages filled the 16 per address and locked the operator's
    page out.  The browser says where the request comes from (``Sec-Fetch-Site``); another site's is refused
    before it holds a stream."""
    with running_web() as (_core, web):
        for site in ("cross-site", "same-site"):
            reply = exchange(web, b"GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1\r\nSec-Fetch-Site: " +
                             site.encode() + b"\r\nSec-Fetch-Mode: no-cors\r\n\r\n")
            assert status(reply) == 403 and b"another site" in reply, reply[:300]
        assert web.stats.streams == 0
        own = connect(web)  # the station's own page (same-origin), and a tool that says nothing, still stream
        own.sendall(b"GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1\r\nSec-Fetch-Site: same-origin\r\n\r\n")
        tool = connect(web)
        tool.sendall(b"GET /api/stream HTTP/1.0\r\n\r\n")
        for sock in (own, tool):
            sock.settimeout(5.0)
            assert sock.recv(64).startswith(b"HTTP/1.0 200")
            sock.close()
