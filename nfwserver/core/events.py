"""The event stream: every string that goes in or out of the server, with time and conversation.

Nova showed incoming (F3) and outgoing (F1) strings for diagnosis; the console shows these events.
The log is bounded in count (a ring of ``capacity`` events) and in size: an event's ``text`` and
``detail`` keep at most :data:`MAX_EVENT_TEXT` characters, the rest replaced by a note of how many
were cut, so a flood of 1 MB pokes holds kilobytes, not gigabytes.  Each event is fanned out to
subscribers; a subscriber that raises is logged and dropped from that one delivery, never breaking
the server.  Texts are otherwise stored as received; :func:`nfwserver.core.nova_protocol.escape_for_log`
renders them safely.
"""

from __future__ import annotations

import enum
import itertools
import logging
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime

log = logging.getLogger(__name__)

#: Characters of an event's text (and detail) kept; Nova's strings and valid pokes are far shorter.
MAX_EVENT_TEXT = 512


def truncate_text(text: str, limit: int = MAX_EVENT_TEXT) -> str:
    """``text`` itself when short enough, else its first ``limit`` characters and a note of the rest."""
    if len(text) <= limit:
        return text
    return f"{text[:limit]}... [{len(text) - limit} more characters]"


class Direction(enum.Enum):
    IN = "in"  #: from a client (poke, execute, request, advise start/stop, connect)
    OUT = "out"  #: to clients (published string, request reply)
    INFO = "info"  #: server-side notes (satellite changed, errors)


@dataclass(frozen=True)
class Event:
    """One line of the diagnostic stream."""

    seq: int
    time: datetime  #: aware UTC, from the server's clock
    direction: Direction
    kind: str  #: "poke", "request", "advise", "publish", "connect", "disconnect", "execute", "note"
    text: str  #: the string itself (untrusted for IN events)
    conversation: int | None = None
    client: str = ""  #: who: "conv 3 on NFW32/NFW_DATA", "console", ...
    accepted: bool | None = None  #: for pokes/executes: acknowledged or refused
    detail: str = ""  #: e.g. the refusal reason, or the number of advise loops served


class EventLog:
    """Bounded, thread-safe event stream with subscribers."""

    def __init__(self, capacity: int = 5000) -> None:
        self._events: deque[Event] = deque(maxlen=capacity)
        self._subscribers: list[Callable[[Event], None]] = []
        self._lock = threading.Lock()
        self._seq = itertools.count(1)

    def add(self, time: datetime, direction: Direction, kind: str, text: str, **fields: object) -> Event:
        detail = fields.get("detail")
        if isinstance(detail, str):
            fields["detail"] = truncate_text(detail)
        text = truncate_text(text)
        with self._lock:  # numbered and stored in one step: the ring is always in seq order, without gaps
            # the keyword fields of Event (conversation, client, accepted, detail): Event checks them when called
            event = Event(next(self._seq), time, direction, kind, text, **fields)  # type: ignore[arg-type]
            self._events.append(event)
            subscribers = list(self._subscribers)
        for callback in subscribers:
            try:
                callback(event)
            except Exception:  # a broken subscriber must not break the server
                log.exception("event subscriber %r failed", callback)
        return event

    def subscribe(self, callback: Callable[[Event], None]) -> Callable[[], None]:
        """Call ``callback(event)`` for every new event; returns a function that unsubscribes."""
        with self._lock:
            self._subscribers.append(callback)

        def unsubscribe() -> None:
            with self._lock:
                if callback in self._subscribers:
                    self._subscribers.remove(callback)

        return unsubscribe

    def recent(self, count: int | None = None, direction: Direction | None = None) -> list[Event]:
        """The latest events, oldest first (optionally only one direction)."""
        with self._lock:
            events = list(self._events)
        if direction is not None:
            events = [e for e in events if e.direction is direction]
        return events if count is None else events[-count:]

    def since(self, after: int, limit: int) -> tuple[list[Event], int]:
        """The oldest ``limit`` events whose seq is above ``after``, oldest first, and how many events
        above ``after`` the ring no longer holds (pushed out by ``capacity`` newer ones).

        A reader that passes the seq of the last event it took each time takes every event once, however
        slowly it reads, as long as it is less than ``capacity`` events behind.  Costs O(events above
        ``after`` still held), not O(capacity), in C: the ring's seqs are consecutive, so how many events are
        newer is known from the newest one's."""
        with self._lock:
            if not self._events:
                return [], 0
            newest = self._events[-1].seq
            held = min(newest - after, len(self._events))  # events above ``after`` in the ring
            if held <= 0:
                return [], 0
            # walked from the newest end: the ``held`` newest, of which the oldest ``limit`` are taken
            picked = list(itertools.islice(reversed(self._events), max(0, held - max(0, limit)), held))
        picked.reverse()
        return picked, (newest - held + 1) - after - 1

    def __len__(self) -> int:
        return len(self._events)
