"""LinkHealth: a fault is visible while it lasts, retried after a bounded backoff, cleared by one success."""

from __future__ import annotations

import logging
from datetime import datetime, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.health import Backoff, HealthBoard, LinkHealth


@pytest.fixture
def clock() -> VirtualClock:
    return VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))


def test_backoff_doubles_up_to_its_bound() -> None:
    b = Backoff(initial_s=2.0, max_s=30.0)
    assert [b.delay(n) for n in range(7)] == [0.0, 2.0, 4.0, 8.0, 16.0, 30.0, 30.0]
    assert b.delay(10_000) == 30.0
    with pytest.raises(ValueError):
        Backoff(initial_s=0.0)
    with pytest.raises(ValueError):
        Backoff(initial_s=5.0, max_s=1.0)


def test_a_failure_waits_its_backoff_and_one_success_clears_it(clock: VirtualClock) -> None:
    h = LinkHealth("rotor", clock, Backoff(1.0, 8.0))
    assert h.ok and h.may_try() and h.describe() == "ok"
    h.failed("RPRT -1")
    assert not h.ok and not h.may_try()
    assert h.describe() == "RPRT -1 (1 failure in 0 s, retry in 1 s)"
    clock.advance(1.0)
    assert h.may_try()
    h.failed("RPRT -1")
    clock.advance(1.5)
    assert not h.may_try()  # second failure: 2 s
    clock.advance(0.5)
    assert h.may_try()
    h.succeeded()
    assert h.ok and h.may_try() and h.fault is None and h.recoveries == 1


def test_retry_now_skips_the_wait_but_keeps_the_fault_until_a_success(clock: VirtualClock) -> None:
    h = LinkHealth("radio", clock, Backoff(10.0, 60.0))
    h.failed("connection refused")
    assert not h.may_try()
    h.retry_now()
    assert h.may_try() and not h.ok
    assert h.fault is not None and h.fault.failures == 1


def test_repeated_failures_write_one_line_then_the_recovery(clock: VirtualClock,
                                                           caplog: pytest.LogCaptureFixture) -> None:
    h = LinkHealth("state-file", clock, Backoff(1.0, 4.0), logger=logging.getLogger("test.health"))
    with caplog.at_level(logging.INFO, logger="test.health"):
        for _ in range(50):
            h.failed("Permission denied")
            clock.advance(0.5)
        h.succeeded()
    lines = [r.getMessage() for r in caplog.records]
    assert lines[0] == "state-file: Permission denied; retrying in 1 s"
    assert sum("Permission denied;" in line for line in lines) == 1
    assert lines[-1].startswith("state-file: recovered after 25.0 s (50 failures)")


def test_the_board_lists_faults_and_tells_listeners(clock: VirtualClock) -> None:
    board = HealthBoard(clock)
    seen: list[tuple[str, bool]] = []
    board.subscribe(lambda h: seen.append((h.name, h.ok)))
    rotor, radio = board.link("rotor"), board.link("radio")
    assert board.link("rotor") is rotor
    radio.failed("EOF")
    radio.failed("EOF")
    assert board.faults() == {"radio": "EOF (2 failures in 0 s, retry in 2 s)"}
    assert board.states()["rotor"] == "ok"
    radio.succeeded()
    assert board.faults() == {}
    assert seen == [("radio", False), ("radio", True)]


def test_a_link_flapping_every_tick_writes_a_line_a_minute_not_two_a_tick(clock: VirtualClock,
                                                                        caplog: pytest.LogCaptureFixture) -> None:
    h = LinkHealth("rotctld", clock, Backoff(0.25, 1.5), logger=logging.getLogger("test.flap"))
    with caplog.at_level(logging.INFO, logger="test.flap"):
        for _ in range(50 * 150):  # 150 s of 50 Hz: a fault and a success every tick
            h.failed("garbage position")
            h.succeeded()
            clock.advance(0.02)
    lines = [r.getMessage() for r in caplog.records]
    assert 2 <= len(lines) <= 6, lines  # the first fault and its recovery, then a counted line a minute
    assert lines[0] == "rotctld: garbage position; retrying in 0.2 s"  # was "0 s": a short wait shows
    assert lines[1].startswith("rotctld: recovered after 0.0 s (1 failure)")
    assert any("more like this" in line for line in lines[2:])
    assert h.ok and h.recoveries == 50 * 150


def test_a_symptom_shows_the_fault_without_growing_the_back_off(clock: VirtualClock) -> None:
    h = LinkHealth("rotor", clock, Backoff(5.0, 60.0))
    h.failed("the rotor refused a move", attempt=False)
    h.failed("the rotor refused a move", attempt=False)
    assert not h.ok and h.fault is not None and h.fault.failures == 0
    assert h.describe() == "the rotor refused a move (for 0 s)"
    fault = h.failed("stalled")  # the first real attempt that failed: the first back-off step
    assert fault.failures == 1 and fault.retry_at == clock.monotonic() + 5.0


def test_every_outage_episode_gets_its_lost_and_recovered_lines(clock: VirtualClock,
                                                                caplog: pytest.LogCaptureFixture) -> None:
    """#34 item 9: the lines were limited per link (one a minute), so four separate 8 s outages of rotctld within
    one minute wrote no line for the last three (and so no recovery line either).  Each episode gets its two
    lines; only the repeats within an episode are limited."""
    h = LinkHealth("rotctld", clock, Backoff(0.25, 1.5), logger=logging.getLogger("test.episodes"))
    with caplog.at_level(logging.INFO, logger="test.episodes"):
        for _ in range(4):  # 8 s out, polled at 5 Hz, then 7 s well
            for _ in range(40):
                h.failed("rotctld at 127.0.0.1:4533 lost (connection refused)")
                clock.advance(0.2)
            h.succeeded()
            clock.advance(7.0)
    lines = [r.getMessage() for r in caplog.records]
    lost = [line for line in lines if "lost (connection refused)" in line]
    recovered = [line for line in lines if "recovered after 8.0 s" in line]
    assert len(lost) == 4 and len(recovered) == 4, lines
    assert len(lines) == 8  # and nothing else: the repeats within each episode stay limited
