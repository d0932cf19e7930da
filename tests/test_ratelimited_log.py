"""RateLimitedLog: the first occurrence at once, then one line per interval carrying the count."""

from __future__ import annotations

import logging
from datetime import datetime, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.ratelimited_log import MAX_KEYS, RateLimitedLog

log = logging.getLogger("nfwserver.test.ratelimited")


def _messages(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.name == log.name]


def test_first_then_a_summary_per_interval_then_the_pending_count_on_clear(caplog) -> None:
    caplog.set_level(logging.INFO, logger=log.name)
    clock = VirtualClock(datetime(2026, 1, 1, tzinfo=timezone.utc))
    limited = RateLimitedLog(log, clock, interval_s=10.0)
    written = []
    for _ in range(1280):  # 20 s at 64 Hz (a step exact in binary)
        written.append(limited.warning("bad", "bad reply %r", "x"))
        clock.advance(1 / 64)
    assert written.count(True) == 2 and written[0] and written[640]
    assert _messages(caplog) == ["bad reply 'x'", "bad reply 'x' (639 more like this in the last 10 s)"]
    assert limited.suppressed("bad") == 639
    limited.clear("bad")
    assert _messages(caplog)[-1] == "bad: 639 more like this in the last 10 s before it cleared"
    assert limited.warning("bad", "bad again")  # after clearing, the next one is written at once
    limited.warning("other", "another kind")  # keys are independent
    assert _messages(caplog)[-2:] == ["bad again", "another kind"]


def test_keys_are_bounded_and_the_interval_must_be_positive() -> None:
    clock = VirtualClock(datetime(2026, 1, 1, tzinfo=timezone.utc))
    limited = RateLimitedLog(log, clock)
    for k in range(3 * MAX_KEYS):
        limited.warning(f"key {k}", "x")
    assert len(limited._windows) == MAX_KEYS
    with pytest.raises(ValueError):
        RateLimitedLog(log, clock, interval_s=0)
