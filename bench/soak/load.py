"""The soak's clients, each on a thread of the benchmark's process (not the station's): Nova TCP ``WATCH``
clients that time every line, one TCP client switching ``SAT=``, web event streams that reconnect, a ``STATUS``
poller that records the link states, and a 50 ms sleeper that shows when the machine itself held everyone.

Every thread stops when :attr:`Load.stop` is set; times are ``time.monotonic()`` seconds.
"""

from __future__ import annotations

import socket
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from nfwserver.tcp.greeting import GREETING
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
        self.status_failures = 0  #: STATUS samples that failed (each followed by a reconnection)
        self.status_failed: list[tuple[float, str]] = []  #: (when, why) of each failure (the first 1000)
        self._status_ok = False
        self.switches = 0
        self.switch_failures = 0
        self.sleeper_late_s = 0.0  #: the 50 ms sleeper's worst oversleep (the machine's own stalls)
        self._threads: list[threading.Thread] = []
        self._poller: threading.Thread | None = None

    @property
    def polling(self) -> bool:
        """Whether the STATUS poller's thread is alive."""
        return self._poller is not None and self._poller.is_alive()

    def start(self) -> None:
        targets: list[tuple[Callable[..., None], tuple[object, ...]]] = [(self._watch, (f,)) for f in self.feeds]
        targets += [(self._stream, (s, i)) for i, s in enumerate(self.streams)]
        targets += [(self._switch, ()), (self._poll_status, ()), (self._sleep, ())]
        for target, args in targets:
            thread = threading.Thread(target=target, args=args, daemon=True, name=f"soak{target.__name__}")
            thread.start()
            self._threads.append(thread)
        self._poller = self._threads[-2]

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
        them.  A sample that fails (no answer within the socket's timeout, the connection refused, evicted or
        closed, an answer that is not a STATUS line, anything else raised) is recorded in
        :attr:`status_failures`, said once per episode on stderr, and the poller reconnects and carries on."""
        while not self.stop.is_set():
            try:
                with self._connect_tcp() as sock, sock.makefile("rb") as reader:
                    greeting = reader.readline().decode("ascii", "replace").strip()
                    if greeting != GREETING:  # an admission refusal (one ERROR line), or a close
                        raise ConnectionError(f"greeted with {greeting[:120]!r}")
                    while not self.stop.wait(0.5):
                        sock.sendall(b"STATUS\r\n")
                        self._status_answer(reader.readline())
            except Exception as exc:  # noqa: BLE001 -- any failure is recorded and the poller carries on
                self._status_failed(exc)
                self.stop.wait(1.0)

    def _status_answer(self, raw: bytes) -> None:
        """Record one answer to ``STATUS``; raise when it is none (the connection closed) or not a STATUS line
        (an ``ERROR`` line, an answer out of step)."""
        if not raw:
            raise ConnectionError("closed by the station")
        line = raw.decode("ascii", "replace").strip()
        fields = parse_status(line)
        if "rotor" not in fields or "radio" not in fields:
            raise ValueError(f"not a STATUS line: {line[:120]!r}")
        self.links.append(LinkSample(time.monotonic(), fields["rotor"], fields["radio"], fields.get("faults", "-")))
        self._status_ok = True

    def _status_failed(self, exc: BaseException) -> None:
        """Count and keep a failed STATUS sample; the first of an episode (after an answer, or the first ever) is
        said on stderr."""
        now = time.monotonic()
        self.status_failures += 1
        reason = f"{type(exc).__name__}: {exc}"
        if len(self.status_failed) < 1000:
            self.status_failed.append((now, reason))
        if self._status_ok or self.status_failures == 1:
            self._status_ok = False
            print(f"  STATUS sample failed ({reason}); reconnecting", file=sys.stderr)

    def status_silence_s(self, now: float, since: float) -> float:
        """Seconds up to ``now`` since the last STATUS answer (or since ``since``, the start, when none came)."""
        return now - (self.links[-1].at if self.links else since)

    def _sleep(self) -> None:
        while not self.stop.is_set():
            before = time.monotonic()
            time.sleep(0.05)
            self.sleeper_late_s = max(self.sleeper_late_s, time.monotonic() - before - 0.05)
