"""The DDE clients ``nfwserver simulate`` can play, each with its real transaction pattern.

Patterns (DESIGN.md §3, observed in public client source):

- ``hot``: a hot advise loop; prints the data pushed on every tick (the default).
- ``warm``: a warm advise loop; prints each notification (no data comes with it).
- ``wisp``: WiSP's DDE client: pokes ``TUNE ON``, requests every ``poll`` seconds (3 s by default)
  and pokes ``TUNE ON`` again whenever a reply lacks ``AH:``.  With ``poll`` 0 it does what WiSP
  does with interval 0: a warm link and a request per notification.
- ``delphi``: Delphi's ``TDdeClientConv``: a warm link, an immediate request, then a request per
  notification.
- ``ndde``: .NET NDde clients: a hot link and a request every second (``poll`` overrides).
- ``matlab``: ``ddeinit``/``ddepoke('TUNE ON')``/``ddereq``: a poke, then requests every ``poll``
  seconds (3 s by default).

Who pokes ``TUNE ON`` at the start is decided by the caller (:mod:`nfwserver.cli.simulate_command`):
it is one of the scheduled pokes.  A client reports each transaction through ``emit(kind, text)``,
kind being ``data``, ``notify``, ``reply`` or ``poke``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from nfwserver.dde.clipboard import CF_TEXT
from nfwserver.fake_dde import ClientConversation, DdeError, Received

CLIENTS = ("hot", "warm", "wisp", "delphi", "ndde", "matlab")
#: Request interval (s) of the polling clients when ``--poll`` is not given.
DEFAULT_POLL_S = {"wisp": 3.0, "ndde": 1.0, "matlab": 3.0}

Emit = Callable[[str, str], None]


@dataclass(frozen=True)
class Link:
    """A DDE address: ``SERVICE|TOPIC!ITEM``."""

    service: str
    topic: str
    item: str

    def __str__(self) -> str:
        return f"{self.service}|{self.topic}!{self.item}"


def parse_link(text: str) -> Link:
    """``SERVICE|TOPIC!ITEM`` -> :class:`Link`; ValueError with one sentence otherwise."""
    service, bar, rest = text.partition("|")
    topic, bang, item = rest.partition("!")
    if not (bar and bang and service.strip() and topic.strip() and item.strip()):
        raise ValueError(f"{text!r} is not SERVICE|TOPIC!ITEM (e.g. NFW32|NFW_DATA!NFW_SERVER)")
    return Link(service.strip(), topic.strip(), item.strip())


class SimulatedClient:
    """One client conversation playing ``kind``'s pattern; driven by :meth:`start` and :meth:`after_tick`."""

    def __init__(self, kind: str, conversation: ClientConversation, item: str, emit: Emit,
                 poll_s: float | None = None) -> None:
        if kind not in CLIENTS:
            raise ValueError(f"client must be one of {', '.join(CLIENTS)}")
        self.kind = kind
        self.conversation = conversation
        self.item = item
        self.emit = emit
        self.poll_s = poll_s if poll_s is not None else DEFAULT_POLL_S.get(kind)
        self._next_request: float | None = None
        conversation.on_receive = self._received

    @property
    def requests_per_notification(self) -> bool:
        return self.kind == "delphi" or (self.kind == "wisp" and self.poll_s == 0)

    def start(self) -> None:
        """Open the links the pattern uses (after the start-up pokes)."""
        if self.kind in ("hot", "ndde"):
            self.conversation.start_advise(self.item, CF_TEXT, hot=True)
        elif self.kind == "warm" or self.requests_per_notification:
            self.conversation.start_advise(self.item, CF_TEXT, hot=False)
        if self.kind == "delphi":
            self.request()
        if self.kind in ("wisp", "ndde", "matlab") and self.poll_s:
            self._next_request = 0.0

    def after_tick(self, offset_s: float) -> None:
        """Send the requests due by ``offset_s`` seconds into the run (once that tick is published)."""
        while self._next_request is not None and self._next_request <= offset_s + 1e-9:
            self.request()
            self._next_request += self.poll_s  # type: ignore[operator]  # set only when poll_s is (start)

    def poke(self, command: str) -> bool:
        """Poke ``command`` to the item; reported as a ``poke`` transaction."""
        try:
            self.conversation.poke(self.item, command)
        except DdeError:
            self.emit("poke", f"{command} (refused)")
            return False
        self.emit("poke", command)
        return True

    def request(self) -> None:
        try:
            text = self.conversation.request_text(self.item)
        except DdeError as exc:
            self.emit("reply", f"(refused: {exc})")
            return
        self.emit("reply", text)
        if self.kind == "wisp" and "AH:" not in text:
            self.poke("TUNE ON")  # WiSP re-pokes whenever a reply lacks AH:

    def _received(self, received: Received) -> None:
        if received.kind == "data" and received.data is not None:
            self.emit("data", received.text or "")
        elif received.kind == "notify":
            self.emit("notify", received.item)
            if self.requests_per_notification:
                self.request()
        elif received.kind == "disconnect":
            self.emit("disconnect", "the server ended the conversation")
