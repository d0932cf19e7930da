"""Serving a dialect over DDE, an adapter on the station core's ticks.

:class:`DialectServer` is a :class:`~nfwserver.dde.transport.DdeServerHandler` for one dialect's names
(case-insensitive, as DDEML compares them) and a tick listener: each tick it builds one view of the
selected satellite, formats each item's string from it once, and posts to an item's advise loops
when its string changed.  Requests return the item's current string.
These trackers take no commands over DDE, so pokes and executes are refused.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from datetime import tzinfo

from nfwserver.core.sample import TickSample
from nfwserver.core.station_core import StationCore
from nfwserver.dde.clipboard import TEXT_FORMATS, encode_text
from nfwserver.dde.transport import ConversationId, DdeServerTransport, PokeResult
from nfwserver.dialects.base import Dialect, view_from_sample
from nfwserver.tracking.derived import revolution_and_phase, sub_satellite_point


class DialectServer:
    """One dialect on one transport; reads the catalog and channels from ``core.state`` on every tick."""

    def __init__(self, dialect: Dialect, core: StationCore, local_zone: tzinfo | None = None) -> None:
        """``local_zone`` for local times (None: the machine's); UT1-UTC comes from the live state."""
        self.dialect = dialect
        self.core = core
        self.local_zone = local_zone
        self._unsubscribe: Callable[[], None] | None = None
        self._lock = threading.Lock()
        self._texts = {item.upper(): dialect.formatter(item)(None) for item in dialect.items}
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

    def text(self, item: str | None = None) -> str:
        """The current string of ``item`` (default: the dialect's first item)."""
        with self._lock:
            return self._texts[(item or self.dialect.items[0]).upper()]

    def on_tick(self, sample: TickSample) -> None:
        view = None
        if sample.catalog_number is not None:
            state = self.core.state
            sat = state.catalog.get(sample.catalog_number)
            if sat is not None and sample.look_angles is not None:
                phase = revolution_and_phase(sat.elements, sample.time)[1]
                view = view_from_sample(sample, sat.name, state.channels.get(sample.catalog_number), float(phase),
                                        sub_satellite_point(sat.satrec, sample.time, state.ut1_utc_s),
                                        self.local_zone)
        changed = []
        for item in self.dialect.items:
            text = self.dialect.formatter(item)(view)
            with self._lock:
                if text != self._texts[item.upper()]:
                    self._texts[item.upper()] = text
                    changed.append(item)
        if self._transport is not None:
            for item in changed:
                self._transport.post_advise(self.dialect.topic, item)

    # -- DdeServerHandler ------------------------------------------------------------------
    def on_connect(self, service: str, topic: str) -> bool:
        return service.upper() == self.dialect.service.upper() and topic.upper() == self.dialect.topic.upper()

    def on_connect_confirm(self, conv: ConversationId, service: str, topic: str) -> None:
        pass

    def _data(self, item: str, fmt: int) -> bytes | None:
        if item.upper() not in self._texts or fmt not in TEXT_FORMATS:
            return None
        return encode_text(self.text(item), fmt)

    def on_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        return self._data(item, fmt)

    def on_advise_request(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bytes | None:
        return self._data(item, fmt)

    def on_poke(self, conv: ConversationId, topic: str, item: str, fmt: int, data: bytes) -> PokeResult:
        return PokeResult.FNOTPROCESSED

    def on_execute(self, conv: ConversationId, topic: str, command: bytes) -> PokeResult:
        return PokeResult.FNOTPROCESSED

    def on_advise_start(self, conv: ConversationId, topic: str, item: str, fmt: int) -> bool:
        return item.upper() in self._texts and fmt in TEXT_FORMATS

    def on_advise_stop(self, conv: ConversationId, topic: str, item: str, fmt: int) -> None:
        pass

    def on_disconnect(self, conv: ConversationId) -> None:
        pass
