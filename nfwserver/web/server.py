"""The web dashboard's listener: :class:`WebServer`, one more adapter on the station core.

Threads and what they do:

- the publisher thread only runs :meth:`WebServer.on_tick`: it keeps a reference to the newest sample
  and sets an event, at a cost that does not depend on the number of browsers;
- ``nfw-web`` (the frame thread) wakes on that event and, while at least one page is connected (an
  event stream is open), builds one frame (JSON) from the live state
  (:mod:`~nfwserver.web.state_view`, :mod:`~nfwserver.web.station_parts`) at most
  :data:`MAX_FRAME_HZ` times a second, and puts it in the :class:`~nfwserver.web.hub.FrameHub`; with no
  page connected it builds none (``/api/state`` then builds its own).  A frame that fails to build is
  logged once a minute and replaced in the hub by ``{"frame_error": ...}``, so no page shows itself live
  on a frame that no longer changes;
- ``nfw-web-http`` accepts connections (Python's :class:`http.server.ThreadingHTTPServer`); each
  connection has a thread of its own, at most ``max_clients`` at once (others are closed at once);
  an event-stream connection sends the hub's newest frame whenever there is one (Server-Sent Events),
  with the log lines that page has not been sent (:class:`~nfwserver.web.station_parts.LogCursor`);
- ``nfw-web-passes``: :class:`~nfwserver.web.pass_board.PassBoard`.

Bounds: every socket has a timeout (``io_timeout_s``): a browser that stops reading blocks only its
own thread, for at most that long, and is then dropped (``stats.dropped``); there is no queue, so it
never costs memory beyond its socket buffer, and no tick ever waits for it.  A request head must arrive
whole within ``head_deadline_s`` and :data:`~nfwserver.web.request_head.MAX_HEAD_BYTES`
(:mod:`~nfwserver.web.request_head`).  At most ``max_clients`` connections at once, at most
``max_per_address`` from one address, and at most ``max_streams`` event streams: a connection over a
cap is answered 503 naming the cap (without reading it) and closed.  Peers outside ``[web] allow`` are
closed before a byte is read.  Each kind of refusal is logged, and recorded in the event stream, once
per burst (a line a minute per address and kind, with the count of the others), so a flood never
pushes the operator's history off the page.
"""

from __future__ import annotations

import json
import logging
import socket
import sys
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import datetime
from http.server import ThreadingHTTPServer
from typing import Any

from nfwserver.config.schema import WebConfig
from nfwserver.core.events import Direction
from nfwserver.core.faces import CountsClients, CountsConversations
from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.easycomm.output import EasyCommOutput
from nfwserver.listen_errors import bind_failure
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.web.control import Control
from nfwserver.web.handler import WebHandler
from nfwserver.web.hub import FrameHub
from nfwserver.web.pass_board import PassBoard
from nfwserver.web.request_head import HEAD_DEADLINE_S, error_response
from nfwserver.web.state_view import now_tracking
from nfwserver.web.station_parts import (
    EventFollower,
    LogCursor,
    clients_part,
    links_part,
    radio_part,
    rotor_part,
)

log = logging.getLogger(__name__)

MAX_FRAME_HZ = 10.0  #: frames built per second at most, whatever the feed's rate
MAX_CLIENTS = 128  #: connections served at once (each event stream holds one)
MAX_PER_ADDRESS = 16  #: connections served at once from one address
MAX_STREAMS = 64  #: event streams at once (the other connections stay free for requests)
IO_TIMEOUT_S = 10.0  #: a read or write that waits longer drops the connection
HISTORY_EVENTS = 200  #: log lines a new page receives first


@dataclass
class StationParts:
    """The station's adapters the page shows (None when not configured); read, never driven."""

    rotor: RotorCoupling | None = None
    radio: RadioCoupling | None = None
    easycomm: EasyCommOutput | None = None
    tcp: CountsClients | None = None  #: NovaTcpServer
    nova: CountsConversations | None = None  #: NovaDdeService
    favourites: Callable[[], Sequence[int]] = field(default=lambda: ())


