"""Nova's TCP face tried as an attacker would (issue 42 items 1, 3, 4, 5), against a real Station of its own.

Each family starts its own station (system clock, in-process DDE, TCP on a free 127.0.0.1 port open to
127.0.0.0/8, where 127.0.0.2-9 stand for other hosts), so that its crowds do not touch the main rig's watchers.

- :func:`run_cross_protocol`: web pages' requests (seeded: method, path, headers in any order, an ``Origin``
  that differs every time, the body Nova commands: ``SAT=``, ``TRACK OFF``, ``TUNE OFF``), each written in one
  to three pieces from one of 8 addresses.  Data lost: any reply besides the greeting, any change of the
  station's satellite, TUNE or TRACK, a request not counted in ``tcp_http_closed``; and, since the rule is
  one log line and one event a minute per address, more of them than 8 per started minute.
- :func:`run_lockout`: the operator's ``nfwserver status`` (its own client code, :func:`nfwserver.tcp.client.ask`,
  and once the real command in a process of its own) and ``nfwserver watch`` (:class:`StationWatcher`, on its
  own thread) under three crowds: 32 connections from 127.0.0.1 sending a blank line every 0.5 s; 32 ``WATCH``
  subscribers from 127.0.0.1; 32 connections from each of 127.0.0.2-9 (the global cap of 256) sending blank
  lines.  Every crowd refills itself after each question.  Data lost: a question not answered, a watch update
  that lost its connection.
"""

from __future__ import annotations

import contextlib
import logging
import random
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

from bench.campaign.fuzz_elements import SOURCE_SETS
from bench.campaign.station_rig import GREETING
from bench.campaign.tally import Tally
from nfwserver.app.station import Station
from nfwserver.cli.watch_command import StationWatcher
from nfwserver.cli.watch_view import WatchUpdate
from nfwserver.clock import SystemClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tcp.client import StationUnreachable, ask

ADDRESSES = [f"127.0.0.{k}" for k in range(2, 10)]
METHODS = ("POST", "GET", "PUT", "PATCH", "DELETE", "OPTIONS")
HEADERS = ("Content-Type: text/plain;charset=UTF-8", "User-Agent: Mozilla/5.0 (X11; Linux x86_64) Chrome/130",
           "Accept: */*", "Connection: keep-alive", "Sec-Fetch-Mode: no-cors", "Sec-Fetch-Site: cross-site",
           "Accept-Encoding: gzip, deflate, br", "Accept-Language: en-GB,en;q=0.9")


