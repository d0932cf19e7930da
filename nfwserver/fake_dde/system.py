"""The fake DDEML itself: session, server transport and client conversations (see the package docstring).

Locking: one re-entrant lock per :class:`FakeDdeSystem` serialises transactions, as DDEML
serialises them on the server's message loop.  Server handlers are called with that lock held, so
a handler must not wait on another thread that needs the transport; the nfwserver core never calls
the transport while holding its own lock.

Bounds, so abandoned or hostile clients cannot exhaust memory or slow the server's tick: each
service accepts at most ``max_conversations_per_service`` conversations (a further connect is
refused with ``DMLERR_NO_CONV_ESTABLISHED``, as DDEML refuses when a server cannot take another),
and each client keeps only its ``received_capacity`` newest deliveries.  Advise loops are indexed
by (topic, item), so posting an item costs one server call per loop on that item, no more.
"""

from __future__ import annotations

import itertools
import logging
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from nfwserver.dde.clipboard import CF_TEXT, decode_text, encode_text
from nfwserver.dde.transport import ConversationId, DdeServerHandler, PokeResult
from nfwserver.fake_dde.errors import (
    DMLERR_BUSY,
    DMLERR_INVALIDPARAMETER,
    DMLERR_NO_CONV_ESTABLISHED,
    DMLERR_NOTPROCESSED,
    DMLERR_SERVER_DIED,
    DdeError,
)

log = logging.getLogger(__name__)

MAX_NAME_LENGTH = 255
#: Default bounds (see the module docstring).
MAX_CONVERSATIONS_PER_SERVICE = 256
RECEIVED_CAPACITY = 10_000


def _check_name(name: str, what: str) -> str:
    if not isinstance(name, str) or not name or len(name) > MAX_NAME_LENGTH:
        raise DdeError(DMLERR_INVALIDPARAMETER, f"{what} name must have 1 to {MAX_NAME_LENGTH} characters")
    return name


@dataclass(frozen=True)
class Received:
    """Something a client conversation received, in order.

    ``kind`` is ``"data"`` (hot advise), ``"notify"`` (warm advise: no data), ``"reply"`` (answer
    to a request) or ``"disconnect"`` (the server ended the conversation).
    """

    seq: int
    kind: str
    item: str
    fmt: int
    data: bytes | None = None

    @property
    def text(self) -> str | None:
        """The data decoded per its clipboard format (None when there is no data)."""
        return None if self.data is None else decode_text(self.data, self.fmt)


@dataclass
class _Loop:
    item: str
    fmt: int
    hot: bool


@dataclass
class _Conversation:
    conv_id: ConversationId
    service: str
    topic: str
    handler: DdeServerHandler
    client: ClientConversation
    loops: dict[tuple[str, int], _Loop] = field(default_factory=dict)


