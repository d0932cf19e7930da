"""Autotrack at run time: follows the station's ticks, keeps a schedule and selects its satellites.

:class:`AutotrackRuntime` is driven by :meth:`~AutotrackRuntime.tick` with the tick's instant (the station's
clock: nothing here reads the time).  It holds the newest schedule, made by the plan provider (a callable
``(now, previous schedule) -> Schedule``, e.g. :class:`~nfwserver.autotrack.planner.StationPlanner`):

- a plan is made at the first tick, again at the first tick after :meth:`~AutotrackRuntime.replan` (new
  elements, a changed configuration) or :meth:`~AutotrackRuntime.switch_on`, every :data:`REPLAN_S` seconds
  (so that the window ahead stays long), and when the clock went back before the plan's start;
- while on, each tick's wanted satellite is the schedule's (the scheduled pass in progress, else the next
  one); when it differs from the one this runtime last selected (or after switching on), the ``select``
  callback is called with its catalog number and returns None when the satellite is selected, else why not.

Plans are kept while off too, so that the next scheduled pass can be shown either way.  Failures are not
latched: a plan that raises or a selection refused is a :attr:`AutotrackStatus.fault`, logged once when the
episode starts and once when it ends, retried every :data:`RETRY_S` seconds; the first success clears it.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timedelta

from nfwserver.autotrack.schedule import PlannedPass, Schedule, clock_minutes

__all__ = ["AutotrackRuntime", "AutotrackStatus", "PlanProvider", "Select"]

log = logging.getLogger(__name__)

#: Makes a schedule for the instant given, from the previous one (None at first).
PlanProvider = Callable[[datetime, Schedule | None], Schedule]
#: Selects a satellite by catalog number: None when done, else why not.
Select = Callable[[int], str | None]

#: Seconds between plans when nothing asks for one sooner.
REPLAN_S = 6 * 3600.0
#: Seconds before a failed plan or a refused selection is tried again.
RETRY_S = 30.0
#: Why autotrack is off when nothing else has been said.
NOT_SWITCHED_ON = "not switched on (AUTO ON, or [autotrack] enabled = true)"


@dataclass(frozen=True)
class AutotrackStatus:
    """What the outputs show of autotrack."""

    on: bool
    off_reason: str | None  #: why it is off (None while on)
    next_pass: PlannedPass | None  #: the scheduled pass in progress, else the next one; None: none planned
    fault: str | None  #: planning or selecting failing now (None when all is well)
    problems: tuple[str, ...]  #: listed satellites that the plan could not use, and why

    def next_pass_text(self) -> str:
        """``SO-50 04:09-04:23`` (UTC) of :attr:`next_pass`, or ``none``."""
        p = self.next_pass
        return "none" if p is None else f"{p.name} {clock_minutes(p.aos)}-{clock_minutes(p.los)}"


class AutotrackRuntime:
    """See the module docstring.  Thread-safe: ticks on one thread, switching and status from others."""

    def __init__(self, planner: PlanProvider, select: Select, on: bool = False,
                 off_reason: str = NOT_SWITCHED_ON, list_warning: Callable[[], str | None] = lambda: None) -> None:
        self._planner, self._select = planner, select
        #: what ``AUTO ON`` says about the list of satellites (nothing to work, names left out), or None
        self.list_warning = list_warning
        self._lock = threading.Lock()
        self._on = on
        self._off_reason = off_reason
        self._schedule: Schedule | None = None
        self._planned_at: datetime | None = None
        self._plan_due = True
        self._plan_asks = 0  #: plans asked for (switching on, replan()): one asked during a plan is not lost
        self._plan_retry: datetime | None = None  #: a failed plan is tried again from then on
        self._plan_fault: str | None = None
        self._selected: int | None = None  #: the satellite this runtime last selected (None after switching on)
        self._switched_on = 0  #: times switched on: a selection begun before the last switch is not recorded
        self._select_retry: datetime | None = None
        self._select_fault: str | None = None

    # -- switching and re-planning (any thread) --------------------------------------------------------------
    @property
    def on(self) -> bool:
        return self._on

    def switch_on(self) -> bool:
        """AUTO ON: plan again and select the schedule's satellite at the next tick.  True when it was off."""
        with self._lock:
            was_on, self._on = self._on, True
            self._off_reason = ""
            self._plan_due, self._selected = True, None
            self._plan_asks += 1
            self._switched_on += 1
            self._plan_retry = self._select_retry = None
        if not was_on:
            log.info("autotrack on")
        return not was_on

    def switch_off(self, reason: str) -> bool:
        """AUTO OFF, or a satellite chosen by someone else; ``reason`` is shown while off.  True when it was on."""
        with self._lock:
            was_on, self._on = self._on, False
            self._off_reason = reason
            self._select_fault = None
        if was_on:
            log.info("autotrack off: %s", reason)
        return was_on

    def replan(self) -> None:
        """The elements or the configuration changed: plan again at the next tick."""
        with self._lock:
            self._plan_due, self._plan_retry = True, None
            self._plan_asks += 1

    # -- reading -----------------------------------------------------------------------------------------------
    @property
    def schedule(self) -> Schedule | None:
        """The newest schedule (None before the first plan)."""
        return self._schedule

    def status(self, now: datetime) -> AutotrackStatus:
        """The status at ``now``."""
        with self._lock:
            schedule = self._schedule
            return AutotrackStatus(self._on, None if self._on else self._off_reason,
                                   schedule.current_or_next(now) if schedule is not None else None,
                                   self._plan_fault or self._select_fault,
                                   schedule.problems if schedule is not None else ())

    # -- ticks (one thread) ----------------------------------------------------------------------------------
    def tick(self, now: datetime) -> int | None:
        """Follow the station to ``now``: plan when due, and while on select the schedule's satellite when it
        changed.  Returns the catalog number selected at this tick, if any."""
        self._plan_if_due(now)
        with self._lock:
            schedule, on, selected = self._schedule, self._on, self._selected
            retry, switched_on = self._select_retry, self._switched_on
        if not on or schedule is None:
            return None
        row = schedule.current_or_next_row(now)
        if row is None:
            return None
        number = int(schedule.columns["catalog_number"][row])
        if number == selected and (retry is None or now < retry):
            return None
        wanted = schedule.pass_at(row)
        why = self._select(wanted.catalog_number)
        with self._lock:
            if not self._on or self._switched_on != switched_on:
                return None  # switched off meanwhile (what was chosen since wins), or off and on: select afresh
            if why is None:
                self._selected, self._select_retry = wanted.catalog_number, None
                if self._select_fault is not None:
                    log.info("autotrack selects again (%s)", wanted.name)
                self._select_fault = None
            else:
                self._selected = wanted.catalog_number  # tried: again after RETRY_S, or at the next change
                self._select_retry = now + timedelta(seconds=RETRY_S)
                if self._select_fault is None:
                    log.warning("autotrack cannot select %s: %s (trying again every %g s)", wanted.name, why,
                                RETRY_S)
                self._select_fault = f"cannot select {wanted.name}: {why}"
        if why is None:
            log.info("autotrack: %s selected for its pass %s-%s (highest %.0f deg)", wanted.name,
                     clock_minutes(wanted.aos), clock_minutes(wanted.los), wanted.max_elevation_deg)
            return wanted.catalog_number
        return None

    def _plan_if_due(self, now: datetime) -> None:
        with self._lock:
            schedule, planned_at = self._schedule, self._planned_at
            due = (self._plan_due or schedule is None or planned_at is None
                   or (now - planned_at).total_seconds() >= REPLAN_S or now < schedule.start)
            if not due or (self._plan_retry is not None and now < self._plan_retry):
                return
            asks = self._plan_asks
        try:
            new = self._planner(now, schedule)
        except Exception as exc:  # a plan that fails must not stop the station: shown, retried
            with self._lock:
                self._plan_retry = now + timedelta(seconds=RETRY_S)
                if self._plan_fault is None:
                    log.warning("autotrack cannot plan: %s (trying again every %g s)", exc, RETRY_S, exc_info=True)
                self._plan_fault = f"cannot plan: {exc}"
            return
        with self._lock:
            if self._plan_fault is not None:
                log.info("autotrack plans again")
            old_problems = schedule.problems if schedule is not None else ()
            self._schedule, self._planned_at = new, now
            self._plan_due = self._plan_asks != asks  # asked again while planning: plan again
            self._plan_retry, self._plan_fault = None, None
        if new.problems and new.problems != old_problems:
            log.warning("autotrack leaves out: %s", "; ".join(new.problems))
