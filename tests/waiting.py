"""The one way tests wait for something that real threads or processes do: poll a condition, fail on timeout.

:func:`wait_for` returns the condition's first truthy value, so ``page = wait_for(lambda: read() or None)``
reads what was waited for; when the time is up it raises :class:`WaitTimeout` naming what was awaited, so a
wait that never ends can never pass silently.  :func:`wait_for_async` is the same wait inside an event loop
(the console's tests), pausing with a coroutine instead of sleeping.  (On a virtual clock, step the clock with
``tests.conftest.advance_until`` instead.)
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Awaitable, Callable
from typing import TypeVar

__all__ = ["WaitTimeout", "wait_for", "wait_for_async"]

T = TypeVar("T")


class WaitTimeout(AssertionError):
    """The condition did not hold within the time given."""


class _Polls:
    """The deadline of one wait: each poll's value, and the failure once the time is up."""

    def __init__(self, predicate: Callable[[], T], timeout_s: float, what: str | Callable[[], str],
                 tolerate: tuple[type[BaseException], ...]) -> None:
        self.predicate, self.timeout_s, self.what, self.tolerate = predicate, timeout_s, what, tolerate
        self.deadline = time.monotonic() + timeout_s

    def poll(self) -> T | None:
        """The condition's value now (None for a tolerated exception); raises :class:`WaitTimeout` when it is
        falsy and the time is up."""
        try:
            value = self.predicate()
        except self.tolerate:
            value = None
        if not value and time.monotonic() >= self.deadline:
            what = self.what() if callable(self.what) else self.what
            raise WaitTimeout(f"timed out after {self.timeout_s:g} s waiting for {what}")
        return value  # type: ignore[no-any-return]


def wait_for(predicate: Callable[[], T], timeout_s: float = 10.0, what: str | Callable[[], str] = "the condition", *,
             interval_s: float = 0.01, tolerate: tuple[type[BaseException], ...] = ()) -> T:
    """Poll ``predicate`` every ``interval_s`` real seconds until it returns something truthy, and return that;
    raise :class:`WaitTimeout` after ``timeout_s`` seconds, naming ``what`` (a callable is asked then, so
    the message can show the state the wait ended in).  Exceptions of the ``tolerate`` types count as
    "not yet" (e.g. ``OSError`` while a server is still starting)."""
    polls = _Polls(predicate, timeout_s, what, tolerate)
    while not (value := polls.poll()):
        time.sleep(interval_s)
    return value


async def wait_for_async(predicate: Callable[[], T], timeout_s: float = 10.0,
                         what: str | Callable[[], str] = "the condition", *, interval_s: float = 0.01,
                         pause: Callable[[float], Awaitable[object]] = asyncio.sleep) -> T:
    """:func:`wait_for` in an event loop: between polls, ``await pause(interval_s)`` (``asyncio.sleep``, or a
    test pilot's pause), so the loop being waited on keeps running."""
    polls = _Polls(predicate, timeout_s, what, ())
    while not (value := polls.poll()):
        await pause(interval_s)
    return value
