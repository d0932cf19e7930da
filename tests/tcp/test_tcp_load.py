"""Many clients, a stalled one and a hostile one on real loopback sockets: nobody disturbs anybody."""

from __future__ import annotations

import dataclasses
import random
import re
import selectors
import threading
import time

import numpy as np

from nfwserver.tcp.server import NovaTcpServer
from tests.dde.conftest import ISS, make_station
from tests.tcp.conftest import LOOPBACK_ONLY, LineClient
from tests.waiting import wait_for

#: these tests load one server from one address: the per-address cap is not what they look at
ONE_BUSY_ADDRESS = dataclasses.replace(LOOPBACK_ONLY, max_per_address=4096)


class Readers:
    """Reads many sockets on one thread until each has ``lines`` CR LF lines (or ``stop`` is set)."""

    def __init__(self, clients: list[LineClient]) -> None:
        self.clients = clients
        self.received = {id(c): b"" for c in clients}
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        sel = selectors.DefaultSelector()
        for c in self.clients:
            c.sock.setblocking(False)
            sel.register(c.sock, selectors.EVENT_READ, c)
        while not self.stop.is_set():
            for key, _ in sel.select(0.05):
                try:
                    chunk = key.fileobj.recv(65536)
                except BlockingIOError:
                    continue
                if not chunk:
                    sel.unregister(key.fileobj)
                self.received[id(key.data)] += chunk
        sel.close()

    def lines(self, client: LineClient) -> list[str]:
        return self.received[id(client)].decode("ascii").split("\r\n")[:-1]

    def count(self, client: LineClient) -> int:
        return self.received[id(client)].count(b"\r\n")

    def close(self) -> None:
        self.stop.set()
        self.thread.join(5)


def _watchers(server: NovaTcpServer, n: int) -> list[LineClient]:
    clients = [LineClient(server.address) for _ in range(n)]
    for c in clients:
        assert c.read_line() == b"Hello, this is Nova for Windows.\r\n"
        c.send(b"WATCH\r\n")
        assert c.read_line() == b"OK\r\n"
    return clients


def test_fifty_watchers_get_every_string_while_a_stalled_one_is_dropped(caplog) -> None:
    station = make_station(rate_hz=10.0)
    server = NovaTcpServer(station.core, ONE_BUSY_ADDRESS, output_limit=4096, send_buffer_bytes=4096)
    server.start()
    published: list[str] = []
    station.core.subscribe(lambda s: published.append(s.text))
    station.core.set_feed(True)
    try:
        watchers = _watchers(server, 50)
        stalled = LineClient(server.address, rcvbuf=2048)
        stalled.send(b"WATCH\r\n")  # and never reads again
        assert wait_for(lambda: server.watcher_count() == 51)
        readers = Readers(watchers)
        costs, dropped_at = [], None
        for k in range(1, 1001):  # at most 100 s of virtual time at 10 Hz
            station.clock.advance(0.1)
            started = time.perf_counter()
            station.core.tick()
            costs.append(time.perf_counter() - started)
            wait_for(lambda k=k: server.stats.delivered >= k, 5.0, f"string {k} to be delivered", interval_s=0.0001)
            assert server.stats.delivered == k
            if dropped_at is None and server.stats.dropped:
                dropped_at = k
            if dropped_at is not None and k >= dropped_at + 50:
                break
        assert dropped_at is not None, "the stalled client was never dropped"
        assert wait_for(lambda: all(readers.count(c) == len(published) for c in watchers), timeout_s=20.0)
        readers.close()
        assert all(readers.lines(c) == published for c in watchers)
        assert len(published) == k and all(p.startswith("ISS AZ:") for p in published)
        assert server.stats.dropped == 1 and server.client_count() == 50
        assert len([r for r in caplog.records if "dropped" in r.getMessage()]) == 1
        assert server.stats.lost == 0 and server.stats.max_buffered <= 4096
        # The publisher only queues the string: its tick costs the same as the computation alone.
        assert float(np.median(costs)) < 0.002
        for c in [*watchers, stalled]:
            c.close()
    finally:
        server.stop()


def _fuzz_items(rng: random.Random, n: int) -> list[bytes]:
    harmless = [b"SUMMARY", b"STATUS", b"summary", b"ANTAZ=12.5", b"ANTEL=-3", b"SAT=99999", b"TUNE", b"TRACK MAYBE"]
    ends = [b"\r", b"\n", b"\r\n", b"\x00"]
    out = []
    for _ in range(n):
        kind = rng.random()
        if kind < 0.3:
            body = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 200)))
        elif kind < 0.6:
            body = "".join(rng.choice("ABCDEFGHIJKLMNOPQRSTUVWXYZ =.-0123456789\t") for _ in range(rng.randrange(40)))
            body = body.encode()
        elif kind < 0.9:
            body = rng.choice(harmless)
        else:
            body = bytes([rng.randrange(32, 127)]) * rng.choice([1023, 1024, 1025, 3000, 70_000])
        out.append(body + rng.choice(ends))
    return out


def _expected_replies(stream: bytes) -> int:
    """An independent count: CR LF is one end, then CR, LF and NUL each end a line; blank lines (blanks,
    tabs, VT, FF and the separators 0x1C-0x1F only) get no reply, a line over 1024 bytes gets one refusal,
    every other line one reply."""
    lines = re.split(rb"[\r\n\x00]", stream.replace(b"\r\n", b"\n"))[:-1]
    return sum(1 for line in lines if len(line) > 1024 or line.strip(b" \t\x0b\x0c\x1c\x1d\x1e\x1f"))


def test_ten_thousand_hostile_lines_disturb_nobody() -> None:
    station = make_station()
    server = NovaTcpServer(station.core, ONE_BUSY_ADDRESS)
    server.start()
    station.core.set_feed(True)
    published: list[str] = []
    station.core.subscribe(lambda s: published.append(s.text))
    try:
        watcher = _watchers(server, 1)[0]
        hostile = LineClient(server.address)
        assert hostile.read_line().startswith(b"Hello")
        readers = Readers([watcher, hostile])
        items = _fuzz_items(random.Random(13), 10_000)
        stream = b"".join(items) + b"\n"
        for k in range(0, len(items), 500):
            hostile.sock.setblocking(True)
            hostile.sock.sendall(b"".join(items[k:k + 500]))
            station.run(0.0)  # one tick between bursts
        hostile.sock.sendall(b"\n")
        expected = _expected_replies(stream)
        assert wait_for(lambda: readers.count(hostile) == expected, timeout_s=60.0), (readers.count(hostile), expected)
        assert wait_for(lambda: readers.count(watcher) == len(published), timeout_s=10.0)
        assert readers.lines(watcher) == published and len(published) == 20
        readers.close()
        assert server.client_count() == 2  # the hostile client is still served, the watcher never noticed
        assert server.stats.max_buffered <= 64 * 1024
        polite = LineClient(server.address)
        assert polite.read_line().startswith(b"Hello")
        assert polite.ask("SUMMARY") == station.core.current_text() != ""
        assert station.core.state.snapshot().satellite.catalog_number == ISS
        for c in (watcher, hostile, polite):
            c.close()
    finally:
        server.stop()
