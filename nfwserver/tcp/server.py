"""Nova's TCP server (Setup/TCP in Nova for Windows) as an adapter on the station core.

One thread, ``nfw-tcp``, owns the listening socket and every connection: a :mod:`selectors` loop,
so many clients cost no thread each.  The loop blocks in ``select`` without a timeout (nothing in
it is scheduled in time); :meth:`NovaTcpServer.stop` and new published strings wake it through a
socket pair.

- Construction is pure; :meth:`NovaTcpServer.start` binds (raising :class:`OSError` when it cannot)
  and :meth:`NovaTcpServer.stop` closes everything.  Port 0 binds any free port (see ``address``).
- A peer whose address is not in ``[tcp] allow`` is closed at once, before the greeting, and
  logged (once a minute per address at most) and recorded in the event stream.
- Lines and replies: :mod:`nfwserver.tcp.protocol`, split by :mod:`nfwserver.tcp.line_splitter`
  (CR, LF, CR LF or NUL; at most 1 KiB kept per client; longer lines refused).
- The publisher thread only runs :meth:`NovaTcpServer.on_tick`: it appends the published string to
  a bounded queue and wakes the loop, at a cost that does not depend on the number of clients.
  The loop then copies the string to each ``WATCH`` client's output buffer.
- Output is bounded per client (``output_limit`` bytes, 64 KiB by default): a watching client whose
  buffer would grow past it has stopped reading and is dropped with one log line; it never delays
  the publisher or any other client.  A client that sends commands without reading the replies is
  not read any further once ``COMMAND_HIGH_WATER`` bytes of replies wait for it (TCP flow control
  then holds the sender back), so its memory stays bounded too.
"""

from __future__ import annotations

import logging
import selectors
import socket
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from nfwserver.config.schema import TcpConfig
from nfwserver.core.events import Direction
from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.tcp.line_splitter import MAX_LINE_BYTES, LineSplitter
from nfwserver.tcp.protocol import GREETING, Action, NovaTcpProtocol, Reply, StatusFields

log = logging.getLogger(__name__)

DEFAULT_OUTPUT_LIMIT = 64 * 1024  #: bytes waiting for one client before a watching client is dropped
COMMAND_HIGH_WATER = 16 * 1024  #: replies waiting before a client's further lines are left unread
MAX_CLIENTS = 256
RECV_BYTES = 4096
PUBLISHED_BACKLOG = 256  #: published strings waiting for the loop (it normally takes them at once)
CRLF = b"\r\n"


@dataclass
class TcpStats:
    accepted: int = 0
    refused: int = 0  #: peers not allowed, or over the client limit
    dropped: int = 0  #: watching clients dropped for not reading
    lost: int = 0  #: published strings lost because the loop fell PUBLISHED_BACKLOG behind
    delivered: int = 0  #: published strings handed to the watchers
    max_buffered: int = 0  #: the most bytes ever waiting for one client


class _Client:
    """One connection; owned by the ``nfw-tcp`` thread."""

    def __init__(self, sock: socket.socket, peer: str) -> None:
        self.sock = sock
        self.peer = peer
        self.splitter = LineSplitter(MAX_LINE_BYTES)
        self.inbox: deque[bytes | None] = deque()  # received lines not handled yet (one read's worth)
        self.out = bytearray()
        self.mask = selectors.EVENT_READ
        self.watching = False
        self.closing = False  # QUIT: close once the output is sent
        self.eof = False  # the client shut its side: answer what it sent, then close (unless watching)
        self.closed = False


def _label(address: tuple) -> str:
    host, port = address[0], address[1]
    return f"tcp [{host}]:{port}" if ":" in host else f"tcp {host}:{port}"


