"""Who may connect to Nova's TCP server, and whom a newcomer displaces when a cap is reached.

The operator is never locked out of the TCP tools (``nfwserver status``, ``poke``, ``watch``), by another
address or by a crowd from the operator's own:

- **The station's own addresses** (:func:`own_addresses`: 127.0.0.1, ::1 and ``[tcp] host`` when it is not a
  wildcard -- the addresses the operator's tools connect from) hold a **reserve** of :func:`reserve_for`
  slots of ``max_clients`` that other addresses cannot take: once other addresses hold ``max_clients -
  reserve`` connections, a newcomer from another address displaces one of theirs (or is refused).  A
  connection from an own address is never closed to make room for another address, so the operator's
  ``nfwserver watch`` survives any crowd of other addresses.
- **Over a cap, the quietest connection goes**: the one that has done least lately -- its commands, each
  weighing half as much every minute (:meth:`~nfwserver.tcp.connection.Connection.activity`; none for one that
  never sent a command) -- and of equals the one quiet longest; among the newcomer's own
  connections when the per-address cap is reached, else among other addresses' connections (an own-address
  newcomer at the global cap takes another address's connection first, then its own quietest).  A blank line,
  a partial line, an over-long line or the line that ends a ``WATCH`` is not a command; a ``WATCH`` counts when
  it is sent, not while it streams.  So neither a crowd sending a blank line every half second nor a crowd of
  idle ``WATCH`` subscribers locks out ``nfwserver status``; and ``nfwserver watch``, which asks ``STATUS``
  every ``--interval`` (1 s) and holds a ``WATCH`` between, is the last of its address to be chosen: a burst
  of new connections that have sent nothing goes first, then ``WATCH`` subscribers that sent one command,
  the oldest first, while the watch's three commands a cycle keep its weight far above theirs.  A
  crowd that keeps sending real commands still loses its quietest member to each newcomer: a newcomer is
  always served.
- A newcomer is refused (one ``ERROR`` line, see :func:`admit`) only when there is nobody it may displace:
  another address when own addresses hold every slot.  A peer outside ``[tcp] allow`` is closed without a word.
"""

from __future__ import annotations

import socket
from collections.abc import Collection, Iterable
from dataclasses import dataclass

from nfwserver.config.schema import TcpConfig
from nfwserver.tcp.client import WILDCARDS
from nfwserver.tcp.connection import Connection

__all__ = ["Admission", "OWN_RESERVE", "admit", "own_addresses", "reserve_for", "turn_away"]

#: Slots of ``max_clients`` kept for the station's own addresses (at most half the cap).
OWN_RESERVE = 8


@dataclass(frozen=True)
class Admission:
    """The decision for one newcomer: serve it (closing ``victim`` first when one is given), or refuse it."""

    victim: Connection | None = None  #: the connection to close first so that the newcomer fits
    refusal: str | None = None  #: why it is refused (for the log); None: served
    line: str | None = None  #: the line the refused peer is sent before the close; None: closed without a word


def own_addresses(host: str) -> frozenset[str]:
    """The addresses the station's own tools connect from when it listens on ``host`` (peer keys)."""
    own = {"127.0.0.1", "::1"}
    if host not in WILDCARDS:
        own.add(TcpConfig.peer_key(host))
    return frozenset(own)


def reserve_for(max_clients: int) -> int:
    """Slots only the station's own addresses may take: :data:`OWN_RESERVE`, at most half of ``max_clients``."""
    return min(OWN_RESERVE, max_clients // 2)


def _quietest(clients: Iterable[Connection], now: float) -> Connection | None:
    """The open connection that has done least for longest; None when there is none: the least
    :meth:`~nfwserver.tcp.connection.Connection.activity` (0 for one that never sent a command), then the oldest
    last command (or connect), then the one that came later (of two equally quiet, the established one stays)."""
    return min((c for c in clients if not c.closed), key=lambda c: (c.activity(now), c.last_active, -c.order),
               default=None)


def admit(config: TcpConfig, clients: Collection[Connection], max_clients: int, own: frozenset[str],
          address: str, now: float) -> Admission:
    """Serve or refuse a new connection from ``address`` (an IP address string) while ``clients`` are
    connected, at ``now`` (clock monotonic seconds), under ``[tcp] allow``/``max_per_address`` and
    ``max_clients`` (see the module docstring)."""
    key = TcpConfig.peer_key(address)
    if not config.allows(address):
        return Admission(refusal="not in [tcp] allow")
    same = [c for c in clients if c.address == key]
    if len(same) >= config.max_per_address:
        victim = _quietest(same, now)
        if victim is not None:
            return Admission(victim)
        return Admission(refusal=f"already {len(same)} connections from {key}",
                         line=f"ERROR too many connections from {key} (at most {config.max_per_address})")
    others = [c for c in clients if c.address not in own]
    if key in own:
        full = len(clients) >= max_clients
        victim = (_quietest(others, now) or _quietest(clients, now)) if full else None
    else:
        full = len(clients) >= max_clients or len(others) >= max_clients - reserve_for(max_clients)
        victim = _quietest(others, now) if full else None
    if full and victim is None:
        return Admission(refusal=f"already {len(clients)} clients",
                         line=f"ERROR the station serves {max_clients} connections at most; try again later")
    return Admission(victim)


def turn_away(sock: socket.socket, line: str | None) -> None:
    """Send a refused peer ``line`` (when given, without waiting) and close its socket."""
    if line is not None:
        try:
            sock.setblocking(False)
            sock.send(line.encode("ascii") + b"\r\n")
        except OSError:
            pass
    sock.close()
