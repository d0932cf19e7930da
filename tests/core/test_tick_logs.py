"""Paths that run every tick log through RateLimitedLog (issue 36 item 7): a fault that repeats at 5 Hz writes
one line and then a count, and nothing that fails is swallowed without a word."""

from __future__ import annotations

import logging
from datetime import timedelta

from nfwserver.core.publisher import run_virtual
from nfwserver.tcp.protocol import NovaTcpProtocol
from nfwserver.tcp.status_line import parse_status
from tests.dde.conftest import make_station


def _errors(caplog, text: str) -> list[logging.LogRecord]:
    return [r for r in caplog.records if r.levelno >= logging.ERROR and text in r.getMessage()]


def test_a_listener_failing_every_tick_is_one_line_a_minute(caplog) -> None:
    station = make_station()

    def broken(sample) -> None:
        raise RuntimeError("listener bug")

    station.core.subscribe(broken)
    with caplog.at_level(logging.ERROR):
        run_virtual(station.core, station.clock, 30.0)  # 151 ticks at 5 Hz
        assert len(_errors(caplog, "tick listener")) == 1
        first = _errors(caplog, "tick listener")[0]
        assert first.exc_info is not None and "listener bug" in str(first.exc_info[1])  # with its traceback
        station.clock.advance(timedelta(seconds=31).total_seconds())
        run_virtual(station.core, station.clock, 1.0)
    later = _errors(caplog, "tick listener")
    assert len(later) == 2 and "more like this" in later[1].getMessage()


def test_a_broken_status_field_is_logged_whole_and_status_still_answers(caplog) -> None:
    station = make_station()

    def extra() -> dict[str, object]:
        raise KeyError("rotor_az")

    protocol = NovaTcpProtocol(station.core, extra)
    with caplog.at_level(logging.ERROR):
        lines = [protocol.status_line() for _ in range(20)]
    assert all(parse_status(line)["extra_error"] == "KeyError" for line in lines)
    logged = _errors(caplog, "STATUS fields")
    assert len(logged) == 1 and logged[0].exc_info is not None and "rotor_az" in str(logged[0].exc_info[1])
