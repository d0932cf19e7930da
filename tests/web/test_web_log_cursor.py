"""The log cursor (each page's place in the log) and :meth:`EventLog.since` it reads by: every line once,
oldest first, at most a frame's worth at a time, the lines the ring lost counted."""

from __future__ import annotations

import json
from datetime import datetime, timedelta, timezone

from nfwserver.core.events import Direction, EventLog
from nfwserver.web.station_parts import MAX_LOG_PER_FRAME, LogCursor

T0 = datetime(2026, 1, 1, tzinfo=timezone.utc)


def _filled(count: int, capacity: int = 5000) -> EventLog:
    events = EventLog(capacity)
    for n in range(count):
        events.add(T0 + timedelta(seconds=n), Direction.OUT, "publish", f"line {n + 1}")
    return events


def _attached(cursor: LogCursor, frame: bytes = b'{"now": 1}') -> dict[str, object]:
    out = json.loads(cursor.attach(frame))
    assert isinstance(out, dict)
    return out


def test_a_cursor_sends_each_line_once_oldest_first_and_at_most_a_frames_worth() -> None:
    events = _filled(5)
    cursor = LogCursor(events)
    assert [line["seq"] for line in cursor.history(3)] == [3, 4, 5]
    assert _attached(cursor) == {"now": 1, "log": [], "log_skipped": 0}
    for n in range(2 * MAX_LOG_PER_FRAME + 10):
        events.add(T0, Direction.IN, "poke", f"poke {n}")
    seqs = []
    for _ in range(3):  # a page far behind catches up over its next frames, losing nothing
        frame = _attached(cursor)
        assert frame["now"] == 1 and frame["log_skipped"] == 0
        assert isinstance(frame["log"], list) and len(frame["log"]) <= MAX_LOG_PER_FRAME
        seqs += [line["seq"] for line in frame["log"]]
    assert seqs == list(range(6, 6 + 2 * MAX_LOG_PER_FRAME + 10))
    assert _attached(cursor)["log"] == []


def test_a_cursor_counts_the_lines_the_ring_no_longer_holds_and_keeps_frame_errors() -> None:
    events = _filled(3, capacity=10)
    cursor = LogCursor(events)
    cursor.history(200)
    for n in range(25):
        events.add(T0, Direction.INFO, "note", f"note {n}")
    frame = _attached(cursor, b'{"frame_error": "the station\'s page is not updating"}')
    assert frame["frame_error"] and frame["log_skipped"] == 15  # seq 4..18 pushed out of the ring of 10
    assert [line["seq"] for line in frame["log"]] == list(range(19, 29))
    assert _attached(LogCursor(EventLog()), b"{}") == {"log": [], "log_skipped": 0}


def test_event_log_since() -> None:
    events = _filled(6, capacity=4)  # holds 3..6
    assert [e.seq for e in events.since(4, 10)[0]] == [5, 6] and events.since(4, 10)[1] == 0
    assert [e.seq for e in events.since(0, 2)[0]] == [3, 4] and events.since(0, 2)[1] == 2
    assert events.since(6, 10) == ([], 0)
