"""Serving a dialect over DDE, an adapter on the station core's ticks.

:class:`DialectServer` is a :class:`~nfwserver.dde.transport.DdeServerHandler` for one dialect's names
(case-insensitive, as DDEML compares them) and a tick listener: each tick it formats the dialect's
string once and posts it to its advise loops when it changed.  Requests return the current string.
These trackers take no commands over DDE, so pokes and executes are refused.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.dde.clipboard import TEXT_FORMATS, encode_text
from nfwserver.dde.transport import ConversationId, DdeServerTransport, PokeResult
from nfwserver.dialects.base import Dialect, view_from_sample
from nfwserver.tracking.derived import revolution_and_phase


class DialectServer:
    """One dialect on one transport; reads the catalog and channels from ``core.state`` on every tick."""

    def __init__(self, dialect: Dialect, core: StationCore) -> None:
        self.dialect = dialect
        self.core = core
        self._unsubscribe: Callable[[], None] | None = None
        self._items = {i.upper() for i in dialect.items}
        self._lock = threading.Lock()
        self._text = dialect.format(None)
        self._transport: DdeServerTransport | None = None

    def attach(self, transport: DdeServerTransport) -> None:
        transport.register_service(self.dialect.service, self)
        self._transport = transport
        if self._unsubscribe is None:
            self._unsubscribe = self.core.subscribe(self.on_tick)

    def detach(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None
        if self._transport is not None:
            self._transport.unregister_service(self.dialect.service)
            self._transport = None

    def text(self) -> str:
        with self._lock:
            return self._text

    def on_tick(self, sample: TickSample) -> None:
        view = None
        if sample.catalog_number is not None:
            state = self.core.state
            sat = state.catalog.get(sample.catalog_number)
            if sat is not None:
                phase = revolution_and_phase(sat.elements, sample.time)[1] if sample.look_angles else None
                view = view_from_sample(sample, sat.name, state.channels.get(sample.catalog_number),
                                        float(phase) if phase is not None else None)
        text = self.dialect.format(view)
        with self._lock:
            changed, self._text = text != self._text, text
        if changed and self._transport is not None:
            for item in self.dialect.items:
                self._transport.post_advise(self.dialect.topic, item)

    # -- DdeServerHandler ------------------------------------------------------------------
    def on_connect(self, service: str, topic: str) -> bool:
        return service.upper() == self.dialect.service.upper() and topic.upper() == self.dialect.topic.upper()

    def on_connect_confirm(self, conv: ConversationId, service: str, topic: str) -> None:
        pass

    def _data(self, item: str, fmt: int) -> bytes | None:
        if item.upper() not in self._items or fmt not in TEXT_FORMATS:
            return None
        return encode_text(self.text(), fmt)

    def on_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        return self._data(item, fmt)

    def on_advise_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        return self._data(item, fmt)

    def on_poke(self, conv: ConversationId, topic: str, item: str, fmt: int, data: bytes) -> PokeResult:
        return PokeResult.FNOTPROCESSED

    def on_execute(self, conv: ConversationId, topic: str, command: bytes) -> PokeResult:
        return PokeResult.FNOTPROCESSED

    def on_advise_start(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bool:
        return item.upper() in self._items and fmt in TEXT_FORMATS

    def on_advise_stop(self, conv: ConversationId, topic: str, item: str, fmt: int) -> None:
        pass

    def on_disconnect(self, conv: ConversationId) -> None:
        pass
