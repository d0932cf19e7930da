"""InstantTrack's mode schedules: ``003B100J150B240-`` names the mode in force at each phase of the orbit.

A schedule is a series of three-digit phases (0..255, 256ths of an orbit, ascending), each followed by the
one-character mode that starts there; it repeats every orbit.  Kept apart from
:mod:`nfwserver.tracking.derived` (which computes the phase) so that the configuration can check schedules
without loading the tracking engine.
"""

from __future__ import annotations

import re

_SCHEDULE = re.compile(r"(\d{3})(.)")


def parse_schedule(schedule: str) -> list[tuple[int, str]]:
    """``003B100J150B240-`` -> [(3, 'B'), (100, 'J'), (150, 'B'), (240, '-')]; ValueError if malformed."""
    text = schedule.strip()
    entries = [(int(m.group(1)), m.group(2)) for m in _SCHEDULE.finditer(text)]
    if not entries or "".join(f"{p:03d}{c}" for p, c in entries) != text:
        raise ValueError(f"schedule {schedule!r} is not a series of three-digit phases each followed by a mode")
    if len(entries) > 12:
        raise ValueError("a schedule holds at most 12 mode changes")
    phases = [p for p, _ in entries]
    if phases != sorted(set(phases)) or phases[-1] > 255:
        raise ValueError("schedule phases must ascend and lie in 0..255")
    return entries


def mode_at(schedule: str, phase: int) -> str:
    """The mode letter in force at ``phase`` (the schedule wraps around the orbit)."""
    entries = parse_schedule(schedule)
    mode = entries[-1][1]
    for start, letter in entries:
        if phase >= start:
            mode = letter
    return mode
