"""One connection of Nova's TCP server and the server's counters (owned by the ``nfw-tcp`` thread)."""

from __future__ import annotations

import errno
import os
import selectors
import socket
from collections import deque
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from nfwserver.config.schema import TcpConfig
from nfwserver.health.link_health import LinkHealth
from nfwserver.tcp.line_splitter import MAX_LINE_BYTES, LineSplitter

__all__ = ["Connection", "ListenerRest", "TcpStats", "admission", "admission_refusal", "bind_listener",
           "idle_victim", "peer_label"]

#: A connection idle (no complete line) for at least this long (clock seconds) may be closed to make room.
EVICT_AFTER_S = 1.0


@dataclass
class TcpStats:
    accepted: int = 0
    refused: int = 0  #: peers not allowed, or over a connection cap
    idle_closed: int = 0  #: connections closed for completing no line within the idle timeout
    evicted: int = 0  #: idle connections closed to make room for a new one under a cap
    dropped: int = 0  #: watching clients dropped for not reading
    lost: int = 0  #: published strings lost because the loop fell PUBLISHED_BACKLOG behind
    delivered: int = 0  #: published strings handed to the watchers
    max_buffered: int = 0  #: the most bytes ever waiting for one client


class Connection:
    """One connection; owned by the ``nfw-tcp`` thread."""

    def __init__(self, sock: socket.socket, peer: str, address: str, now: float) -> None:
        self.sock = sock
        self.peer = peer
        self.address = address  #: the peer's address, one key per host (TcpConfig.peer_key)
        self.last_line = now  #: clock monotonic seconds of the last complete line (or of the connect)
        self.splitter = LineSplitter(MAX_LINE_BYTES)
        self.inbox: deque[bytes | None] = deque()  # received lines not handled yet (one read's worth)
        self.out = bytearray()
        self.mask = selectors.EVENT_READ
        self.watching = False
        self.closing = False  # QUIT: close once the output is sent
        self.eof = False  # the client shut its side: answer what it sent, then close (unless watching)
        self.closed = False


def admission(config: TcpConfig, per_address: Mapping[str, int], clients: Iterable[Connection], max_clients: int,
              address: str, now: float) -> tuple[tuple[str, str | None] | None, Connection | None]:
    """(why a new connection from ``address`` is refused, or None; a connection to close first so it fits, or
    None): over a cap, :func:`idle_victim` makes room when it finds one (see :func:`admission_refusal`)."""
    key = TcpConfig.peer_key(address)
    clients = list(clients)
    refusal = admission_refusal(config, per_address.get(key, 0), len(clients), max_clients, address)
    if refusal is None or refusal[1] is None:  # served, or not allowed at all
        return refusal, None
    victim = idle_victim(clients, key, per_address.get(key, 0) >= config.max_per_address, now)
    return (refusal, None) if victim is None else (None, victim)


def idle_victim(clients: Iterable[Connection], key: str, same_address: bool, now: float) -> Connection | None:
    """The connection to close so that a new one from ``key`` fits under a cap, or None: the one idle longest,
    for at least :data:`EVICT_AFTER_S`, never a ``WATCH`` subscriber; among ``key``'s own connections when the
    cap reached is the per-address one (``same_address``).  So idle connections never lock out a client that
    talks -- on the loopback default every local tool shares one address, the operator's ``status`` and
    ``poke`` included -- while a client that keeps talking keeps its connection."""
    idle = [c for c in clients if not c.watching and not c.closed and now - c.last_line >= EVICT_AFTER_S
            and (not same_address or c.address == key)]
    return min(idle, key=lambda c: c.last_line, default=None)


def peer_label(address: tuple[Any, ...]) -> str:
    host, port = address[0], address[1]
    return f"tcp [{host}]:{port}" if ":" in host else f"tcp {host}:{port}"



def admission_refusal(config: TcpConfig, from_address: int, connected: int, max_clients: int,
                      address: str) -> tuple[str, str | None] | None:
    """Why a new connection from ``address`` (already holding ``from_address`` of the ``connected``
    ones) is refused, as (log reason, line sent to the peer or None to close without a word); None to serve it."""
    key = TcpConfig.peer_key(address)
    if not config.allows(address):
        return "not in [tcp] allow", None
    if from_address >= config.max_per_address:
        return (f"already {from_address} connections from {key}",
                f"ERROR too many connections from {key} (at most {config.max_per_address})")
    if connected >= max_clients:
        return (f"already {max_clients} clients",
                f"ERROR the station serves {max_clients} connections at most; try again later")
    return None


def bind_listener(host: str, port: int) -> socket.socket:
    """A non-blocking listening socket on ``host``:``port`` (0: any free port); OSError when it cannot bind."""
    family, _, _, _, sockaddr = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)[0]
    listener = socket.socket(family, socket.SOCK_STREAM)
    try:
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        listener.bind(sockaddr)
        listener.listen(64)
        listener.setblocking(False)
    except OSError:
        listener.close()
        raise
    return listener


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
