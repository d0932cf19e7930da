"""The one way tests wait for something that real threads or processes do: poll a condition, fail on timeout.

:func:`wait_for` returns the condition's first truthy value, so ``page = wait_for(lambda: read() or None)``
reads what was waited for; when the time is up it raises :class:`WaitTimeout` naming what was awaited, so a
wait that never ends can never pass silently.  (On a virtual clock, step the clock with
``tests.conftest.advance_until`` instead.)
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

__all__ = ["WaitTimeout", "wait_for"]

T = TypeVar("T")


class WaitTimeout(AssertionError):
    """The condition did not hold within the time given."""


def wait_for(predicate: Callable[[], T], timeout_s: float = 10.0, what: str | Callable[[], str] = "the condition", *,
             interval_s: float = 0.01, tolerate: tuple[type[BaseException], ...] = ()) -> T:
    """Poll ``predicate`` every ``interval_s`` real seconds until it returns something truthy, and return that;
    raise :class:`WaitTimeout` after ``timeout_s`` seconds, naming ``what`` (a callable is asked then, so
    the message can show the state the wait ended in).  Exceptions of the ``tolerate`` types count as
    "not yet" (e.g. ``OSError`` while a server is still starting)."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            value = predicate()
        except tolerate:
            value = None  # type: ignore[assignment]
        if value:
            return value
        if time.monotonic() >= deadline:
            raise WaitTimeout(f"timed out after {timeout_s:g} s waiting for {what() if callable(what) else what}")
        time.sleep(interval_s)