@contextlib.contextmanager
def attack_station(workdir: Path) -> Iterator[Station]:
    """A running station tracking the ISS, TUNE and TRACK on, its TCP port open to 127.0.0.0/8."""
    workdir.mkdir(parents=True, exist_ok=True)
    text = (f'[observer]\nlocation = "JO02ae"\n[elements]\nfiles = ["{SOURCE_SETS}"]\nuse_bundled = false\n'
            '[server]\nsatellite = 25544\ntune = true\ntrack = true\nstate_file = "none"\n'
            '[tcp]\nenabled = true\nport = 0\nallow = ["127.0.0.0/8"]\n')
    station = Station(parse_config(text, str(workdir / "attack.toml")), SystemClock(),
                      transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        yield station
    finally:
        station.stop()


class _Records(logging.Handler):
    """Counts the TCP server's warnings that name one of :data:`ADDRESSES`."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.count = 0

    def emit(self, record: logging.LogRecord) -> None:
        if any(f"{a}:" in record.getMessage() for a in ADDRESSES):
            self.count += 1


def _request(rng: random.Random, k: int, port: int, station_sat: int, other_sat: int) -> bytes:
    headers = [f"Host: 127.0.0.1:{port}", f"Origin: http://attacker{k}.example:{rng.randrange(1, 65536)}",
               *rng.sample(HEADERS, rng.randint(0, len(HEADERS)))]
    rng.shuffle(headers)
    body = rng.choice(("\r\n", "")) + "\r\n".join(rng.sample(
        [f"SAT={other_sat}", "TRACK OFF", "TUNE OFF", f"SAT={station_sat}", "QUIT", "STATUS"], 3)) + "\r\n"
    head = f"{rng.choice(METHODS)} /{rng.randrange(10**6)}?q={k} HTTP/1.{rng.randint(0, 1)}\r\n"
    return (head + "".join(h + "\r\n" for h in headers) + f"Content-Length: {len(body)}\r\n\r\n" + body).encode()


def _send_request(address: str, target: tuple[str, int], data: bytes, pieces: list[int]) -> bytes:
    """Everything the server sent back besides the greeting, until it closed the connection."""
    with socket.socket() as s:
        s.bind((address, 0))
        s.settimeout(5.0)
        s.connect(target)
        start = 0
        for cut in [*pieces, len(data)]:
            with contextlib.suppress(OSError):  # closed after the first piece: the rest is refused, as it must be
                s.sendall(data[start:cut])
            start = cut
        received = b""
        with contextlib.suppress(OSError):
            while chunk := s.recv(65536):
                received += chunk
    return received.removeprefix(GREETING)


def run_cross_protocol(tally: Tally, count: int, seed: int, workdir: Path) -> None:
    rng = random.Random(seed + 42)
    records = _Records()
    logging.getLogger("nfwserver.tcp.server").addHandler(records)
    started = time.monotonic()
    try:
        with attack_station(workdir / "cross-protocol") as station:
            tcp = station.tcp
            assert tcp is not None and tcp.address is not None
            other = next(s.catalog_number for s in station.catalog if s.catalog_number != 25544)
            before = station.core.state.snapshot()
            for k in range(count):
                tally.tried += 1
                data = _request(rng, k, tcp.address[1], 25544, other)
                pieces = sorted(rng.sample(range(1, len(data)), rng.randint(0, 2)))
                extra = _send_request(ADDRESSES[k % len(ADDRESSES)], tcp.address, data, pieces)
                if extra:
                    tally.loss(f"a request was answered: {extra[:80]!r}")
            after = station.core.state.snapshot()
            for name in ("catalog_number", "feed_on", "tracking"):
                if getattr(after, name) != getattr(before, name):
                    tally.loss(f"the requests changed {name}: {getattr(before, name)} -> {getattr(after, name)}")
            if tcp.stats.http_closed != count:
                tally.loss(f"{count - tcp.stats.http_closed} requests not counted as HTTP", 1)
            events = [e for e in station.core.events.recent() if any(f"{a}:" in (e.client or "") for a in ADDRESSES)]
    finally:
        logging.getLogger("nfwserver.tcp.server").removeHandler(records)
    allowed = len(ADDRESSES) * (int((time.monotonic() - started) // 60) + 1)
    if records.count > allowed or len(events) > allowed:
        tally.loss(f"{records.count} log lines and {len(events)} events for {count} requests (at most {allowed})")
    tally.extra.update({"requests (one to three writes each, 8 addresses)": count,
                        "closed as HTTP (tcp_http_closed)": tcp.stats.http_closed, "commands run from them": 0
                        if before.catalog_number == after.catalog_number else "some", "log lines": records.count,
                        "events": len(events)})


class _Crowd:
    """Connections from ``address`` that keep their number up and send what they are told to."""

    def __init__(self, target: tuple[str, int], address: str, size: int, watch: bool) -> None:
        self.target, self.address, self.size, self.watch = target, address, size, watch
        self.socks: list[socket.socket] = []
        self.fill()

    def _open(self) -> socket.socket:
        s = socket.socket()
        s.bind((self.address, 0))
        s.settimeout(5.0)
        s.connect(self.target)
        if self.watch:
            s.sendall(b"WATCH\r\n")
            received = b""
            while b"OK\r\n" not in received and (chunk := s.recv(4096)):
                received += chunk
        return s

    def fill(self) -> None:
        while len(self.socks) < self.size:
            try:
                self.socks.append(self._open())
            except OSError:  # refused or closed at once: try again next round
                return

    def talk(self, data: bytes) -> None:
        """Send ``data`` on every connection; those the server closed are dropped, then the crowd refills."""
        alive = []
        for s in self.socks:
            try:
                s.setblocking(False)
                with contextlib.suppress(BlockingIOError):
                    while s.recv(65536):  # drain what came (a WATCH stream); b"" means closed
                        pass
                    raise ConnectionResetError
                s.settimeout(5.0)
                if data:
                    s.sendall(data)
                alive.append(s)
            except OSError:
                s.close()
        self.socks = alive
        self.fill()

    def close(self) -> None:
        for s in self.socks:
            s.close()


def run_lockout(tally: Tally, rounds: int, workdir: Path) -> None:
    with attack_station(workdir / "lockout") as station:
        tcp = station.tcp
        assert tcp is not None and tcp.address is not None
        port = tcp.address[1]
        updates: list[WatchUpdate] = []
        stop = threading.Event()
        watcher = StationWatcher("127.0.0.1", port, updates.append, clock=SystemClock(), interval_s=1.0, stop=stop)
        thread = threading.Thread(target=watcher.run, name="campaign-operator-watch", daemon=True)
        thread.start()
        for _ in range(100):  # the operator's watch is running before the crowds come (at most 10 s)
            if watcher.answers:
                break
            time.sleep(0.1)
        watched = [e.client for e in station.core.events.recent() if e.kind == "connect"]
        scenarios = {"32 from 127.0.0.1, a blank line every 0.5 s": [("127.0.0.1", False)],
                     "32 WATCH from 127.0.0.1": [("127.0.0.1", True)],
                     "32 from each of 127.0.0.2-9 (the global cap), blank lines": [(a, False) for a in ADDRESSES]}
        try:
            for name, crowds in scenarios.items():
                evicted = tcp.stats.evicted
                groups = [_Crowd(tcp.address, address, 32, watch) for address, watch in crowds]
                served = 0
                for _ in range(rounds):
                    for group in groups:
                        group.talk(b"" if group.watch else b"\r\n")
                    time.sleep(0.5)
                    tally.tried += 1
                    try:
                        served += ask("127.0.0.1", port, "STATUS").startswith("satellite=")
                    except StationUnreachable as exc:
                        tally.loss(f"{name}: status failed: {exc}")
                cli = subprocess.run([sys.executable, "-m", "nfwserver", "status", "--host", "127.0.0.1",
                                      "--port", str(port)], capture_output=True, text=True, timeout=60)
                tally.tried += 1
                if cli.returncode != 0:
                    tally.loss(f"{name}: `nfwserver status` exit {cli.returncode}: {cli.stderr.strip()[:120]}")
                tally.extra[name] = (f"status answered {served} of {rounds}, `nfwserver status` exit "
                                     f"{cli.returncode}, {tcp.stats.evicted - evicted} closed to make room")
                for group in groups:
                    group.close()
        finally:
            stop.set()
            thread.join(5.0)
        lost = [u for u in updates if not u.connected]
        if lost:
            why = [e.text for e in station.core.events.recent() if e.kind == "disconnect"
                   and e.time <= lost[0].time and e.client == watched[0]][-1:] if watched else []
            tally.loss(f"`nfwserver watch` lost its connection {len(lost)} times: {lost[0].problem} {why}",
                       len(lost))
        tally.extra["`nfwserver watch` updates, disconnected"] = f"{watcher.answers}, {len(lost)}"
