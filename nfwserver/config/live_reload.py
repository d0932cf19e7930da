"""Which parts of the configuration a running station takes on the fly, and which wait for a restart.

The station keeps one table of :class:`ConfigPart` rows (:data:`nfwserver.app.live_config.CONFIG_PARTS`):
each names a part of :class:`~nfwserver.config.schema.Config` by the dotted paths of its values and says
how a change is taken: ``apply`` applies it to the running station at once, or, for a part it cannot
change live (listeners, devices, element sources, the DDE service names), ``apply`` is None and the change
waits for a restart.  :func:`restart_needed` lists the restart-only parts that differ (by the label the log
uses); :func:`keep_running` gives the configuration the station then runs with: the new one, with every
restart-only value kept as it is running, so the next comparison is true.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Any, Generic, TypeVar

from nfwserver.config.schema import Config

__all__ = ["ConfigPart", "keep_running", "restart_needed"]

Target = TypeVar("Target")


@dataclass(frozen=True)
class ConfigPart(Generic[Target]):
    """One part of the configuration and how a running ``Target`` takes a change of it."""

    label: str  #: what the log calls it ("[tcp]", "[radio] backend")
    paths: tuple[str, ...]  #: dotted paths on Config of the values it covers
    #: applies the new configuration's values of this part to the running target; None: restart only
    apply: Callable[[Target, Config], None] | None = None

    def differs(self, running: Config, new: Config) -> bool:
        """Whether any of this part's values differ between ``running`` and ``new``."""
        return any(_get(running, path) != _get(new, path) for path in self.paths)


def _get(config: object, path: str) -> Any:
    for name in path.split("."):
        config = getattr(config, name)
    return config


def _with(config: Any, path: str, value: Any) -> Any:
    head, _, rest = path.partition(".")
    return replace(config, **{head: _with(getattr(config, head), rest, value) if rest else value})


def restart_needed(parts: Iterable[ConfigPart[Any]], running: Config, new: Config) -> list[str]:
    """The labels of the restart-only ``parts`` whose values differ between ``running`` and ``new``."""
    return [part.label for part in parts if part.apply is None and part.differs(running, new)]


def keep_running(parts: Iterable[ConfigPart[Any]], running: Config, new: Config) -> Config:
    """``new`` with every restart-only part's values taken from ``running``."""
    for part in parts:
        if part.apply is None:
            for path in part.paths:
                new = _with(new, path, _get(running, path))
    return new
