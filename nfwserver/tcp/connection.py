"""One connection of Nova's TCP server and the server's counters (owned by the ``nfw-tcp`` thread)."""

from __future__ import annotations

import errno
import logging
import math
import os
import selectors
import socket
from collections import deque
from dataclasses import dataclass
from datetime import datetime
from typing import Any

from nfwserver.core.events import Direction, EventLog
from nfwserver.health.link_health import LinkHealth
from nfwserver.tcp.line_splitter import MAX_LINE_BYTES, LineSplitter

__all__ = ["Connection", "ListenerRest", "TcpStats", "peer_label", "prepare_socket"]

ACTIVITY_HALF_LIFE_S = 60.0  #: clock seconds in which a command's weight in Connection.activity halves
log = logging.getLogger("nfwserver.tcp.server")  #: the server's log: one name for everything the TCP face writes


@dataclass
class TcpStats:
    accepted: int = 0
    refused: int = 0  #: peers not allowed, or over a connection cap with no connection to close for them
    http_closed: int = 0  #: connections closed for speaking HTTP (a web page's request: cross-protocol)
    idle_closed: int = 0  #: connections closed for completing no line within the idle timeout
    evicted: int = 0  #: connections closed to make room for a new one under a cap (the quietest)
    dropped: int = 0  #: watching clients dropped for not reading
    lost: int = 0  #: published strings lost because the loop fell PUBLISHED_BACKLOG behind
    delivered: int = 0  #: published strings handed to the watchers
    max_buffered: int = 0  #: the most bytes ever waiting for one client

    def status_fields(self) -> dict[str, object]:
        """The counts STATUS shows: peers refused, closed for speaking HTTP, closed to make room."""
        return {"tcp_refused": self.refused, "tcp_http_closed": self.http_closed, "tcp_evicted": self.evicted}


class Connection:
    """One connection; owned by the ``nfw-tcp`` thread."""

    def __init__(self, sock: socket.socket, peer: str, address: str, now: float, order: int = 0) -> None:
        self.sock = sock
        self.peer = peer
        self.address = address  #: the peer's address, one key per host (TcpConfig.peer_key)
        self.last_line = now  #: clock monotonic seconds of the last complete line (or of the connect): idle timeout
        #: clock monotonic seconds of the last command it sent (or of the connect): a blank line, a partial or
        #: over-long line, or a line ending a WATCH is not one; a WATCH is one when it is sent, not while it lasts
        self.last_active = now
        self._activity = 0.0  #: commands sent, each weighing less as it ages (half-life ACTIVITY_HALF_LIFE_S)
        self.order = order  #: the server's count of accepted connections when this one came (breaks ties)
        self.splitter = LineSplitter(MAX_LINE_BYTES)
        self.inbox: deque[bytes | None] = deque()  # received lines not handled yet (one read's worth)
        self.out = bytearray()
        self.mask = selectors.EVENT_READ
        self.watching = False
        self.closing = False  # QUIT: close once the output is sent
        self.eof = False  # the client shut its side: answer what it sent, then close (unless watching)
        self.closed = False
        self.announced = False  #: its connect is on record (log and event stream): from its first line on


    def commanded(self, now: float) -> None:
        """It sent a command (a line answered; blank, over-long and WATCH-ending lines are not) at ``now``."""
        self._activity = self.activity(now) + 1.0
        self.last_active = now

    def activity(self, now: float) -> float:
        """How much it has done lately: its commands, each counting 1 when sent and half as much every
        :data:`ACTIVITY_HALF_LIFE_S` clock seconds after; 0 for one that never sent a command."""
        return self._activity * math.pow(0.5, max(0.0, now - self.last_active) / ACTIVITY_HALF_LIFE_S)

    def announce(self, events: EventLog, now: datetime) -> None:
        """Put its connect on record (log and event stream): done at its first line."""
        self.announced = True
        log.debug("TCP client %s connected", self.peer)  # a client reconnecting every minute: 1,440 lines a day
        events.add(now, Direction.IN, "connect", "TCP", client=self.peer, accepted=True)


def peer_label(address: tuple[Any, ...]) -> str:
    host, port = address[0], address[1]
    return f"tcp [{host}]:{port}" if ":" in host else f"tcp {host}:{port}"


def prepare_socket(sock: socket.socket, send_buffer_bytes: int | None) -> None:
    """An accepted socket made ready: non-blocking, no Nagle delay (one short line per reply), ``SO_SNDBUF``
    set when ``send_buffer_bytes`` is given."""
    sock.setblocking(False)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    if send_buffer_bytes:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, send_buffer_bytes)


class ListenerRest:
    """Out of descriptors or memory, the listener is set aside for a back-off instead of spinning on a socket
    it cannot accept; ``health`` (the ``tcp-accept`` link) shows it meanwhile.  At the end of the back-off a
    spare descriptor is looked for: found, the fault clears and the listener is back, whether or not a peer is
    waiting; not found, it rests again."""

    def __init__(self, health: LinkHealth) -> None:
        self.health = health
        self.resting = False
        self._descriptors = False  #: the rest is for want of descriptors (a spare one can be looked for)

    def rest(self, selector: selectors.BaseSelector, listener: socket.socket, exc: OSError) -> None:
        self.health.failed(f"cannot accept connections: {exc.strerror or exc}")
        self._descriptors = exc.errno in (errno.EMFILE, errno.ENFILE)
        if not self.resting:
            selector.unregister(listener)
            self.resting = True

    def resume_at(self) -> float | None:
        """Clock monotonic seconds when the resting listener is tried again; None when it is not resting."""
        fault = self.health.fault
        return fault.retry_at if self.resting and fault is not None else None

    def maybe_resume(self, selector: selectors.BaseSelector, listener: socket.socket) -> None:
        """At the end of the back-off: listen again.  Out of descriptors, a spare one found clears the fault
        at once; out of memory (which a spare descriptor does not prove over), the fault stays until a
        connection is accepted, so a shortage that lasts keeps growing the back-off instead of restarting it."""
        if not self.resting or not self.health.may_try():
            return
        if self._descriptors:
            try:
                os.close(os.dup(listener.fileno()))
            except OSError as exc:
                self.health.failed(f"cannot accept connections: {exc.strerror or exc}")
                return
            self.health.succeeded()
        selector.register(listener, selectors.EVENT_READ, "listen")
        self.resting = False