class NovaTcpServer:
    """See the module docstring.  ``extra`` adds fields to ``STATUS``; ``send_buffer_bytes`` sets
    SO_SNDBUF on accepted sockets (None: the system's default)."""

    def __init__(self, core: StationCore, config: TcpConfig, extra: StatusFields | None = None, *,
                 output_limit: int = DEFAULT_OUTPUT_LIMIT, send_buffer_bytes: int | None = None,
                 max_clients: int = MAX_CLIENTS, set_flip: Callable[[str], None] | None = None) -> None:
        self.core = core
        self.config = config
        self.protocol = NovaTcpProtocol(core, extra, set_flip)
        self.output_limit = output_limit
        self.send_buffer_bytes = send_buffer_bytes
        self.max_clients = max_clients
        self.stats = TcpStats()
        self.address: tuple[str, int] | None = None
        self._clients: set[_Client] = set()
        self._watching: set[_Client] = set()
        self._published: deque[str] = deque(maxlen=PUBLISHED_BACKLOG)
        self._wake_pending = False
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._selector: selectors.BaseSelector | None = None
        self._listener: socket.socket | None = None
        self._wake_r: socket.socket | None = None
        self._wake_w: socket.socket | None = None
        self._unsubscribe: Callable[[], None] | None = None
        self._refusals = RateLimitedLog(log, core.clock, 60.0)

    # -- what others read ------------------------------------------------------------------------
    def client_count(self) -> int:
        """Connected clients (the console shows it beside the DDE conversations)."""
        return len(self._clients)

    def watcher_count(self) -> int:
        return len(self._watching)

    # -- life cycle --------------------------------------------------------------------------------
    def start(self) -> None:
        """Bind ``[tcp] host``/``port`` and serve on thread ``nfw-tcp``; OSError when it cannot bind."""
        if self._thread is not None:
            return
        family, _, _, _, sockaddr = socket.getaddrinfo(self.config.host, self.config.port, type=socket.SOCK_STREAM,
                                                       flags=socket.AI_PASSIVE)[0]
        listener = socket.socket(family, socket.SOCK_STREAM)
        try:
            listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            listener.bind(sockaddr)
            listener.listen(64)
            listener.setblocking(False)
        except OSError:
            listener.close()
            raise
        self._listener = listener
        self.address = listener.getsockname()[:2]
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._selector = selectors.DefaultSelector()
        self._selector.register(listener, selectors.EVENT_READ, "listen")
        self._selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        self._stop.clear()
        self._unsubscribe = self.core.subscribe(self.on_tick)
        self._thread = threading.Thread(target=self._run, name="nfw-tcp", daemon=True)
        self._thread.start()
        log.info("Nova TCP server listening on %s port %d", *self.address)

    def stop(self) -> None:
        if self._thread is None:
            return
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        self._stop.set()
        self._wake()
        self._thread.join(5.0)
        self._thread = None
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
            self._wake()

    def _wake(self) -> None:
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
                ready = self._selector.select()
                for key, mask in ready:
                    if key.data == "listen":
                        self._accept()
                    elif key.data == "wake":
                        self._drain_wake()
                    elif not key.data.closed:
                        self._service(key.data, mask)
                self._deliver()
            except Exception:  # keep serving whatever one connection did
                log.exception("TCP server loop failed; carrying on")

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
            except OSError as exc:  # e.g. out of file descriptors: try again on the next event
                self._refusals.warning("accept", "TCP accept failed: %s", exc)
                return
            peer = _label(address)
            reason = None
            if not self.config.allows(address[0]):
                reason = "not in [tcp] allow"
            elif len(self._clients) >= self.max_clients:
                reason = f"already {self.max_clients} clients"
            if reason is not None:
                sock.close()
                self._refusals.warning(address[0], "TCP connection from %s refused: %s", peer, reason)
                self.core.events.add(self.core.clock.now(), Direction.INFO, "note", f"connection refused: {reason}",
                                     client=peer, accepted=False)
                self.stats.refused += 1  # counted once it is on record (log and event stream)
                continue
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            if self.send_buffer_bytes:
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, self.send_buffer_bytes)
            client = _Client(sock, peer)
            self._clients.add(client)
            self._selector.register(sock, client.mask, client)
            self.stats.accepted += 1
            log.info("TCP client %s connected", peer)
            self.core.events.add(self.core.clock.now(), Direction.IN, "connect", "TCP", client=peer, accepted=True)
            self._queue(client, GREETING.encode("ascii") + CRLF)
            self._pump(client)

    def _service(self, client: _Client, mask: int) -> None:
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
                client.inbox.extend(client.splitter.feed(data))
        self._pump(client)

    def _handle_lines(self, client: _Client) -> None:
        while client.inbox and len(client.out) < COMMAND_HIGH_WATER and not client.closing:
            item = client.inbox.popleft()
            if client.watching:  # any line ends WATCH
                client.watching = False
                self._watching.discard(client)
            reply: Reply | None
            if item is None:
                reply = self.protocol.too_long(MAX_LINE_BYTES)
            else:
                try:
                    reply = self.protocol.handle(item.decode("ascii", errors="replace"), client.peer)
                except Exception:
                    log.exception("TCP command from %s failed", client.peer)
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

    def _queue(self, client: _Client, data: bytes) -> None:
        client.out += data
        if len(client.out) > self.stats.max_buffered:
            self.stats.max_buffered = len(client.out)

    def _send(self, client: _Client) -> bool:
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

    def _pump(self, client: _Client) -> None:
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

    def _close(self, client: _Client, reason: str, accepted: bool | None = None) -> None:
        if client.closed:
            return
        client.closed = True
        self._clients.discard(client)
        self._watching.discard(client)
        if self._selector is not None:
            try:
                self._selector.unregister(client.sock)
            except (KeyError, ValueError):
                pass
        client.sock.close()
        client.out.clear()
        client.inbox.clear()
        log.info("TCP client %s disconnected: %s", client.peer, reason)
        self.core.events.add(self.core.clock.now(), Direction.IN, "disconnect", reason, client=client.peer,
                             accepted=accepted)
