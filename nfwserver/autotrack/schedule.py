"""A schedule: the candidate passes of a window, each scheduled or left out with its reason.

The passes are kept as the pass search's columns (:class:`~nfwserver.tracking.pass_records.PassList`
columns: times in seconds after :attr:`Schedule.start`, NaN when unknown; angles degrees), in AOS order
(TCA when the AOS is unknown, then catalog number), beside the rule's decisions.  A
:class:`PlannedPass` is made when one is read.  Times on the records are aware UTC datetimes.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from datetime import datetime, timedelta
from functools import cached_property

import numpy as np

from nfwserver.autotrack.rule import NO_BLOCKER, Decisions

__all__ = ["PlannedPass", "Schedule", "clock_minutes"]


@dataclass(frozen=True, slots=True)
class PlannedPass:
    """One candidate pass and the rule's decision on it."""

    index: int  #: its row in the schedule (AOS order)
    catalog_number: int
    name: str  #: the satellite's DDE name
    priority: int  #: its satellite's place in the list, 0 = highest
    aos: datetime | None  #: None: before the search reached (in progress from before the window)
    tca: datetime
    los: datetime | None  #: None: after the search reached
    max_elevation_deg: float
    scheduled: bool
    reason: str  #: why it is left out ("" when scheduled)

    def in_progress(self, when: datetime) -> bool:
        """True when the pass is under way at ``when`` (AOS <= when < LOS)."""
        return (self.aos is None or self.aos <= when) and (self.los is None or when < self.los)


def clock_minutes(when: datetime | None, offset: Callable[[datetime], timedelta] | None = None) -> str:
    """``HH:MM`` of ``when`` (UTC, or shifted by ``offset(when)``), truncated; ``--:--`` when unknown."""
    if when is None:
        return "--:--"
    if offset is not None:
        when = when + offset(when)
    return f"{when.hour:02d}:{when.minute:02d}"


@dataclass(frozen=True)
class Schedule:
    """The rule applied to the candidate passes between ``start`` and ``end`` (aware UTC)."""

    start: datetime
    end: datetime
    columns: dict[str, np.ndarray]  #: PassList columns of the candidate passes, AOS order
    decisions: Decisions  #: per row of ``columns``
    priorities: tuple[int, ...]  #: catalog numbers, highest priority first
    names: Mapping[int, str]  #: DDE name by catalog number
    min_el_deg: float
    min_gap_s: float
    #: reasons of passes left out by an earlier plan (row -> reason), kept when re-planned
    carried_reasons: Mapping[int, str] = field(default_factory=dict)
    problems: tuple[str, ...] = ()  #: listed satellites that could not be planned, and why

    def __len__(self) -> int:
        return len(self.columns["tca_s"])

    def _time(self, seconds: float) -> datetime | None:
        return None if math.isnan(seconds) else self.start + timedelta(seconds=seconds)

    def pass_at(self, row: int, offset: Callable[[datetime], timedelta] | None = None) -> PlannedPass:
        """Row ``row`` as a record (its reason's clock times shifted by ``offset``, e.g. a local zone)."""
        cols = self.columns
        number = int(cols["catalog_number"][row])
        tca = self._time(float(cols["tca_s"][row]))
        assert tca is not None
        return PlannedPass(row, number, self.names.get(number, str(number)), self.priorities.index(number),
                           self._time(float(cols["aos_s"][row])), tca, self._time(float(cols["los_s"][row])),
                           float(cols["max_elevation_deg"][row]), bool(self.decisions.scheduled[row]),
                           self.reason(row, offset))

    def reason(self, row: int, offset: Callable[[datetime], timedelta] | None = None) -> str:
        """Why row ``row`` is left out: ``overlaps SO-50 04:09-04:23``, ``too close to SO-50 04:09-04:23 (38 s
        apart, min_gap_s 60)``; "" when it is scheduled.  Clock times UTC, or shifted by ``offset``."""
        if self.decisions.scheduled[row]:
            return ""
        k = int(self.decisions.blocker[row])
        if k == NO_BLOCKER:
            return self.carried_reasons.get(row, "left out")
        number = int(self.columns["catalog_number"][k])
        times = (f"{clock_minutes(self._time(float(self.columns['aos_s'][k])), offset)}-"
                 f"{clock_minutes(self._time(float(self.columns['los_s'][k])), offset)}")
        what = f"{self.names.get(number, str(number))} {times}"
        separation = float(self.decisions.separation_s[row])
        if separation < 0.0 or math.isnan(separation):
            return f"overlaps {what}"
        return f"too close to {what} ({separation:.0f} s apart, min_gap_s {self.min_gap_s:g})"

    def reasons(self, offset: Callable[[datetime], timedelta] | None = None) -> list[str]:
        """Every row's reason ("" for the scheduled ones)."""
        return [self.reason(i, offset) for i in range(len(self))]

    def scheduled_rows(self) -> np.ndarray:
        """The rows of the scheduled passes, in AOS order."""
        return self._scheduled[0]

    @cached_property
    def _scheduled(self) -> tuple[np.ndarray, np.ndarray]:
        """The scheduled rows and their LOS (s after the start; +inf when unknown), both ascending: scheduled
        passes are apart, so their LOS are in AOS order (made by the rule, not by a later element update)."""
        rows = np.flatnonzero(self.decisions.scheduled)
        los = self.columns["los_s"][rows]
        return rows, np.maximum.accumulate(np.where(np.isnan(los), np.inf, los)) if len(los) else los

    def current_or_next_row(self, when: datetime) -> int | None:
        """The row of the scheduled pass in progress at ``when``, else of the next one; None when no scheduled
        pass ends after ``when``.  Its satellite is the one selected at ``when``: the next pass's from the
        previous scheduled pass's LOS on."""
        rows, los = self._scheduled
        k = int(np.searchsorted(los, (when - self.start).total_seconds(), side="right"))
        return int(rows[k]) if k < len(rows) else None

    def current_or_next(self, when: datetime) -> PlannedPass | None:
        """The pass of :meth:`current_or_next_row` as a record."""
        row = self.current_or_next_row(when)
        return self.pass_at(row) if row is not None else None

