"""The device and diagnostic parts of a frame: rotor, radio, link health, clients and the string log.

Rotor and radio values are what their worker threads last recorded (plain attribute reads, as the
console and ``STATUS`` do); no device is ever asked from here.  Rotor angles are given twice: in the
rotor's own frame (``*_rotor``: KCT, elevation above 90 when flipped) and in the sky (``az``/``el``, for
the polar plot).  Clients and the log come from the station's event stream
(:class:`~nfwserver.core.events.EventLog`): :class:`EventFollower` (the frame thread's) keeps the last
state of each connected client (bounded; a client that disconnects leaves the list, its lines stay in the
log); each page's own :class:`LogCursor` (its event stream's thread's) remembers the last log line that
page was sent, and puts every newer line into the next frame the page is sent, so a page sees every
string once, however many frames it skips.
"""

from __future__ import annotations

import json
import logging
import math
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from nfwserver.core.events import Event, EventLog
from nfwserver.core.faces import CountsClients, CountsConversations
from nfwserver.easycomm.output import EasyCommOutput
from nfwserver.health.board import HealthBoard
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.rotor.coupling import RotorCoupling, sky_from_rotor
from nfwserver.web.state_view import iso

if TYPE_CHECKING:
    from nfwserver.autotrack.schedule import Schedule

log = logging.getLogger(__name__)


@dataclass
class StationParts:
    """The station's adapters the page shows (None when not configured); read, never driven."""

    rotor: RotorCoupling | None = None
    radio: RadioCoupling | None = None
    easycomm: EasyCommOutput | None = None
    tcp: CountsClients | None = None  #: NovaTcpServer
    nova: CountsConversations | None = None  #: NovaDdeService
    favourites: Callable[[], Sequence[int]] = field(default=lambda: ())
    #: autotrack's newest schedule (AutotrackRuntime.schedule), None without one: the page's timeline
    autotrack_schedule: Callable[[], Schedule | None] = field(default=lambda: None)

#: Log lines sent to a page in one frame at most (the rest go with its next frames); clients remembered at most.
MAX_LOG_PER_FRAME = 100
MAX_CLIENTS = 64


def _angle(value: float | None) -> float | None:
    return round(value, 2) if value is not None and math.isfinite(value) else None


def rotor_part(rotor: RotorCoupling | None) -> dict[str, object] | None:
    """Commanded (target) and actual positions, flip mode and state, link state, KCT status bits."""
    if rotor is None:
        return None
    driver = rotor.driver
    position = driver.rotor_position()
    _, _, target_el, target_az = driver.positions()
    out: dict[str, object] = {"flip_mode": rotor.flip_mode, "flipped": bool(rotor.flip_state),
                              "kct_status": f"0x{int(driver.status().bits):02X}"}
    out["state"] = driver.link_state()
    out["actual"] = None
    if position is not None and all(map(math.isfinite, position)):
        az, el = sky_from_rotor(position[0], position[1])
        out["actual"] = {"az": _angle(az), "el": _angle(el), "az_rotor": _angle(position[0]),
                         "el_rotor": _angle(position[1])}
    out["target"] = None
    if target_az is not None and target_el is not None and math.isfinite(target_az) and math.isfinite(target_el):
        az, el = sky_from_rotor(target_az, target_el)
        out["target"] = {"az": _angle(az), "el": _angle(el), "az_rotor": _angle(target_az),
                         "el_rotor": _angle(target_el)}
    return out


def radio_part(radio: RadioCoupling | None, doppler_on: bool) -> dict[str, object] | None:
    if radio is None:
        return None
    result = radio.current_result()  # none while the satellite has no channel: no other satellite's frequency
    state = radio.link_state()
    return {"state": state, "tuning": doppler_on, "error": None if state == "ok" else str(radio.tuner.last_error or ""),
            "rx_hz": result.rx_hz if result is not None else None,
            "tx_hz": result.tx_hz if result is not None and result.tx_hz else None}


def links_part(health: HealthBoard) -> dict[str, object]:
    """Every link's state (``ok`` or the fault's description) and the faults alone."""
    states = health.states()
    return {"states": states, "faults": {name: text for name, text in states.items() if text != "ok"}}


