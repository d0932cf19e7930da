"""Which connections the web face holds when its caps are reached: the operator is never locked out.

Every admitted connection has a :class:`Slot` with its peer's address, when it was taken in and what it is
doing (:class:`Phase`): still sending its request (``HEAD``: the request line, headers or body have not all
arrived; an idle connection that has sent nothing is one too), being answered (``BUSY``) or holding an event
stream (``STREAM``).  Three caps, and what happens at each:

- **per address** (``max_per_address``): a new connection from an address that already holds that many
  takes the place of that address's oldest connection still sending its request; without one it is refused;
- **the station's own reserve** (``own_reserve``): connections from the station's own address (loopback
  ``127.0.0.1`` or ``::1``, or the address the connection came in on, i.e. from the station's own machine)
  may use every slot; other addresses together at most ``max_clients - own_reserve``, so a crowd, however
  patient, always leaves the operator that many;
- **in all** (``max_clients``): a new connection takes the place of the oldest connection still sending
  its request, of another address first; one from the station's own address may also take the place of
  another address's event stream.  The station's own event streams and connections being answered are
  never taken, and another address never takes the station's own connections;
- **event streams** (the server's ``max_streams``): a stream for the station's own address ends another
  address's oldest stream (:meth:`Admission.make_room_for_stream`); others are refused.

"The oldest still sending its request" is the connection that has done least for longest: a slowloris that
trickles a byte every few seconds, a half request, or a browser's spare connection that sent nothing.  A
request that arrives whole is ``BUSY`` within a millisecond, so a well-behaved client is never the one
taken; a request head must in any case arrive within the head deadline
(:data:`~nfwserver.web.request_head.HEAD_DEADLINE_S`, as nginx's ``client_header_timeout``).  A connection
that is taken is shut down at once (its thread sees the end of the stream and closes it without an answer);
its slot is free before the new one is counted in.
"""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterable
from dataclasses import dataclass
from enum import Enum

from nfwserver.config.schema import plain_address

__all__ = ["OWN_RESERVE", "Admission", "Phase", "Slot", "Verdict"]

OWN_RESERVE = 16  #: slots only the station's own address may use
_LOOPBACK_OWN = frozenset({"127.0.0.1", "::1"})


class Phase(Enum):
    HEAD = "still sending its request"
    BUSY = "being answered"
    STREAM = "event stream"


@dataclass(eq=False)
class Slot:
    """One admitted connection."""

    sock: socket.socket
    host: str  #: the peer's address (an IPv4-mapped IPv6 address as IPv4)
    own: bool  #: from the station's own address
    since: float  #: :func:`time.monotonic` seconds when it was taken in
    phase: Phase = Phase.HEAD


@dataclass(frozen=True)
class Verdict:
    """What :meth:`Admission.admit` decided: the new slot, or why not; and the slot it took the place of."""

    slot: Slot | None
    reason: str | None = None
    evicted: Slot | None = None


def is_own(host: str, local: str) -> bool:
    """Whether a peer at ``host``, connected to ``local``, is the station's own machine."""
    return host in _LOOPBACK_OWN or host == plain_address(local)


class Admission:
    """The connection table of one web server; every method may be called from any thread."""

    def __init__(self, max_clients: int, max_per_address: int, own_reserve: int = OWN_RESERVE) -> None:
        self.max_clients = max_clients
        self.max_per_address = max_per_address
        self.own_reserve = min(own_reserve, max_clients)
        self.evicted = 0  #: connections taken for a newer one
        self._slots: dict[int, Slot] = {}
        self._lock = threading.Lock()

    @property
    def active(self) -> int:
        with self._lock:
            return len(self._slots)

    def admit(self, sock: socket.socket, peer: str, local: str) -> Verdict:
        """Take in ``sock`` from ``peer`` (connected to our ``local`` address), making room if a cap is reached."""
        host = plain_address(peer)
        own = is_own(host, local)
        with self._lock:
            victim: Slot | None = None
            mine = [s for s in self._slots.values() if s.host == host]
            if len(mine) >= self.max_per_address:
                victim = _oldest(s for s in mine if s.phase is Phase.HEAD)
                if victim is None:
                    return Verdict(None, f"already {self.max_per_address} connections from {host} (the cap per "
                                         "address), none of them idle")
                self._take(victim)
            else:
                others = sum(1 for s in self._slots.values() if not s.own)
                others_cap = self.max_clients - self.own_reserve
                if len(self._slots) >= self.max_clients or (not own and others >= others_cap):
                    victim = self._victim(own)
                    if victim is None:
                        why = (f"already {others_cap} connections from other addresses than the station's own "
                               f"({self.own_reserve} are reserved for it)" if not own and others >= others_cap
                               else f"already {self.max_clients} connections (the web server's cap)")
                        return Verdict(None, why)
                    self._take(victim)
            slot = Slot(sock, host, own, time.monotonic())
            self._slots[id(sock)] = slot
        return Verdict(slot, None, victim)

    def _victim(self, own: bool) -> Slot | None:
        """The slot a new connection takes the place of (see the module docstring), or None."""
        slots = list(self._slots.values())
        choices = [(s for s in slots if not s.own and s.phase is Phase.HEAD)]
        if own:
            choices += [(s for s in slots if s.own and s.phase is Phase.HEAD),
                        (s for s in slots if not s.own and s.phase is Phase.STREAM)]
        for candidates in choices:
            victim = _oldest(candidates)
            if victim is not None:
                return victim
        return None

    def make_room_for_stream(self, sock: socket.socket) -> Slot | None:
        """The event streams' own cap is reached and ``sock`` asks for one: when it comes from the station's own
        address, end another address's oldest event stream for it and return that slot; else None."""
        with self._lock:
            slot = self._slots.get(id(sock))
            if slot is None or slot.sock is not sock or not slot.own:
                return None
            victim = _oldest(s for s in self._slots.values() if not s.own and s.phase is Phase.STREAM)
            if victim is not None:
                self._take(victim)
            return victim

    def _take(self, victim: Slot) -> None:
        """Free ``victim``'s slot and end its connection (its own thread then finds it closed)."""
        del self._slots[id(victim.sock)]
        self.evicted += 1
        try:
            victim.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass

    def release(self, sock: socket.socket) -> None:
        """``sock``'s connection has ended (a slot already taken for another is not counted twice)."""
        with self._lock:
            slot = self._slots.get(id(sock))
            if slot is not None and slot.sock is sock:
                del self._slots[id(sock)]

    def holds(self, sock: socket.socket) -> bool:
        """Whether ``sock``'s connection still has its slot (False once taken for another, or released)."""
        with self._lock:
            slot = self._slots.get(id(sock))
            return slot is not None and slot.sock is sock

    def mark(self, sock: socket.socket, phase: Phase) -> None:
        """``sock``'s connection is now in ``phase``."""
        with self._lock:
            slot = self._slots.get(id(sock))
            if slot is not None and slot.sock is sock:
                slot.phase = phase


def _oldest(slots: Iterable[Slot]) -> Slot | None:
    return min(slots, key=lambda s: s.since, default=None)
