"""The KCT driver's alarms (a stalled rotor) as a stream of events for the console and the event log.

The original driver sounded its conditions on the PC speaker; here each becomes an :class:`Announcement`
that the driver logs and hands to its listeners (the rotor coupling forwards them as console events), so an
operator sees what the driver would have sounded.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Announcement:
    """One alarm: when (the driver's clock, aware UTC), ``kind`` (``"alarm"``) and what."""

    time: datetime
    kind: str
    text: str


def describe(item: Announcement) -> str:
    """One line for logs and the console: ``ALARM: ...``."""
    return f"{item.kind.upper()}: {item.text}"


class Annunciator:
    """The listeners of the driver's announcements."""

    def __init__(self, now: Callable[[], datetime]) -> None:
        self._now = now
        self.listeners: list[Callable[[Announcement], None]] = []

    def emit(self, kind: str, text: str) -> Announcement:
        """Log one announcement and hand it to every listener."""
        item = Announcement(self._now(), kind, text)
        log.warning("rotor driver: %s", text)
        for listener in list(self.listeners):
            try:
                listener(item)
            except Exception:
                log.exception("announcement listener failed")
        return item