@dataclass
class ClientRecord:
    """The last seen of one client of the station (a DDE conversation, a TCP peer, a browser)."""

    name: str
    connected: bool
    last_kind: str
    last_text: str
    last_time: str | None
    accepted: bool | None

    def as_json(self) -> dict[str, object]:
        return {"name": self.name, "connected": self.connected, "last_kind": self.last_kind,
                "last_text": self.last_text, "last_time": self.last_time, "accepted": self.accepted}


def event_json(event: Event) -> dict[str, object]:
    return {"seq": event.seq, "time": iso(event.time), "dir": event.direction.value, "kind": event.kind,
            "text": event.text, "client": event.client, "accepted": event.accepted, "detail": event.detail}


class EventFollower:
    """Reads the event stream forward for the client list; owned by the frame thread."""

    def __init__(self, events: EventLog) -> None:
        self.events = events
        self.last_seq = 0
        self.clients: OrderedDict[str, ClientRecord] = OrderedDict()

    def catch_up(self) -> None:
        """Note the clients of every event added since the last call (that the ring still holds)."""
        fresh, _ = self.events.since(self.last_seq, len(self.events))
        for event in fresh:
            self._note_client(event)
        if fresh:
            self.last_seq = fresh[-1].seq

    def _note_client(self, event: Event) -> None:
        if not event.client or event.kind == "note" and event.client in ("config", "health", "startup"):
            return
        record = self.clients.pop(event.client, None)
        if event.kind == "disconnect":
            return  # a finished connection (every `nfwserver poke` is one) leaves the list; the log keeps it
        if record is None:
            record = ClientRecord(event.client, True, "", "", None, None)
        if event.kind == "connect":
            record.connected = True
        if event.kind != "connect" and event.kind != "disconnect" or not record.last_kind:
            record.last_kind, record.last_text = event.kind, event.text
            record.last_time, record.accepted = iso(event.time), event.accepted
        self.clients[event.client] = record
        while len(self.clients) > MAX_CLIENTS:
            self.clients.popitem(last=False)

    def client_list(self) -> list[dict[str, object]]:
        return [c.as_json() for c in reversed(self.clients.values())]


def clients_part(follower: EventFollower, counts: Callable[[], dict[str, object]]) -> dict[str, object]:
    """Counts from the adapters (DDE conversations and loops, TCP clients, browsers) and the client list."""
    try:
        numbers = counts()
    except Exception:  # an adapter's count must not stop the frame
        log.debug("web: client counts failed", exc_info=True)
        numbers = {}
    return {"counts": numbers, "list": follower.client_list()}


class LogCursor:
    """One page's place in the log: the seq of the last line it was sent; owned by its stream's thread.

    Frames are shared by every page and a page that reads slowly skips to the newest, so the frames
    themselves carry no log lines: :meth:`attach` adds to each frame a page is sent the lines that page
    has not been sent yet (read from the station's own bounded ring, nothing stored per page but one
    number).  Lines are sent oldest first, at most :data:`MAX_LOG_PER_FRAME` to a frame; a page more
    lines behind gets the rest with its next frames, and only lines the ring no longer holds (more than
    its capacity behind) are lost, counted in ``log_skipped``.
    """

    def __init__(self, events: EventLog) -> None:
        self.events = events
        self.last_seq = 0

    def history(self, count: int) -> list[dict[str, object]]:
        """The newest ``count`` lines, oldest first (the page's start); the cursor moves past them."""
        lines = self.events.recent(count)
        if lines:
            self.last_seq = lines[-1].seq
        return [event_json(e) for e in lines]

    def attach(self, frame: bytes) -> bytes:
        """``frame`` (a JSON object) with ``log``: the lines this page has not been sent (at most
        :data:`MAX_LOG_PER_FRAME`), and ``log_skipped``: those no longer in the ring; the cursor moves
        past them."""
        body = frame.strip()
        if not (body.startswith(b"{") and body.endswith(b"}")):
            raise ValueError("a frame must be a JSON object")
        lines, skipped = self.events.since(self.last_seq, MAX_LOG_PER_FRAME)
        if lines:
            self.last_seq = lines[-1].seq
        tail = json.dumps({"log": [event_json(e) for e in lines], "log_skipped": skipped},
                          allow_nan=False, default=str).encode()
        inner = body[1:-1].strip()
        return b"{" + inner + b", " + tail[1:] if inner else tail
