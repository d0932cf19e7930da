"""Nova's TCP server (Setup/TCP in Nova for Windows) as an adapter on the station core.

One thread, ``nfw-tcp``, owns the listening socket and every connection: a :mod:`selectors` loop,
so many clients cost no thread each.  The loop waits in ``select`` until the next idle deadline;
:meth:`NovaTcpServer.stop` and new published strings wake it through a socket pair.

- Construction is pure; :meth:`NovaTcpServer.start` binds (raising :class:`OSError` when it cannot), ``stop``
  closes everything.  Port 0 binds any free port (see ``address``).
- A peer whose address is not in ``[tcp] allow`` is closed at once, before the greeting.  IPv4-mapped IPv6
  peers count as their IPv4 address everywhere (allow list, caps, rate limits).
- HTTP (a web page's request: a request line or a header line, :mod:`nfwserver.tcp.http_guard`) closes the
  connection at once: no line of that read, nor anything after it, is run (``tcp_http_closed`` in STATUS).
- Caps: ``[tcp] max_per_address`` per address, ``max_clients`` in all, with a reserve for the station's own
  addresses; a new connection over one closes the quietest connection it may displace, else gets one
  ``ERROR`` line and is closed (:mod:`nfwserver.tcp.admission`).  A connection that completes no line for
  ``idle_timeout_s`` is closed (a ``WATCH`` subscriber never is).
- Refusals (HTTP, allow list, commands) are counted always, logged once a minute per peer address (refusals.py).
- Out of file descriptors (EMFILE and kin), the listener rests for a back-off (0.1 s doubling to 5 s)
  instead of spinning: the ``tcp-accept`` link shows it in STATUS until a spare descriptor is found.
- Lines: :mod:`nfwserver.tcp.protocol`, split by :mod:`nfwserver.tcp.line_splitter` (CR, LF, CR LF
  or NUL; at most 1 KiB kept; longer lines refused).  The line ending a ``WATCH`` gets ``OK`` and is
  not executed (a client stopping the stream with ``QUIT`` meant "stop").
- The publisher thread only runs :meth:`NovaTcpServer.on_tick` (append to a bounded queue, wake the loop:
  a cost independent of the clients); the loop copies the string to each ``WATCH`` client's buffer.
- Output is bounded per client (``output_limit`` bytes, 64 KiB by default): a watching client whose
  buffer would grow past it has stopped reading and is dropped with one log line; it never delays
  the publisher or any other client.  A client that sends commands without reading the replies is
  not read any further once ``COMMAND_HIGH_WATER`` bytes of replies wait for it (TCP flow control
  then holds the sender back), so its memory stays bounded too.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import selectors
import socket
from collections import deque
from collections.abc import Callable

from nfwserver.config.schema import TcpConfig
from nfwserver.core.events import Direction
from nfwserver.core.sample import TickSample
from nfwserver.core.service_thread import ServiceThread
from nfwserver.core.station_core import StationCore
from nfwserver.health.link_health import Backoff
from nfwserver.listen_errors import bind_failure
from nfwserver.listen_socket import stream_listener
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.tcp.admission import admit, own_addresses, turn_away
from nfwserver.tcp.connection import Connection, ListenerRest, TcpStats, peer_label, prepare_socket
from nfwserver.tcp.http_guard import http_in
from nfwserver.tcp.line_splitter import MAX_LINE_BYTES
from nfwserver.tcp.protocol import GREETING, Action, NovaTcpProtocol, Reply, StatusFields
from nfwserver.tcp.refusals import PeerRefusals

log = logging.getLogger(__name__)

DEFAULT_OUTPUT_LIMIT = 64 * 1024  #: bytes waiting for one client before a watching client is dropped
COMMAND_HIGH_WATER = 16 * 1024  #: replies waiting before a client's further lines are left unread
MAX_CLIENTS = 256
#: accept() failures that mean "no descriptors or memory now": the listener rests instead of spinning
_RESOURCE_ERRNOS = frozenset({errno.EMFILE, errno.ENFILE, errno.ENOBUFS, errno.ENOMEM})
ACCEPT_BACKOFF = Backoff(0.1, 5.0)
RECV_BYTES = 4096
PUBLISHED_BACKLOG = 256  #: published strings waiting for the loop (it normally takes them at once)
CRLF = b"\r\n"


class NovaTcpServer(ServiceThread):
    """See the module docstring.  ``extra`` adds fields to ``STATUS``; ``send_buffer_bytes`` sets
    SO_SNDBUF on accepted sockets (None: the system's default)."""

    thread_name = "nfw-tcp"

    def __init__(self, core: StationCore, config: TcpConfig, extra: StatusFields | None = None, *,
                 output_limit: int = DEFAULT_OUTPUT_LIMIT, send_buffer_bytes: int | None = None,
                 max_clients: int | None = None) -> None:
        super().__init__()
        self.core = core
        self.config = config
        self.extra = extra
        self.protocol = NovaTcpProtocol(core, self._status_fields)
        self.output_limit = output_limit
        self.send_buffer_bytes = send_buffer_bytes
        self.max_clients = max_clients if max_clients is not None else config.max_clients
        self._rest = ListenerRest(core.health.link("tcp-accept", ACCEPT_BACKOFF))
        self.stats = TcpStats()
        self.address: tuple[str, int] | None = None
        self._clients: set[Connection] = set()
        self._watching: set[Connection] = set()
        self._published: deque[str] = deque(maxlen=PUBLISHED_BACKLOG)
        self._wake_pending = False
        self._selector: selectors.BaseSelector | None = None
        self._listener: socket.socket | None = None
        self._wake_r: socket.socket | None = None
        self._wake_w: socket.socket | None = None
        self._unsubscribe: Callable[[], None] | None = None
        self._refusals = RateLimitedLog(log, core.clock, 60.0)  #: the server's own troubles
        self._peers = PeerRefusals(core, log)  #: refused and HTTP-speaking peers, once a minute per address
        self._own = own_addresses(config.host)

    # -- what others read ------------------------------------------------------------------------
    def client_count(self) -> int:
        """Connected clients (the console shows it beside the DDE conversations)."""
        return len(self._clients)

    def watcher_count(self) -> int:
        return len(self._watching)

    def _status_fields(self) -> dict[str, object]:
        """STATUS's fields beyond the core's: ``extra``'s, then this server's refusal counts."""
        return {**(self.extra() if self.extra is not None else {}), **self.stats.status_fields()}

    def wake(self) -> None:
        """Let the loop look at the clock now (idle connections, the accept back-off): for a clock that
        does not run by itself."""
        self._ring()

    # -- life cycle --------------------------------------------------------------------------------
    def start(self) -> None:
        """Bind ``[tcp] host``/``port`` and serve on thread ``nfw-tcp``; OSError when it cannot bind."""
        if self.running:
            return
        try:
            listener = stream_listener(self.config.host, self.config.port)
        except OSError as exc:
            raise bind_failure(exc, "tcp", self.config.host, self.config.port) from None
        self._listener = listener
        self.address = listener.getsockname()[:2]
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._selector = selectors.DefaultSelector()
        self._selector.register(listener, selectors.EVENT_READ, "listen")
        self._selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        self._unsubscribe = self.core.subscribe(self.on_tick)
        super().start()
        log.info("Nova TCP server listening on %s port %d", *self.address)

    def stop(self) -> None:
        if not self.running:
            return
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        self._stop.set()
        self._ring()
        super().stop()
        for client in list(self._clients):
            self._close(client, "server stopping")
        for sock in (self._listener, self._wake_r, self._wake_w):
            if sock is not None:
                sock.close()
        if self._selector is not None:
            self._selector.close()
        self._listener = self._wake_r = self._wake_w = None
        self._selector = None

    # -- the publisher's side ----------------------------------------------------------------------
    def on_tick(self, sample: TickSample) -> None:
        """Tick listener (publisher thread): queue the published string for the watchers; O(1)."""
        if not sample.text or not self._watching:
            return
        if len(self._published) == PUBLISHED_BACKLOG:
            self.stats.lost += 1
        self._published.append(sample.text)
        if not self._wake_pending:
            self._wake_pending = True
            self._ring()

    def _ring(self) -> None:
        """Wake the select loop (a byte on its socket pair)."""
        try:
            if self._wake_w is not None:
                self._wake_w.send(b"\0")
        except OSError:  # full (the loop is awake anyway) or closing
            pass

    # -- the loop (thread nfw-tcp) -------------------------------------------------------------------
    def _run(self) -> None:
        assert self._selector is not None
        while not self._stop.is_set():
            try:
                ready = self._selector.select(self._next_timeout())
                self._check_clock()
                for key, mask in ready:
                    if key.data == "listen":
                        self._accept()
                    elif key.data == "wake":
                        self._drain_wake()
                    elif not key.data.closed:
                        self._service(key.data, mask)
                self._deliver()
            except Exception:  # keep serving whatever one connection did
                self._refusals.log(logging.ERROR, "loop", "TCP server loop failed; carrying on", exc_info=True)

    def _next_timeout(self) -> float | None:
        """Real seconds until something on the clock is due (an idle deadline, the end of the accept
        back-off), at least 50 ms; None when nothing is."""
        now = self.core.clock.monotonic()
        due = [c.last_line + self.config.idle_timeout_s for c in self._clients if not c.watching]
        if (resume_at := self._rest.resume_at()) is not None:
            due.append(resume_at)
        if not due:
            return None
        return min(max(min(due) - now, 0.05), 60.0)

    def _check_clock(self) -> None:
        """Close idle connections; put the listener back when its back-off has run out."""
        now = self.core.clock.monotonic()
        for client in [c for c in self._clients if not c.watching]:
            if now - client.last_line >= self.config.idle_timeout_s:
                self.stats.idle_closed += 1
                self._close(client, f"idle for {self.config.idle_timeout_s:g} s without a complete line")
        if self._selector is not None and self._listener is not None:
            self._rest.maybe_resume(self._selector, self._listener)

    def _drain_wake(self) -> None:
        # Drain first, then clear the flag: a tick that sets the flag and sends its byte during the drain
        # must not have its byte swallowed while the flag stays set (every later tick would skip the wake).
        try:
            while self._wake_r is not None and self._wake_r.recv(4096):
                pass
        except OSError:
            pass
        self._wake_pending = False

    def _accept(self) -> None:
        assert self._listener is not None and self._selector is not None
        for _ in range(64):
            try:
                sock, address = self._listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as exc:
                if exc.errno in _RESOURCE_ERRNOS:
                    if self._selector is not None:
                        self._rest.rest(self._selector, self._listener, exc)
                else:  # the peer gave up between connect and accept (ECONNABORTED ...): the next one
                    self._refusals.warning("accept", "TCP accept failed: %s", exc)
                return
            self._rest.health.succeeded()
            peer = peer_label(address)
            key = TcpConfig.peer_key(address[0])
            decision = admit(self.config, self._clients, self.max_clients, self._own, address[0],
                             self.core.clock.monotonic())
            if decision.victim is not None:  # over a cap: the quietest connection makes room (tcp.admission)
                self.stats.evicted += 1
                self._close(decision.victim, f"the quietest, closed to make room for {peer} under the connection "
                                             "caps")
            if decision.refusal is not None:
                self.stats.refused += 1  # counted and on record before the peer can see the close
                self._peers.record(key, peer, f"refused: {decision.refusal}")
                turn_away(sock, decision.line)
                continue
            prepare_socket(sock, self.send_buffer_bytes)
            client = Connection(sock, peer, key, self.core.clock.monotonic(), self.stats.accepted)
            self._clients.add(client)
            self._selector.register(sock, client.mask, client)
            self.stats.accepted += 1
            self._queue(client, GREETING.encode("ascii") + CRLF)
            self._pump(client)

    def _service(self, client: Connection, mask: int) -> None:
        if mask & selectors.EVENT_READ and not client.inbox and not client.eof:
            try:
                data = client.sock.recv(RECV_BYTES)
            except (BlockingIOError, InterruptedError):
                data = None
            except OSError as exc:
                self._close(client, f"receive failed: {exc}")
                return
            if data == b"":
                client.eof = True
            elif data:
                lines = client.splitter.feed(data)
                if (kind := http_in(lines)) is not None:  # a web page's request: nothing of it runs, not even the
                    # lines before it in this read
                    self.stats.http_closed += 1
                    self._peers.record(client.address, client.peer, f"closed: it sent {kind} (a web page's "
                                       "request?); Nova's TCP port does not speak HTTP")
                    self._close(client, f"sent {kind}", accepted=False)
                    return
                client.inbox.extend(lines)
        self._pump(client)

    def _handle_lines(self, client: Connection) -> None:
        while client.inbox and len(client.out) < COMMAND_HIGH_WATER and not client.closing:
            item = client.inbox.popleft()
            client.last_line = self.core.clock.monotonic()
            if not client.announced:  # on record from its first line: an HTTP flood leaves no connect events
                client.announce(self.core.events, self.core.clock.now())
            reply: Reply | None
            if client.watching:  # any line ends WATCH, and is not executed
                client.watching = False
                self._watching.discard(client)
                reply = Reply(("OK",))
            elif item is None:
                reply = self.protocol.too_long(MAX_LINE_BYTES)
            else:
                try:
                    reply = self.protocol.handle(item.decode("ascii", errors="replace"), client.peer,
                                                 rate_key=f"tcp {client.address}")
                    if reply is not None:  # a command (a blank line gets no reply): the client is doing something
                        client.commanded(client.last_line)
                except Exception:
                    self._refusals.log(logging.ERROR, f"failed:{client.address}", "TCP command from %s failed",
                                       client.peer, exc_info=True)
                    reply = Reply(("ERROR internal error",))
            if reply is None:
                continue
            self._queue(client, b"".join(line.encode("ascii", errors="replace") + CRLF for line in reply.lines))
            if reply.action is Action.WATCH:
                client.watching = True
                self._watching.add(client)
            elif reply.action is Action.QUIT:
                client.closing = True
                client.inbox.clear()

    def _queue(self, client: Connection, data: bytes) -> None:
        client.out += data
        if len(client.out) > self.stats.max_buffered:
            self.stats.max_buffered = len(client.out)

    def _send(self, client: Connection) -> bool:
        """Send what the socket takes now; False when the connection was closed."""
        while client.out:
            try:
                sent = client.sock.send(client.out)
            except (BlockingIOError, InterruptedError):
                break
            except OSError as exc:
                self._close(client, f"send failed: {exc}")
                return False
            del client.out[:sent]
        return True

    def _pump(self, client: Connection) -> None:
        """Send what waits, handle received lines while there is room, then choose what to wait for."""
        while not client.closed:
            if not self._send(client):
                return
            if client.inbox and len(client.out) < COMMAND_HIGH_WATER and not client.closing:
                self._handle_lines(client)
                continue
            break
        if not client.out and (client.closing or (client.eof and not client.inbox and not client.watching)):
            self._close(client, "QUIT" if client.closing else "closed by the client")
            return
        want = selectors.EVENT_WRITE if client.out else 0
        if not client.inbox and not client.closing and not client.eof:
            want |= selectors.EVENT_READ
        if want != client.mask and self._selector is not None:
            if not want:  # a watcher that shut its side, with nothing to send: wait for nothing
                self._selector.unregister(client.sock)
            elif not client.mask:
                self._selector.register(client.sock, want, client)
            else:
                self._selector.modify(client.sock, want, client)
            client.mask = want

    def _deliver(self) -> None:
        while self._published:
            try:
                text = self._published.popleft()
            except IndexError:
                break
            data = text.encode("ascii", errors="replace") + CRLF
            for client in list(self._watching):
                if len(client.out) + len(data) > self.output_limit:
                    self.stats.dropped += 1
                    log.warning("TCP client %s dropped: %d bytes wait for it, it has stopped reading",
                                client.peer, len(client.out))
                    self._close(client, "stopped reading", accepted=False)
                    continue
                self._queue(client, data)
                self._pump(client)
            self.stats.delivered += 1

    def _close(self, client: Connection, reason: str, accepted: bool | None = None) -> None:
        if client.closed:
            return
        client.closed = True
        self._clients.discard(client)
        self._watching.discard(client)
        if self._selector is not None:
            with contextlib.suppress(KeyError, ValueError):
                self._selector.unregister(client.sock)
        client.sock.close()
        client.out.clear()
        client.inbox.clear()
        if not client.announced:  # it never sent a line: only the counters (and refusals) keep it
            log.debug("TCP client %s closed before its first line: %s", client.peer, reason)
            return
        ordinary = reason in ("QUIT", "closed by the client", "server stopping")  # the event stream keeps them
        (log.debug if ordinary else log.info)("TCP client %s disconnected: %s", client.peer, reason)
        self.core.events.add(self.core.clock.now(), Direction.IN, "disconnect", reason, client=client.peer,
                             accepted=accepted)
