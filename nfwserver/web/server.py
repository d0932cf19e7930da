"""The web dashboard's listener: :class:`WebServer`, one more adapter on the station core.

Threads and what they do:

- the publisher thread only runs :meth:`WebServer.on_tick`: it keeps a reference to the newest sample
  and sets an event, at a cost that does not depend on the number of browsers;
- ``nfw-web`` (the frame thread) wakes on that event and, while an event stream is open, builds one frame
  (JSON) from the live state (:mod:`~nfwserver.web.state_view`, :mod:`~nfwserver.web.station_parts`) at most
  :data:`MAX_FRAME_HZ` times a second into the :class:`~nfwserver.web.hub.FrameHub` (with no page, none:
  ``/api/state`` builds its own).  A frame that fails to build is logged once a minute and replaced in the
  hub by ``{"frame_error": ...}``, so no page shows itself live on a frame that no longer changes;
- ``nfw-web-http`` accepts connections (Python's :class:`http.server.ThreadingHTTPServer`); each
  connection has a thread of its own, at most ``max_clients`` at once; an event stream sends the hub's newest
  frame whenever there is one (SSE), with the log lines that page lacks (:class:`~.station_parts.LogCursor`);
- ``nfw-web-passes``: :class:`~nfwserver.web.pass_board.PassBoard`.

Bounds: every socket has a timeout (``io_timeout_s``): a browser that stops reading blocks only its own thread,
that long at most, then is dropped (``stats.dropped``); no queue, so no memory beyond its socket buffer, and no
tick ever waits for it.  A request head must arrive
whole within ``head_deadline_s`` and :data:`~nfwserver.web.request_head.MAX_HEAD_BYTES`
(:mod:`~nfwserver.web.request_head`).  Connections are held by :class:`~nfwserver.web.admission.Admission`:
at a cap (``max_clients``, ``max_per_address``) the one that has done least for longest makes room, and
``own_reserve`` slots are kept for the station's own address; one that cannot be let in is answered 503
naming the cap.  At most ``max_streams`` event streams.  Peers outside ``[web] allow`` are closed before a
byte is read.  Refusals of every kind are logged, and recorded in the event stream, once a minute per peer
address (with the count of the others), so a flood never pushes the operator's history off the page.
"""

from __future__ import annotations

import json
import logging
import socket
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime
from http.server import ThreadingHTTPServer
from typing import Any