class FakeDdeSystem:
    """One simulated Windows session holding DDE servers and client conversations."""

    def __init__(self, received_capacity: int = RECEIVED_CAPACITY,
                 max_conversations_per_service: int = MAX_CONVERSATIONS_PER_SERVICE) -> None:
        self._lock = threading.RLock()
        self._services: dict[str, tuple[str, DdeServerHandler]] = {}
        self._conversations: dict[ConversationId, _Conversation] = {}
        self._per_service: dict[str, int] = {}  #: open conversations by upper-case service name
        #: advise loops by (upper-case topic, upper-case item): conversation id -> None (ordered set)
        self._advised: dict[tuple[str, str], dict[ConversationId, None]] = {}
        self._ids = itertools.count(1)
        self._seq = itertools.count(1)
        self.received_capacity = received_capacity
        self.max_conversations_per_service = max_conversations_per_service
        self.refused_connects = 0  #: connects refused because a service was full

    # -- server side -------------------------------------------------------------------------
    def server_transport(self) -> FakeServerTransport:
        """A transport through which one server registers its services."""
        return FakeServerTransport(self)

    def _register(self, service: str, handler: DdeServerHandler) -> None:
        _check_name(service, "service")
        with self._lock:
            key = service.upper()
            if key in self._services and self._services[key][1] is not handler:
                raise DdeError(DMLERR_INVALIDPARAMETER, f"service {service!r} is already registered")
            self._services[key] = (service, handler)

    def _unregister(self, service: str) -> None:
        with self._lock:
            entry = self._services.pop(service.upper(), None)
            if entry is None:
                return
            for conv in [c for c in self._conversations.values() if c.service.upper() == service.upper()]:
                self._end(conv, by_server=True)

    def _post_advise(self, topic: str, item: str) -> int:
        """Serve every advise loop on (topic, item); returns how many loops were served."""
        served = 0
        with self._lock:
            for conv_id in list(self._advised.get((topic.upper(), item.upper()), ())):
                conv = self._conversations[conv_id]
                for loop in [lp for (key, _), lp in list(conv.loops.items()) if key == item.upper()]:
                    try:
                        data = conv.handler.on_advise_request(conv.conv_id, conv.topic, loop.item, loop.fmt)
                    except Exception:
                        log.exception("server failed an advise request on conversation %d", conv.conv_id)
                        continue
                    if data is None:
                        continue
                    served += 1
                    if loop.hot:
                        conv.client._deliver(Received(next(self._seq), "data", loop.item, loop.fmt, bytes(data)))
                    else:
                        conv.client._deliver(Received(next(self._seq), "notify", loop.item, loop.fmt, None))
        return served

    # -- client side -------------------------------------------------------------------------
    def connect(self, service: str, topic: str, client_name: str = "client") -> ClientConversation:
        """Open a conversation (DdeConnect); raises :class:`DdeError` DMLERR_NO_CONV_ESTABLISHED."""
        _check_name(service, "service")
        _check_name(topic, "topic")
        with self._lock:
            entry = self._services.get(service.upper())
            if entry is None:
                raise DdeError(DMLERR_NO_CONV_ESTABLISHED, f"no server offers service {service!r}")
            handler = entry[1]
            key = service.upper()
            if self._per_service.get(key, 0) >= self.max_conversations_per_service:
                self.refused_connects += 1
                if self.refused_connects == 1:
                    log.warning("service %s has %d conversations, its limit; further connects are refused",
                                entry[0], self.max_conversations_per_service)
                raise DdeError(DMLERR_NO_CONV_ESTABLISHED, f"service {service!r} already has "
                               f"{self.max_conversations_per_service} conversations; connect refused")
            try:
                ok = handler.on_connect(service, topic)
            except Exception:
                log.exception("server failed a connect to %s/%s", service, topic)
                ok = False
            if not ok:
                raise DdeError(DMLERR_NO_CONV_ESTABLISHED, f"service {service!r} refused topic {topic!r}")
            conv_id = next(self._ids)
            client = ClientConversation(self, conv_id, service, topic, client_name)
            self._conversations[conv_id] = _Conversation(conv_id, service, topic, handler, client)
            self._per_service[key] = self._per_service.get(key, 0) + 1
            try:
                handler.on_connect_confirm(conv_id, service, topic)
            except Exception:
                log.exception("server failed a connect confirmation on conversation %d", conv_id)
            return client

    def _conv(self, conv_id: ConversationId) -> _Conversation:
        conv = self._conversations.get(conv_id)
        if conv is None:
            raise DdeError(DMLERR_NO_CONV_ESTABLISHED, "the conversation has ended")
        return conv

    def _call(self, conv: _Conversation, what: str, fn: Callable[[], object]) -> object:
        try:
            return fn()
        except Exception:
            log.exception("server failed a %s on conversation %d", what, conv.conv_id)
            return None

    def _request(self, conv_id: ConversationId, item: str, fmt: int) -> bytes:
        _check_name(item, "item")
        with self._lock:
            conv = self._conv(conv_id)
            data = self._call(conv, "request", lambda: conv.handler.on_request(conv_id, conv.topic, item, fmt))
            if data is None:
                raise DdeError(DMLERR_NOTPROCESSED, f"the server refused the request for {item!r}")
            reply: bytes = bytes(data)  # type: ignore[call-overload]  # on_request's bytes, through _call
            conv.client._deliver(Received(next(self._seq), "reply", item, fmt, reply))
            return reply

    def _poke(self, conv_id: ConversationId, item: str, fmt: int, data: bytes) -> None:
        _check_name(item, "item")
        with self._lock:
            conv = self._conv(conv_id)
            result = self._call(conv, "poke", lambda: conv.handler.on_poke(conv_id, conv.topic, item, fmt, data))
        self._ack(result, f"poke to {item!r}")

    def _execute(self, conv_id: ConversationId, command: bytes) -> None:
        with self._lock:
            conv = self._conv(conv_id)
            result = self._call(conv, "execute", lambda: conv.handler.on_execute(conv_id, conv.topic, command))
        self._ack(result, "execute")

    @staticmethod
    def _ack(result: object, what: str) -> None:
        if result == PokeResult.FACK:
            return
        if result == PokeResult.FBUSY:
            raise DdeError(DMLERR_BUSY, f"the server was busy and did not take the {what}")
        raise DdeError(DMLERR_NOTPROCESSED, f"the server refused the {what}")

    def _start_advise(self, conv_id: ConversationId, item: str, fmt: int, hot: bool) -> None:
        _check_name(item, "item")
        with self._lock:
            conv = self._conv(conv_id)
            key = (item.upper(), fmt)
            existing = conv.loops.get(key)
            if existing is not None:  # DDEML changes the link type of the existing loop
                existing.hot = hot
                return
            ok = self._call(conv, "advise start", lambda: conv.handler.on_advise_start(conv_id, conv.topic, item, fmt))
            if not ok:
                raise DdeError(DMLERR_NOTPROCESSED, f"the server refused an advise loop on {item!r}")
            conv.loops[key] = _Loop(item, fmt, hot)
            self._advised.setdefault((conv.topic.upper(), item.upper()), {})[conv_id] = None

    def _stop_advise(self, conv_id: ConversationId, item: str, fmt: int) -> None:
        with self._lock:
            conv = self._conv(conv_id)
            loop = conv.loops.pop((item.upper(), fmt), None)
            if loop is None:
                raise DdeError(DMLERR_NOTPROCESSED, f"there is no advise loop on {item!r}")
            if not any(key == item.upper() for key, _ in conv.loops):
                self._unindex(conv, item.upper())
            self._call(conv, "advise stop", lambda: conv.handler.on_advise_stop(conv_id, conv.topic, loop.item, fmt))

    def _disconnect(self, conv_id: ConversationId) -> None:
        with self._lock:
            conv = self._conversations.get(conv_id)
            if conv is not None:
                self._end(conv, by_server=False)

    def _unindex(self, conv: _Conversation, item_key: str) -> None:
        index_key = (conv.topic.upper(), item_key)
        loops = self._advised.get(index_key)
        if loops is not None:
            loops.pop(conv.conv_id, None)
            if not loops:
                del self._advised[index_key]

    def _end(self, conv: _Conversation, by_server: bool) -> None:
        if self._conversations.pop(conv.conv_id, None) is not None:
            key = conv.service.upper()
            self._per_service[key] -= 1
            if not self._per_service[key]:
                del self._per_service[key]
        for item_key in {key for key, _ in conv.loops}:
            self._unindex(conv, item_key)
        conv.loops.clear()
        self._call(conv, "disconnect", lambda: conv.handler.on_disconnect(conv.conv_id))
        conv.client._closed()
        if by_server:
            conv.client._deliver(Received(next(self._seq), "disconnect", "", 0, None))

    def conversation_count(self) -> int:
        """Open conversations (all services)."""
        with self._lock:
            return len(self._conversations)

    def advise_loop_count(self) -> int:
        """Advise loops across all conversations."""
        with self._lock:
            return sum(len(c.loops) for c in self._conversations.values())


