"""The record types of the configuration table: one :class:`Setting` per key, one :class:`Section` each.

Kept apart from the table (:mod:`nfwserver.config.table`) so that the value converters
(:mod:`nfwserver.config.kinds`) can name a setting without importing the table that uses them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["Section", "Setting"]


@dataclass(frozen=True)
class Setting:
    """One key of one section."""

    section: str
    key: str
    kind: str  #: a converter name in :data:`nfwserver.config.kinds.CONVERTERS`
    default: Any  #: TOML value used when the key is absent; None = not set
    help: str
    where: str  #: dotted path of the effective value on Config
    lo: float | None = None  #: numbers: inclusive range; texts: ``hi`` is the maximum length
    hi: float | None = None
    choices: tuple[Any, ...] = ()
    example: Any = None  #: shown commented out in the template instead of the default
    initial: Any = None  #: written by ``config init`` instead of the default (a starting choice)
    #: a further check of a well-formed value: why it is refused, or None.  ``config set`` never writes a file
    #: whose value fails it; a file that already holds one loads with a warning (:mod:`~nfwserver.config.loader`)
    check: Callable[[Any], str | None] | None = None

    @property
    def name(self) -> str:
        return f"[{self.section}] {self.key}"


@dataclass(frozen=True)
class Section:
    name: str
    help: str