from nfwserver.config.schema import WebConfig
from nfwserver.core.events import Direction
from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.listen_errors import bind_failure
from nfwserver.listen_socket import claim_port
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.web.admission import OWN_RESERVE, Admission, Phase
from nfwserver.web.control import Control
from nfwserver.web.handler import WebHandler
from nfwserver.web.hub import FrameHub
from nfwserver.web.pass_board import PassBoard
from nfwserver.web.request_head import HEAD_DEADLINE_S, error_response
from nfwserver.web.state_view import now_tracking
from nfwserver.web.station_parts import (
    EventFollower,
    LogCursor,
    StationParts,
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
class WebStats:
    accepted: int = 0
    refused: int = 0  #: connections and requests refused (outside [web] allow, a cap, a check)
    streams: int = 0  #: event streams open now
    dropped: int = 0  #: event streams dropped for not reading (write timeout) or a failed send
    frames: int = 0  #: frames built
    evicted: int = 0  #: connections closed to make room for a newer one (web/admission.py)


class _HttpServer(ThreadingHTTPServer):
    daemon_threads = True
    allow_reuse_address = False  #: the port's options are nfwserver.listen_socket's (server_bind)
    request_queue_size = 64

    def __init__(self, address: tuple[Any, ...], web: WebServer, family: int) -> None:
        self.address_family = family
        self.web = web
        super().__init__(address, WebHandler)

    def server_bind(self) -> None:
        claim_port(self.socket)  # SO_EXCLUSIVEADDRUSE on Windows, SO_REUSEADDR on POSIX (nfwserver.listen_socket)
        super().server_bind()

    def verify_request(self, request: Any, client_address: Any) -> bool:
        return self.web._admit(request, client_address)

    def process_request_thread(self, request: Any, client_address: Any) -> None:
        try:
            super().process_request_thread(request, client_address)
        finally:
            self.web.admission.release(request)

    def handle_error(self, request: Any, client_address: Any) -> None:
        """Whatever escaped a connection's handler: one rate-limited line, never a traceback on stderr."""
        self.web.connection_failed(str(client_address[0]), sys.exc_info()[1])


class WebServer:
    """See the module docstring.  Construction is pure; :meth:`start` binds (OSError when it cannot)."""

    def __init__(self, core: StationCore, config: WebConfig, parts: StationParts | None = None, *,
                 max_clients: int = MAX_CLIENTS, io_timeout_s: float = IO_TIMEOUT_S,
                 send_buffer_bytes: int | None = None, max_per_address: int = MAX_PER_ADDRESS,
                 max_streams: int = MAX_STREAMS, head_deadline_s: float = HEAD_DEADLINE_S,
                 own_reserve: int = OWN_RESERVE) -> None:
        self.core = core
        self.config = config
        self.parts = parts or StationParts()
        self.max_clients = max_clients
        self.max_per_address = max_per_address
        self.max_streams = max_streams
        self.own_reserve = own_reserve  #: connections only the station's own address may use
        self.head_deadline_s = head_deadline_s  #: real seconds a request head may take to arrive
        self.io_timeout_s = io_timeout_s
        self.send_buffer_bytes = send_buffer_bytes
        self.stats = WebStats()
        self.hub = FrameHub()
        #: refusals of every kind: a line (and an event) a minute per peer address, whatever the request says
        self._refusals = RateLimitedLog(log, core.clock, 60.0)
        self.control = Control(core, config, self.command_refused)
        self.admission = Admission(max_clients, max_per_address, own_reserve)
        self.board = PassBoard(core.state, core.clock, self.parts.favourites, self.parts.rotor,
                               self.parts.autotrack_schedule)
        self.address: tuple[str, int] | None = None
        self._follower = EventFollower(core.events)
        self._latest: dict[str, object] = {}
        self._sample: TickSample | None = None
        self._ticked = threading.Event()
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._httpd: _HttpServer | None = None
        self._threads: list[threading.Thread] = []
        self._unsubscribe: Callable[[], None] | None = None
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
        verdict = None
        if self.config.allows(host):
            verdict = self.admission.admit(request, host, str(request.getsockname()[0]))
        reason = "not in [web] allow" if verdict is None else verdict.reason
        with self._lock:
            if reason is None:
                self.stats.accepted += 1
            else:
                self.stats.refused += 1
        if verdict is not None and verdict.evicted is not None:
            gone = verdict.evicted
            with self._lock:
                self.stats.evicted += 1
            if gone.phase is Phase.STREAM:
                self.hub.wake()  # its thread, waiting for a frame, sees at once that it was taken
            self._note_refusal(gone.host, f"web connection from {gone.host} closed ({gone.phase.value} for "
                               f"{time.monotonic() - gone.since:.1f} s) to make room for one from {host}",
                               "connection closed to make room for another (it had done least for longest)")
        if reason is None:
            return True
        if verdict is not None:  # a peer that is let in hears why it is turned away
            try:
                request.setblocking(False)
                request.send(error_response(503, f"connection refused: {reason}"))
            except OSError:
                pass
        self._note_refusal(host, f"web connection from {host} refused: {reason}", f"connection refused: {reason}")
        return False

    def _note_refusal(self, host: str, line: str, event: str | None = None) -> bool:
        """One log line and one event a minute per peer address (``host``), for refusals of any kind: what
        varies from one request to the next (Origin, Host, token, path) is the peer's choice, so it does not
        make another line.  The line after a quiet minute carries the count of those left out.  True when
        this one was written (``event``, when given, is then recorded as a note)."""
        if not self._refusals.warning(host, "%s", line):
            return False
        if event is None:
            return True
        self.core.events.add(self.core.clock.now(), Direction.INFO, "note", event, client=f"web {host}",
                             accepted=False)
        return True

    def request_refused(self, host: str, status: int, why: str) -> None:
        """A request answered ``status`` before its route (head too slow or too large, wrong Host, ...)."""
        with self._lock:
            self.stats.refused += 1
        self._note_refusal(host, f"web request from {host} refused ({status}): {why}",
                           f"request refused ({status}): {why}")

    def command_refused(self, host: str, line: str) -> bool:
        """A command refused by :class:`~nfwserver.web.control.Control`: counted, and logged as every refusal;
        True when its line was written (the control then records its own event)."""
        with self._lock:
            self.stats.refused += 1
        return self._note_refusal(host, line)

    def connection_failed(self, host: str, exc: BaseException | None) -> None:
        """A connection that ended in an error of the peer's making (reset, timeout): one line per burst."""
        what = f"{type(exc).__name__}: {exc}" if exc is not None else "unknown error"
        self._refusals.log(logging.INFO, f"{host}:failed", "web connection from %s ended: %s", host, what[:200])

    def stream_opened(self, peer: str, sock: socket.socket | None = None) -> str | None:
        """Count an event stream in (on ``sock``); or why not (over :attr:`max_streams`, unless it is the station's
        own address's and another address's stream makes room for it)."""
        first = False
        with self._lock:
            full = self.stats.streams >= self.max_streams
        gone = self.admission.make_room_for_stream(sock) if full and sock is not None else None
        with self._lock:
            if gone is not None:
                self.stats.evicted += 1
            if self.stats.streams >= self.max_streams and gone is None:
                self.stats.refused += 1
                reason = f"already {self.max_streams} event streams (the web server's cap)"
            else:
                self.stats.streams += 1
                first, reason = self.stats.streams == 1, None
        if gone is not None:
            self.hub.wake()  # its thread, waiting for a frame, sees at once that it was taken
            self._note_refusal(gone.host, f"web event stream for {gone.host} closed to make room for the station's "
                               "own page", "event stream closed to make room for the station's own page")
        if reason is None and first:
            self._safe_frame()  # frames were not built while no page was connected: a fresh one now
        if reason is not None:
            host = peer.removeprefix("web ")
            self._note_refusal(host, f"web event stream for {host} refused: {reason}",
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