class FakeServerTransport:
    """The server side of a :class:`FakeDdeSystem` (implements ``DdeServerTransport``)."""

    def __init__(self, system: FakeDdeSystem) -> None:
        self.system = system
        self._services: list[str] = []

    def register_service(self, service: str, handler: DdeServerHandler) -> None:
        self.system._register(service, handler)
        self._services.append(service)

    def unregister_service(self, service: str) -> None:
        self.system._unregister(service)
        self._services = [s for s in self._services if s.upper() != service.upper()]

    def post_advise(self, topic: str, item: str) -> None:
        self.system._post_advise(topic, item)

    def close(self) -> None:
        for service in list(self._services):
            self.unregister_service(service)


class ClientConversation:
    """A client's end of one conversation (the ``HCONV`` of DDEML)."""

    def __init__(self, system: FakeDdeSystem, conv_id: ConversationId, service: str, topic: str,
                 client_name: str) -> None:
        self.system = system
        self.conv_id = conv_id
        self.service = service
        self.topic = topic
        self.client_name = client_name
        self.connected = True
        self.received: deque[Received] = deque(maxlen=system.received_capacity)
        #: Called with each :class:`Received` as it arrives (like a client's DdeCallback).
        self.on_receive: Callable[[Received], None] | None = None

    def _deliver(self, item: Received) -> None:
        self.received.append(item)
        if self.on_receive is not None:
            try:
                self.on_receive(item)
            except Exception:
                log.exception("client callback of conversation %d failed", self.conv_id)

    def _closed(self) -> None:
        self.connected = False

    def _live(self) -> None:
        if not self.connected:
            raise DdeError(DMLERR_SERVER_DIED, "the conversation has ended")

    def request(self, item: str, fmt: int = CF_TEXT) -> bytes:
        """XTYP_REQUEST: the item's data as bytes."""
        self._live()
        return self.system._request(self.conv_id, item, fmt)

    def request_text(self, item: str, fmt: int = CF_TEXT) -> str:
        """XTYP_REQUEST decoded to text."""
        return decode_text(self.request(item, fmt), fmt)

    def poke(self, item: str, data: str | bytes, fmt: int = CF_TEXT) -> None:
        """XTYP_POKE; text is encoded in ``fmt`` with its trailing NUL.  Raises on refusal."""
        self._live()
        payload = encode_text(data, fmt) if isinstance(data, str) else bytes(data)
        self.system._poke(self.conv_id, item, fmt, payload)

    def execute(self, command: str | bytes) -> None:
        """XTYP_EXECUTE with a command string.  Raises on refusal."""
        self._live()
        payload = encode_text(command) if isinstance(command, str) else bytes(command)
        self.system._execute(self.conv_id, payload)

    def start_advise(self, item: str, fmt: int = CF_TEXT, hot: bool = True) -> None:
        """XTYP_ADVSTART: hot link (data pushed) or warm link (``hot=False``: notification only)."""
        self._live()
        self.system._start_advise(self.conv_id, item, fmt, hot)

    def stop_advise(self, item: str, fmt: int = CF_TEXT) -> None:
        """XTYP_ADVSTOP."""
        self._live()
        self.system._stop_advise(self.conv_id, item, fmt)

    def disconnect(self) -> None:
        """DdeDisconnect (ending a conversation twice is harmless)."""
        if self.connected:
            self.system._disconnect(self.conv_id)

    def texts(self, kinds: tuple[str, ...] = ("data",)) -> list[str]:
        """Decoded texts of everything received of the given kinds, in order."""
        # r.data is not None, so r.text is a str
        return [r.text for r in self.received if r.kind in kinds and r.data is not None]  # type: ignore[misc]