@dataclass
class WebStats:
    accepted: int = 0
    refused: int = 0  #: outside [web] allow, or over max_clients
    streams: int = 0  #: event streams open now
    dropped: int = 0  #: event streams dropped for not reading (write timeout) or a failed send
    frames: int = 0  #: frames built


class _HttpServer(ThreadingHTTPServer):
    daemon_threads = True
    allow_reuse_address = True
    request_queue_size = 64

    def __init__(self, address: tuple[Any, ...], web: WebServer, family: int) -> None:
        self.address_family = family
        self.web = web
        super().__init__(address, WebHandler)

    def verify_request(self, request: Any, client_address: Any) -> bool:
        return self.web._admit(request, client_address)

    def process_request_thread(self, request: Any, client_address: Any) -> None:
        try:
            super().process_request_thread(request, client_address)
        finally:
            self.web._release(client_address)

    def handle_error(self, request: Any, client_address: Any) -> None:
        """Whatever escaped a connection's handler: one rate-limited line, never a traceback on stderr."""
        self.web.connection_failed(str(client_address[0]), sys.exc_info()[1])


class WebServer:
    """See the module docstring.  Construction is pure; :meth:`start` binds (OSError when it cannot)."""

    def __init__(self, core: StationCore, config: WebConfig, parts: StationParts | None = None, *,
                 max_clients: int = MAX_CLIENTS, io_timeout_s: float = IO_TIMEOUT_S,
                 send_buffer_bytes: int | None = None, max_per_address: int = MAX_PER_ADDRESS,
                 max_streams: int = MAX_STREAMS, head_deadline_s: float = HEAD_DEADLINE_S) -> None:
        self.core = core
        self.config = config
        self.parts = parts or StationParts()
        self.max_clients = max_clients
        self.max_per_address = max_per_address
        self.max_streams = max_streams
        self.head_deadline_s = head_deadline_s  #: real seconds a request head may take to arrive
        self.io_timeout_s = io_timeout_s
        self.send_buffer_bytes = send_buffer_bytes
        self.stats = WebStats()
        self.hub = FrameHub()
        self.control = Control(core, config)
        self.board = PassBoard(core.state, core.clock, self.parts.favourites, self.parts.rotor)
        self.address: tuple[str, int] | None = None
        self._follower = EventFollower(core.events)
        self._latest: dict[str, object] = {}
        self._sample: TickSample | None = None
        self._ticked = threading.Event()
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._active = 0
        self._per_address: dict[str, int] = {}
        self._httpd: _HttpServer | None = None
        self._threads: list[threading.Thread] = []
        self._unsubscribe: Callable[[], None] | None = None
        self._refusals = RateLimitedLog(log, core.clock, 60.0)
        self._frame_log = RateLimitedLog(log, core.clock, 60.0)
        self._build_lock = threading.Lock()

    @property
    def url(self) -> str:
        assert self.address is not None
        host = self.address[0]
        return f"http://[{host}]:{self.address[1]}/" if ":" in host else f"http://{host}:{self.address[1]}/"

    # -- life cycle --------------------------------------------------------------------------------
    def start(self) -> None:
        if self._httpd is not None:
            return
        try:
            family, _, _, _, sockaddr = socket.getaddrinfo(self.config.host, self.config.port,
                                                           type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)[0]
            self._httpd = _HttpServer(sockaddr, self, family)
        except OSError as exc:
            raise bind_failure(exc, "web", self.config.host, self.config.port) from None
        # an AF_INET or AF_INET6 listener: its address starts with (host, port)
        self.address = self._httpd.server_address[:2]  # type: ignore[assignment]
        self._stop.clear()
        self.hub.reopen()
        self._unsubscribe = self.core.subscribe(self.on_tick)
        self.board.start()
        self._threads = [threading.Thread(target=self._frames, name="nfw-web", daemon=True),
                         threading.Thread(target=self._httpd.serve_forever, kwargs={"poll_interval": 0.25},
                                          name="nfw-web-http", daemon=True)]
        for thread in self._threads:
            thread.start()
        log.info("web dashboard on %s", self.url)

    def stop(self) -> None:
        if self._httpd is None:
            return
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        self._stop.set()
        self._ticked.set()
        self.hub.close()
        self._httpd.shutdown()
        self._httpd.server_close()
        for thread in self._threads:
            thread.join(5.0)
        self.board.stop()
        self._httpd = None

    # -- the publisher's side ----------------------------------------------------------------------
    def on_tick(self, sample: TickSample) -> None:
        """Tick listener (publisher thread): keep the newest sample and wake the frame thread; O(1)."""
        self._sample = sample
        self._ticked.set()

    # -- frames (thread nfw-web) -------------------------------------------------------------------
    def _frames(self) -> None:
        clock = self.core.clock
        framed: datetime | None = None  # the instant of the sample the last frame carried
        while not self._stop.is_set():
            clock.wait(self._ticked, 1.0)
            if self._stop.is_set():
                break
            sample = self._sample
            if sample is not None and framed is not None:
                # A feed faster than MAX_FRAME_HZ: frames carry the newest sample at that rate.  Measured
                # between the samples' own instants, not by the clock when the frame thread woke: a frame
                # thread that woke late must not hold back the next sample's frame (on a clock that then
                # stands still, for good).
                early = 1.0 / MAX_FRAME_HZ - (sample.time - framed).total_seconds()
                if early > 1e-6:
                    clock.wait(self._stop, early)
            self._ticked.clear()
            if self.stats.streams == 0:
                continue  # nobody to send it to: build nothing (a page that connects gets one at once)
            framed = self._safe_frame() or framed

    def _safe_frame(self) -> datetime | None:
        """:meth:`_build_frame`; a failure is logged (rate-limited) and put in the hub as a frame error."""
        try:
            framed = self._build_frame()
        except Exception as exc:  # the station carries on; the pages say they are not updated
            error = f"{type(exc).__name__}: {exc}"[:300]
            self._frame_log.log(logging.ERROR, "frame", "web: building a frame failed: %s", error, exc_info=True)
            self.hub.publish(json.dumps({"frame_error": f"the station's page is not updating: {error}"}).encode())
            return None
        self._frame_log.clear("frame")
        return framed

    def _build_frame(self) -> datetime | None:
        """Build and publish a frame of the newest sample; returns that sample's instant (None without one)."""
        with self._build_lock:
            return self._build_frame_locked()

    def _build_frame_locked(self) -> datetime | None:
        now = self.core.clock.now()
        sample = self._sample or self.core.tracker.last_sample
        self._follower.catch_up()  # the client list; log lines go to each page by its own cursor
        frame: dict[str, object] = {
            "now": now_tracking(self.core, sample, now),
            "next_event": self.board.next_event(sample.time if sample is not None else now),
            "rotor": rotor_part(self.parts.rotor),
            "radio": radio_part(self.parts.radio, self.core.state.doppler_on),
            "links": links_part(self.core.health),
            "clients": clients_part(self._follower, self._counts),
            "passes_version": self.board.version,
            "control": self.control.enabled,
        }
        self._latest = frame
        self.stats.frames += 1
        self.hub.publish(json.dumps(frame, allow_nan=False, default=str).encode())
        return sample.time if sample is not None else None

    def _counts(self) -> dict[str, object]:
        counts: dict[str, object] = {"web_streams": self.stats.streams}
        if self.parts.nova is not None:
            counts["dde_conversations"], counts["dde_advise_loops"] = self.parts.nova.client_count()
        if self.parts.tcp is not None:
            counts["tcp_clients"] = self.parts.tcp.client_count()
        if self.parts.easycomm is not None:
            counts["easycomm"] = "open" if self.parts.easycomm.connected else "closed"
        return counts

    # -- what the handler reads ------------------------------------------------------------------
    def state_json(self) -> bytes:
        """``/api/state``: the newest frame, with the last :data:`HISTORY_EVENTS` log lines."""
        if self.stats.streams == 0:  # no frame thread at work: this request's own, from the live state
            self._safe_frame()
        frame = dict(self._latest)
        frame["log"], frame["log_skipped"] = LogCursor(self.core.events).history(HISTORY_EVENTS), 0
        return json.dumps(frame, allow_nan=False, default=str).encode()

    def page_log(self) -> tuple[LogCursor, list[dict[str, object]]]:
        """A new page's place in the log, just past its history (the last :data:`HISTORY_EVENTS` lines):
        its stream sends the history, then each frame with the lines that page has not been sent."""
        cursor = LogCursor(self.core.events)
        return cursor, cursor.history(HISTORY_EVENTS)

    # -- connections (nfw-web-http and connection threads) ---------------------------------------
    def configure(self, config: WebConfig) -> None:
        """Take a changed ``[web]`` section while running: control, token and host names apply to the
        next request (an old token stops working at once); host, port and allow need a restart."""
        self.config = config
        self.control.config = config

    def _admit(self, request: Any, client_address: Any) -> bool:
        host = str(client_address[0])
        reason = None
        if not self.config.allows(host):
            reason = "not in [web] allow"
        with self._lock:
            if reason is None and self._active >= self.max_clients:
                reason = f"already {self.max_clients} connections (the web server's cap)"
            if reason is None and self._per_address.get(host, 0) >= self.max_per_address:
                reason = f"already {self.max_per_address} connections from {host} (the cap per address)"
            if reason is None:
                self._active += 1
                self._per_address[host] = self._per_address.get(host, 0) + 1
                self.stats.accepted += 1
                return True
            self.stats.refused += 1
        if reason != "not in [web] allow":  # a peer that is let in hears why it is turned away
            try:
                request.setblocking(False)
                request.send(error_response(503, f"connection refused: {reason}"))
            except OSError:
                pass
        self._note_refusal(host, "connection", f"web connection from {host} refused: {reason}",
                           f"connection refused: {reason}")
        return False

    def _release(self, client_address: Any) -> None:
        host = str(client_address[0])
        with self._lock:
            self._active -= 1
            left = self._per_address.get(host, 1) - 1
            if left > 0:
                self._per_address[host] = left
            else:
                self._per_address.pop(host, None)

    def _note_refusal(self, host: str, kind: str, line: str, event: str) -> None:
        """One log line and one event per burst of refusals of ``kind`` from ``host``."""
        if self._refusals.warning(f"{host}:{kind}", "%s", line):
            self.core.events.add(self.core.clock.now(), Direction.INFO, "note", event, client=f"web {host}",
                                 accepted=False)

    def request_refused(self, host: str, status: int, why: str) -> None:
        """A request answered ``status`` before its route (head too slow or too large, wrong Host, ...)."""
        with self._lock:
            self.stats.refused += 1
        self._note_refusal(host, f"http {status}", f"web request from {host} refused ({status}): {why}",
                           f"request refused ({status}): {why}")

    def connection_failed(self, host: str, exc: BaseException | None) -> None:
        """A connection that ended in an error of the peer's making (reset, timeout): one line per burst."""
        what = f"{type(exc).__name__}: {exc}" if exc is not None else "unknown error"
        self._refusals.log(logging.INFO, f"{host}:failed", "web connection from %s ended: %s", host, what[:200])

    def stream_opened(self, peer: str) -> str | None:
        """Count an event stream in; or why not (over :attr:`max_streams`)."""
        first = False
        with self._lock:
            if self.stats.streams >= self.max_streams:
                self.stats.refused += 1
                reason = f"already {self.max_streams} event streams (the web server's cap)"
            else:
                self.stats.streams += 1
                first, reason = self.stats.streams == 1, None
        if reason is None and first:
            self._safe_frame()  # frames were not built while no page was connected: a fresh one now
        if reason is not None:
            host = peer.removeprefix("web ")
            self._note_refusal(host, "stream", f"web event stream for {host} refused: {reason}",
                               f"event stream refused: {reason}")
            return reason
        log.debug("web page %s connected", peer)  # a page reconnecting every minute: 1,440 lines a day at INFO
        return None

    def stream_closed(self, peer: str, reason: str, dropped: bool) -> None:
        with self._lock:
            self.stats.streams -= 1
            if dropped:
                self.stats.dropped += 1
        (log.warning if dropped else log.debug)("web page %s disconnected: %s", peer, reason)

    @property
    def stopping(self) -> bool:
        return self._stop.is_set()
