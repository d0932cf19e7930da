"""Nova for Windows' DDE interface as an adapter on the station core.

:class:`NovaDdeService` is a :class:`~nfwserver.dde.transport.DdeServerHandler`: attach it to a
transport (the in-process :mod:`nfwserver.fake_dde`, or the Windows DDEML transport) and it serves
the core's Nova string.  It keeps no station state of its own — only its conversations and advise
loops:

- requests and advise data answer :meth:`StationCore.current_text` (empty before ``TUNE ON``; a
  request on the item is never refused, since WiSP's poll has no error handler);
- every tick that published a string posts an advise on each served item;
- pokes and executes are Nova commands, handed to :meth:`StationCore.command`.

Names served (docs/COMPATIBILITY.md): services ``NFW32`` and ``NFW_SERVER``, topic ``NFW_DATA``, items
``NFW_SERVER`` and ``NFW_DATA``; compared case-insensitively; configurable.

Threading: transport callbacks arrive on the transport's thread, ticks on the publisher's.  The
adapter's own lock guards only its conversation tables, and the transport is never called while it
is held (the transport calls the handler with its own lock held: the lock order is transport -> adapter).
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable

from nfwserver.commands.table import Face
from nfwserver.core.events import Direction
from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.dde.clipboard import TEXT_FORMATS, decode_text, encode_text, format_name
from nfwserver.dde.transport import ConversationId, DdeServerTransport, PokeResult
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)

DEFAULT_SERVICES = ("NFW32", "NFW_SERVER")
DEFAULT_TOPIC = "NFW_DATA"
DEFAULT_ITEMS = ("NFW_SERVER", "NFW_DATA")


class NovaDdeService:
    """Serves the core's Nova string over DDE; see the module docstring."""

    def __init__(self, core: StationCore, *, services: Iterable[str] = DEFAULT_SERVICES,
                 topic: str = DEFAULT_TOPIC, items: Iterable[str] = DEFAULT_ITEMS) -> None:
        self.core = core
        self.services = tuple(services)
        self.topic = topic
        self.items = tuple(items)
        self._item_keys = {i.upper() for i in self.items}
        self._service_keys = {s.upper() for s in self.services}
        self._lock = threading.Lock()
        self._conversations: dict[ConversationId, str] = {}
        self._loops: set[tuple[ConversationId, str, int]] = set()
        self._transports: list[DdeServerTransport] = []
        self._post_failures = RateLimitedLog(log, core.clock, 60.0)  #: per tick: one line, then a count a minute
        self._encoded: tuple[str, dict[int, bytes]] = ("", {})
        self._unsubscribe: Callable[[], None] | None = None

    # -- life cycle --------------------------------------------------------------------------
    def attach(self, transport: DdeServerTransport) -> None:
        """Register the service names on ``transport`` and follow the core's ticks."""
        for service in self.services:
            transport.register_service(service, self)
        with self._lock:
            self._transports.append(transport)
            if self._unsubscribe is None:
                self._unsubscribe = self.core.subscribe(self.on_tick)

    def detach(self) -> None:
        """Stop following ticks and unregister from every transport (their conversations end)."""
        with self._lock:
            transports, self._transports = self._transports, []
            unsubscribe, self._unsubscribe = self._unsubscribe, None
        if unsubscribe is not None:
            unsubscribe()
        for transport in transports:
            for service in self.services:
                try:
                    transport.unregister_service(service)
                except Exception:
                    log.exception("could not unregister %s", service)

    def client_count(self) -> tuple[int, int]:
        """(open conversations, advise loops)."""
        with self._lock:
            return len(self._conversations), len(self._loops)

    # -- ticks -------------------------------------------------------------------------------
    def on_tick(self, sample: TickSample) -> None:
        """Post the new string to every advise loop (publisher thread)."""
        if not sample.text:
            return
        with self._lock:
            transports = list(self._transports)
            loops = len(self._loops)
        for transport in transports:
            for item in self.items:
                try:
                    transport.post_advise(self.topic, item)
                except Exception:
                    self._post_failures.log(logging.ERROR, f"post:{item}", "posting advise on %s failed", item,
                                            exc_info=True)
        self.core.events.add(sample.time, Direction.OUT, "publish", sample.text, detail=f"{loops} advise loop(s)")

    def _data(self, fmt: int) -> tuple[str, bytes]:
        """The current string and its bytes in ``fmt``, encoded once per string (every advise loop of a
        tick asks for the same bytes; reading the cached pair needs no lock: it is replaced whole)."""
        text = self.core.current_text()
        cached_text, cache = self._encoded
        data = cache.get(fmt) if cached_text == text else None
        if data is None:
            data = encode_text(text, fmt)
            with self._lock:
                if self._encoded[0] != text:
                    self._encoded = (text, {})
                self._encoded[1][fmt] = data
        return text, data

    # -- DdeServerHandler ----------------------------------------------------------------------
    def _label(self, conv: ConversationId) -> str:
        return self._conversations.get(conv, f"conv {conv}")

    def on_connect(self, service: str, topic: str) -> bool:
        ok = service.upper() in self._service_keys and topic.upper() == self.topic.upper()
        self.core.events.add(self.core.clock.now(), Direction.IN, "connect", f"{service}|{topic}", accepted=ok)
        return ok

    def on_connect_confirm(self, conv: ConversationId, service: str, topic: str) -> None:
        with self._lock:
            self._conversations[conv] = f"conv {conv} {service}/{topic}"

    def on_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        now = self.core.clock.now()
        if item.upper() not in self._item_keys or fmt not in TEXT_FORMATS:
            self.core.events.add(now, Direction.IN, "request", item, conversation=conv, client=self._label(conv),
                                 accepted=False, detail=f"unknown item or {format_name(fmt)}")
            return None
        text, data = self._data(fmt)
        self.core.events.add(now, Direction.OUT, "request", text, conversation=conv, client=self._label(conv),
                             detail=item)
        return data

    def _command(self, conv: ConversationId, text: str) -> PokeResult:
        result = self.core.command(text, source=self._label(conv), conversation=conv, face=Face.DDE)
        return PokeResult.FACK if result.accepted else PokeResult.FNOTPROCESSED

    def on_poke(self, conv: ConversationId, topic: str, item: str, fmt: int, data: bytes) -> PokeResult:
        if fmt not in TEXT_FORMATS:
            self.core.events.add(self.core.clock.now(), Direction.IN, "poke", f"<{len(data)} bytes>",
                                 conversation=conv, client=self._label(conv), accepted=False,
                                 detail=f"unsupported {format_name(fmt)}")
            return PokeResult.FNOTPROCESSED
        return self._command(conv, decode_text(data, fmt))

    def on_execute(self, conv: ConversationId, topic: str, command: bytes) -> PokeResult:
        return self._command(conv, decode_text(command))

    def on_advise_start(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bool:
        ok = item.upper() in self._item_keys and fmt in TEXT_FORMATS
        if ok:
            with self._lock:
                self._loops.add((conv, item.upper(), fmt))
        self.core.events.add(self.core.clock.now(), Direction.IN, "advise", f"start {item} {format_name(fmt)}",
                             conversation=conv, client=self._label(conv), accepted=ok)
        return ok

    def on_advise_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        if item.upper() not in self._item_keys or fmt not in TEXT_FORMATS:
            return None
        return self._data(fmt)[1]

    def on_advise_stop(self, conv: ConversationId, topic: str, item: str, fmt: int) -> None:
        with self._lock:
            self._loops.discard((conv, item.upper(), fmt))
        self.core.events.add(self.core.clock.now(), Direction.IN, "advise", f"stop {item} {format_name(fmt)}",
                             conversation=conv, client=self._label(conv))

    def on_disconnect(self, conv: ConversationId) -> None:
        with self._lock:
            label = self._conversations.pop(conv, f"conv {conv}")
            self._loops = {loop for loop in self._loops if loop[0] != conv}
        self.core.events.add(self.core.clock.now(), Direction.IN, "disconnect", label, conversation=conv,
                             client=label)
