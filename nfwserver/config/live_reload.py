"""Which parts of the configuration a running station can take on the fly, and which wait for a restart.

:data:`RESTART_ONLY` is the one list of the parts a running station cannot change live (listeners, devices,
element sources, DDE names of the service): each entry is what the log says and the dotted paths, on
:class:`~nfwserver.config.schema.Config`, of the values it covers.  Everything else (observer, horizon,
UT1-UTC, rate, channels, DDE names of satellites, radio tuning on/off) is applied live by the station.
:func:`restart_needed` lists what differs; :func:`keep_running` gives the configuration the station then
runs with: the new one, with every restart-only value kept as it is running, so the next comparison is true.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from nfwserver.config.schema import Config

__all__ = ["RESTART_ONLY", "keep_running", "restart_needed"]

#: (what the log calls it, dotted paths on Config)
RESTART_ONLY: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("[elements]", ("elements",)),
    ("[rotor]", ("rotor",)),
    ("[radio] backend", ("radio.backend", "radio.host", "radio.port")),
    ("[server] services/topic/items", ("server.services", "server.topic", "server.items")),
    ("[dialects]", ("dialects",)),
    ("[tcp]", ("tcp",)),
    ("[easycomm]", ("easycomm",)),
    ("[web]", ("web",)),
)


def _get(config: object, path: str) -> Any:
    for name in path.split("."):
        config = getattr(config, name)
    return config


def _with(config: Any, path: str, value: Any) -> Any:
    head, _, rest = path.partition(".")
    return replace(config, **{head: _with(getattr(config, head), rest, value) if rest else value})


def restart_needed(running: Config, new: Config) -> list[str]:
    """The labels of :data:`RESTART_ONLY` whose values differ between ``running`` and ``new``."""
    return [label for label, paths in RESTART_ONLY
            if any(_get(running, path) != _get(new, path) for path in paths)]


def keep_running(running: Config, new: Config) -> Config:
    """``new`` with every restart-only value taken from ``running``."""
    for _, paths in RESTART_ONLY:
        for path in paths:
            new = _with(new, path, _get(running, path))
    return new
