"""Stale element sets: those whose epoch lies too long before the time asked for (no numpy, for commands that
must start quickly).  Stale sets are still used, with a warning; see :mod:`nfwserver.tracking.screening`."""

from __future__ import annotations

from collections.abc import Sequence
from datetime import datetime, timedelta
from typing import Any, TypeVar

#: Element sets older than this (days) before the time asked for are reported as stale.
STALE_AFTER_DAYS = 30.0

T = TypeVar("T")


def stale_satellites(satellites: Sequence[T], at: datetime, max_age_days: float = STALE_AFTER_DAYS) -> list[T]:
    """The satellites (or element sets) whose element epoch is more than ``max_age_days`` before ``at``."""
    oldest = at - timedelta(days=max_age_days)
    return [s for s in satellites if _epoch(s) < oldest]


def _epoch(item: Any) -> datetime:
    """The element epoch (UTC) of a satellite or of an element set."""
    epoch: datetime = getattr(item, "elements", item).epoch
    return epoch
