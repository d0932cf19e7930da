"""Every log line reaches each page once, however many frames its event stream skips.

The hub keeps one frame, the newest: a stream's thread that is slow to take frames skips some.  Frames
once carried only the lines added since the previous frame, so a skipped frame's lines never reached
that page (the browser test ``test_a_connecting_page_shows_each_log_line_once`` lost one about one run
in five).  Each stream now adds to the frame it sends the lines its page has not been sent."""

from __future__ import annotations

import json
import select
import socket
import threading
from collections.abc import Callable

from nfwserver.clock import VirtualClock
from nfwserver.core.events import Direction
from nfwserver.web.hub import FrameHub
from tests.waiting import wait_for
from tests.web.web_helpers import connect, running_web


class _HeldReaderHub(FrameHub):
    """A hub whose readers are held before they take the next frame until :attr:`gate` is set: a stream
    thread slow to pick frames up, made deterministic."""

    def __init__(self) -> None:
        super().__init__()
        self.gate = threading.Event()
        self.waiting = threading.Event()

    def wait_newer(self, seen: int, timeout_s: float | None = None,
                   ended: Callable[[], bool] | None = None) -> tuple[int, bytes | None]:
        self.waiting.set()
        self.gate.wait(30.0)
        return super().wait_newer(seen, timeout_s, ended)


class _SseReader:
    """The events of a ``GET /api/stream`` answer on a real socket, read as they come (never blocking)."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.buffer = b""
        self.events: list[tuple[str, object]] = []  #: (event name, its data as JSON)

    def poll(self) -> list[tuple[str, object]]:
        while select.select([self.sock], [], [], 0)[0]:
            chunk = self.sock.recv(65536)
            if not chunk:
                break
            self.buffer += chunk
        *blocks, self.buffer = self.buffer.split(b"\n\n")
        for block in blocks:
            fields = dict(line.split(b": ", 1) for line in block.split(b"\n") if b": " in line)
            if b"event" in fields:
                self.events.append((fields[b"event"].decode(), json.loads(fields[b"data"])))
        return self.events

    def log_seqs(self) -> list[int]:
        """Every log line's seq as sent, in order: the history's, then each state frame's."""
        seqs: list[int] = []
        for name, data in self.events:
            lines = data if name == "history" else data.get("log", []) if isinstance(data, dict) else []
            seqs += [line["seq"] for line in lines]
        return seqs


def _as_page_shows(seqs: list[int]) -> list[int]:
    """What the page (app.js ``addLog``) shows of those: a line whose seq is not above the last shown is skipped."""
    shown: list[int] = []
    for seq in seqs:
        if not shown or seq > shown[-1]:
            shown.append(seq)
    return shown


def test_a_stream_that_skips_frames_is_sent_every_log_line_once() -> None:
    """Two frames, each with new log lines, published before the stream's thread takes one: it sends only
    the newest frame, and that frame must carry the lines of the one it skipped."""
    with running_web() as (core, web):
        clock = core.clock
        assert isinstance(clock, VirtualClock)
        hub = web.hub = _HeldReaderHub()
        try:
            with connect(web) as page:
                page.sendall(b"GET /api/stream HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n")
                wait_for(hub.waiting.is_set, what="the stream's thread, held before it takes its next frame")
                first = hub.seq
                for n in (1, 2):  # frames first+1 and first+2, while the reader is held
                    core.events.add(clock.now(), Direction.INFO, "note", f"line of frame {n}", client="test")
                    core.tick(clock.now())  # the frame thread frames this tick
                    wait_for(lambda n=n: hub.seq >= first + n, what=f"frame {n} with its lines")
                    clock.advance(0.2)
                expected = [e.seq for e in core.events.recent()]
                hub.gate.set()
                reader = _SseReader(page)
                wait_for(lambda: reader.poll() and any(seq >= expected[-1] for seq in reader.log_seqs()), 10.0,
                         lambda: f"the line {expected[-1]} on the page's stream; sent {reader.log_seqs()}")
                sent = reader.log_seqs()
                shown = [seq for seq in _as_page_shows(sent) if seq <= expected[-1]]
                assert shown == expected, f"lines missing from the page: {sorted(set(expected) - set(shown))}"
                assert len(sent) == len(set(sent)), f"lines sent twice: {sent}"
        finally:
            hub.gate.set()
