"""The station's links and their health, in one place for STATUS, the console and the web page."""

from __future__ import annotations

import threading
from collections.abc import Callable

from nfwserver.clock import Clock
from nfwserver.health.link_health import Backoff, LinkHealth

__all__ = ["HealthBoard"]


class HealthBoard:
    """Named :class:`LinkHealth` objects, made on first use; one board per station."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self._links: dict[str, LinkHealth] = {}
        self._lock = threading.Lock()
        self._listeners: list[Callable[[LinkHealth], None]] = []

    def link(self, name: str, backoff: Backoff | None = None, paced: bool = True) -> LinkHealth:
        """The health of link ``name`` (``rotor``, ``radio``, ``elements``, ``state-file`` ...); ``backoff``
        and ``paced`` count when the link is first made."""
        with self._lock:
            health = self._links.get(name)
            if health is None:
                health = LinkHealth(name, self.clock, backoff, on_change=self._changed, paced=paced)
                self._links[name] = health
            return health

    def subscribe(self, listener: Callable[[LinkHealth], None]) -> None:
        """Call ``listener(health)`` whenever a link enters or leaves a fault (console, event log)."""
        with self._lock:
            self._listeners.append(listener)

    def faults(self) -> dict[str, str]:
        """``{name: description}`` of the links failing now, in name order."""
        with self._lock:
            links = sorted(self._links.items())
        return {name: h.describe() for name, h in links if not h.ok}

    def states(self) -> dict[str, str]:
        """``{name: "ok" | description}`` of every link, in name order."""
        with self._lock:
            links = sorted(self._links.items())
        return {name: h.describe() for name, h in links}

    def _changed(self, health: LinkHealth) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for listener in listeners:
            listener(health)
