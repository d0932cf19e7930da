"""The soak's clients, each on a thread of the benchmark's process (not the station's): Nova TCP ``WATCH``
clients that time every line, one TCP client switching ``SAT=``, web event streams that reconnect, a ``STATUS``
poller that records the link states, and a 50 ms sleeper that shows when the machine itself held everyone.

Every thread stops when :attr:`Load.stop` is set; times are ``time.monotonic()`` seconds.
"""

from __future__ import annotations

import socket
import threading
import time
from dataclasses import dataclass, field

from nfwserver.tcp.status_line import parse_status

#: A feed gap longer than this (seconds) is counted as a stall as a client sees it.
GAP_S = 0.5


@dataclass
class FeedTimes:
    """Arrival times of one client's lines: the longest gap and the gaps over :data:`GAP_S`, kept as they come
    (constant memory: a two-hour run at 50 Hz is 360,000 lines)."""

    name: str
    lines: int = 0
    last: float | None = None
    longest_s: float = 0.0
    longest_at: float = 0.0
    gaps: list[tuple[float, float]] = field(default_factory=list)  #: (when, seconds) of each gap over GAP_S
    reconnects: int = 0

    def arrived(self, now: float) -> None:
        if self.last is not None:
            gap = now - self.last
            if gap > self.longest_s:
                self.longest_s, self.longest_at = gap, now
            if gap > GAP_S:
                self.gaps.append((now, gap))
        self.last = now
        self.lines += 1


@dataclass
class LinkSample:
    """One ``STATUS`` answer: when, the rotor's and radio's words and the failing links."""

    at: float
    rotor: str
    radio: str
    faults: str


class Load:
    """The clients of one soak against the station's TCP port ``tcp_port`` and web port ``web_port``."""

    def __init__(self, tcp_port: int, web_port: int, satellites: list[int], switch_s: float, web_reconnect_s: float,
                 watchers: int = 3, streams: int = 4) -> None:
        self.tcp_port, self.web_port = tcp_port, web_port
        self.satellites, self.switch_s, self.web_reconnect_s = satellites, switch_s, web_reconnect_s
        self.stop = threading.Event()
        self.feeds = [FeedTimes(f"tcp-{i + 1}") for i in range(watchers)]
        self.streams = [FeedTimes(f"web-{i + 1}") for i in range(streams)]
        self.links: list[LinkSample] = []
        self.switches = 0
        self.switch_failures = 0
        self.sleeper_late_s = 0.0  #: the 50 ms sleeper's worst oversleep (the machine's own stalls)
        self._threads: list[threading.Thread] = []

    def start(self) -> None:
        targets = [(self._watch, (f,)) for f in self.feeds] + [(self._stream, (s, i)) for i, s in
                                                              enumerate(self.streams)]
        targets += [(self._switch, ()), (self._poll_status, ()), (self._sleep, ())]
        for target, args in targets:
            thread = threading.Thread(target=target, args=args, daemon=True)
            thread.start()
            self._threads.append(thread)

    def join(self) -> None:
        self.stop.set()
        for thread in self._threads:
            thread.join(10.0)

    # -- clients ------------------------------------------------------------------------------
    def _connect_tcp(self) -> socket.socket:
        sock = socket.create_connection(("127.0.0.1", self.tcp_port), timeout=5.0)
        sock.settimeout(2.0)
        return sock

    def _watch(self, feed: FeedTimes) -> None:
        """A ``WATCH`` client: every line timed; reconnects if the station drops it."""
        while not self.stop.is_set():
            try:
                with self._connect_tcp() as sock:
                    sock.sendall(b"WATCH\r\n")
                    buffer = b""
                    skip = 2  # the greeting and WATCH's answer
                    while not self.stop.is_set():
                        try:
                            chunk = sock.recv(65536)
                        except TimeoutError:
                            continue
                        if not chunk:
                            break
                        now = time.monotonic()
                        buffer += chunk
                        *lines, buffer = buffer.split(b"\n")
                        for _ in lines:
                            if skip:
                                skip -= 1
                            else:
                                feed.arrived(now)
            except OSError:
                pass
            if not self.stop.is_set():
                feed.reconnects += 1
                feed.last = None
                self.stop.wait(1.0)

    def _stream(self, feed: FeedTimes, index: int) -> None:
        """A web page's event stream, reconnected every :attr:`web_reconnect_s` (its frames timed; the gap across
        a reconnection is not counted)."""
        while not self.stop.is_set():
            ends = time.monotonic() + self.web_reconnect_s
            feed.last = None
            try:
                with socket.create_connection(("127.0.0.1", self.web_port), timeout=5.0,
                                              source_address=(f"127.0.1.{index + 1}", 0)) as sock:
                    sock.sendall(f"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1:{self.web_port}\r\n\r\n".encode())
                    sock.settimeout(1.0)
                    buffer = b""
                    while not self.stop.is_set() and time.monotonic() < ends:
                        try:
                            chunk = sock.recv(1 << 20)
                        except TimeoutError:
                            continue
                        if not chunk:
                            break
                        now = time.monotonic()
                        buffer += chunk
                        *messages, buffer = buffer.split(b"\n\n")
                        for message in messages:
                            if message.startswith(b"event: state"):
                                feed.arrived(now)
            except OSError:
                self.stop.wait(1.0)
            feed.reconnects += 1

    def _switch(self) -> None:
        """``SAT=`` every :attr:`switch_s`, round the list of satellites."""
        k = 0
        while not self.stop.wait(self.switch_s):
            k += 1
            try:
                with self._connect_tcp() as sock:
                    sock.recv(1024)  # the greeting
                    sock.sendall(f"SAT={self.satellites[k % len(self.satellites)]}\r\n".encode())
                    answer = sock.recv(1024)
                self.switches += 1
                if not answer.startswith(b"OK"):
                    self.switch_failures += 1
            except OSError:
                self.switch_failures += 1

    def _poll_status(self) -> None:
        """``STATUS`` twice a second on one connection (reopened when lost): the link states as the station says
        them."""
        while not self.stop.is_set():
            try:
                with self._connect_tcp() as sock:
                    reader = sock.makefile("rb")
                    reader.readline()  # the greeting
                    while not self.stop.wait(0.5):
                        sock.sendall(b"STATUS\r\n")
                        fields = parse_status(reader.readline().decode("ascii", "replace"))
                        self.links.append(LinkSample(time.monotonic(), fields.get("rotor", "-"),
                                                     fields.get("radio", "-"), fields.get("faults", "-")))
            except OSError:
                self.stop.wait(1.0)

    def _sleep(self) -> None:
        while not self.stop.is_set():
            before = time.monotonic()
            time.sleep(0.05)
            self.sleeper_late_s = max(self.sleeper_late_s, time.monotonic() - before - 0.05)
