"""The autotrack runtime on virtual time: ticks, selections, re-plans, switching and faults.

The ``select`` callback is a recorder standing in for the station's selection (the real wiring is the
station's); what it must have been told at each instant is worked out from ``nfwserver passes`` CSV rows by the
rule's words (tests/autotrack/test_schedule_cli.py's oracle), not from the runtime's own schedule.
"""

from __future__ import annotations

import csv
import io
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

from nfwserver.autotrack import AutotrackRuntime, AutotrackSettings, StationPlanner, plan_schedule
from nfwserver.autotrack import runtime as runtime_module
from nfwserver.autotrack.schedule import PlannedPass, Schedule
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import parse_observer
from tests.autotrack.test_schedule_cli import AMATEUR, SIX, _oracle, _time

START = datetime(2026, 5, 8, tzinfo=timezone.utc)
OBSERVER = parse_observer("JO02ae")
PRIORITY = [25544, 27607, 43017, 7530, 44909, 24278]


class Station:
    """What the planner reads (a catalog that can be updated) and a recorder of the selections."""

    def __init__(self, catalog: Catalog) -> None:
        self.catalog = catalog
        self.clock = VirtualClock(START)
        self.selected: int | None = None
        self.calls: list[tuple[datetime, int]] = []
        self.refuse: str | None = None

    def select(self, number: int) -> str | None:
        self.calls.append((self.clock.now(), number))
        if self.refuse is None:
            self.selected = number
        return self.refuse

    def runtime(self, on: bool = True, settings: AutotrackSettings | None = None) -> AutotrackRuntime:
        settings = settings or AutotrackSettings(tuple(SIX))
        planner = StationPlanner(lambda: self.catalog, lambda: (OBSERVER, HorizonTable(), 0.0), lambda: settings)
        return AutotrackRuntime(planner, self.select, on=on)

    def run(self, runtime: AutotrackRuntime, until: datetime, step_s: float = 5.0) -> None:
        while self.clock.now() < until:
            runtime.tick(self.clock.now())
            self.clock.advance(step_s)


def passes_of(schedule: Schedule | None) -> list[PlannedPass]:
    """Every candidate pass of ``schedule``, scheduled or not, in AOS order."""
    assert schedule is not None
    return [schedule.pass_at(row) for row in range(len(schedule))]


def _catalog(path: Path = AMATEUR) -> Catalog:
    return Catalog(load_element_file(path).sets)


def _passes_csv(capsys: pytest.CaptureFixture[str], elements: Path, start: datetime, hours: float) -> list[dict]:
    sats = [arg for name in SIX for arg in ("--sat", name)]
    assert main(["passes", "--elements", str(elements), "--observer", "JO02ae", "--start", start.isoformat(),
                 "--hours", str(hours), *sats, "--min-el", "10", "--format", "csv"]) == 0
    return list(csv.DictReader(io.StringIO(capsys.readouterr().out)))


def _expected_at(rows: list[dict], decisions: dict, when: datetime) -> int | None:
    """The satellite of the first scheduled pass (oracle's decisions) whose LOS is after ``when``."""
    return _Expected(rows, decisions)(when)


class _Expected:
    """:func:`_expected_at` for many instants: the scheduled passes' (AOS, LOS, catalog number) parsed once."""

    def __init__(self, rows: list[dict], decisions: dict) -> None:
        self.passes = sorted((_time(r["aos_utc"]), _time(r["los_utc"]), int(r["catalog_number"])) for r in rows
                             if decisions[(r["catalog_number"], r["aos_utc"])] == "")

    def __call__(self, when: datetime) -> int | None:
        return next((number for _, los, number in self.passes if los > when), None)


def test_a_day_on_virtual_time_selects_the_scheduled_satellite_at_every_tick(capsys) -> None:
    rows = _passes_csv(capsys, AMATEUR, START, 26)
    decisions = _oracle(rows, PRIORITY, 60.0)
    station = Station(_catalog())
    runtime = station.runtime()
    end = START + timedelta(hours=24)
    expected = _Expected(rows, decisions)
    mismatches = []
    while station.clock.now() < end:  # 1 s ticks: every second names the schedule's satellite
        now = station.clock.now()
        runtime.tick(now)
        if station.selected != expected(now):
            mismatches.append((now, station.selected))
        station.clock.advance(1.0)
    assert mismatches == []
    # one call per change, each made right at the previous scheduled pass's LOS (the first at the start)
    changes = [n for i, (_, n) in enumerate(station.calls) if i == 0 or station.calls[i - 1][1] != n]
    assert len(station.calls) == len(changes) > 10
    scheduled = sorted((r for r in rows if decisions[(r["catalog_number"], r["aos_utc"])] == ""),
                       key=lambda r: _time(r["aos_utc"]))
    for when, number in station.calls[1:]:
        before = [r for r in scheduled if _time(r["los_utc"]) <= when]
        assert when - _time(before[-1]["los_utc"]) < timedelta(seconds=1)
        assert number == _expected_at(rows, decisions, when)


def _shifted_so50(tmp_path: Path) -> Path:
    """The amateur file with SO-50's set a little newer and its mean anomaly 40 degrees on."""
    lines = AMATEUR.read_text(encoding="utf-8").splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("1 27607"))
    line1, line2 = lines[k], lines[k + 1]
    epoch = float(line1[18:32]) + 0.0001
    line1 = line1[:18] + f"{epoch:014.8f}" + line1[32:68]
    anomaly = (float(line2[43:51]) + 40.0) % 360.0
    line2 = line2[:43] + f"{anomaly:8.4f}" + line2[51:68]
    lines[k], lines[k + 1] = line1 + str(_checksum(line1)), line2 + str(_checksum(line2))
    path = tmp_path / "amateur-new.txt"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _checksum(line: str) -> int:
    return sum(int(c) if c.isdigit() else c == "-" for c in line[:68]) % 10


def test_new_elements_are_planned_when_replan_is_asked(capsys, tmp_path) -> None:
    newer = _shifted_so50(tmp_path)
    station = Station(_catalog())
    runtime, unaware = station.runtime(), station.runtime(on=False)
    runtime.tick(START)
    unaware.tick(START)
    old = [p.aos for p in passes_of(runtime.schedule) if p.catalog_number == 27607]
    summary = station.catalog.update(load_element_file(newer).sets)
    assert summary.updated == [27607]
    runtime.replan()
    later = START + timedelta(hours=1)
    station.clock.advance(3600.0)
    runtime.tick(later)
    unaware.tick(later)
    assert [p.aos for p in passes_of(unaware.schedule) if p.catalog_number == 27607] == old  # not asked: the old plan
    rows = _passes_csv(capsys, newer, later, 20)
    so50 = [r["aos_utc"] for r in rows if r["catalog_number"] == "27607" and _time(r["los_utc"]) > later]
    got = [f"{p.aos:%Y-%m-%dT%H:%M:%S.%f}"[:23] + "Z" for p in passes_of(runtime.schedule) if p.catalog_number == 27607
           and p.aos is not None and later + timedelta(hours=20) > p.aos]
    assert got == so50 and got != [f"{a:%Y-%m-%dT%H:%M:%S.%f}"[:23] + "Z" for a in old if a > later][:len(got)]
    # and the selections follow the new passes
    decisions = _oracle(rows, PRIORITY, 60.0)
    station.run(runtime, later + timedelta(hours=18), step_s=10.0)
    for when, number in station.calls[1:]:
        assert number == _expected_at(rows, decisions, when)


def test_a_begun_pass_keeps_its_decision_when_replanned() -> None:
    # 05-08: AO-7 06:02-06:23 is left out (overlaps SO-50 05:50-06:03, of higher priority).
    catalog = _catalog()
    settings = AutotrackSettings(tuple(SIX))
    first = plan_schedule(catalog, OBSERVER, None, 0.0, settings, START, START + timedelta(hours=24))
    ao7 = next(p for p in passes_of(first) if p.catalog_number == 7530 and f"{p.aos:%H:%M}" == "06:02")
    assert ao7.reason == "overlaps SO-50 05:50-06:03"
    at = START + timedelta(hours=6, minutes=10)  # SO-50's pass is over, AO-7's under way
    fresh = plan_schedule(catalog, OBSERVER, None, 0.0, settings, at, at + timedelta(hours=24))
    again = plan_schedule(catalog, OBSERVER, None, 0.0, settings, at, at + timedelta(hours=24), previous=first)
    assert fresh.current_or_next(at).catalog_number == 7530  # alone, the rule would now take AO-7 mid-pass
    kept = next(p for p in passes_of(again) if p.catalog_number == 7530 and p.in_progress(at))
    assert not kept.scheduled and kept.reason == "overlaps SO-50 05:50-06:03"
    assert again.current_or_next(at).catalog_number == 44909  # RS-44 07:05


def test_switching_off_stops_selecting_and_on_selects_at_once() -> None:
    station = Station(_catalog())
    runtime = station.runtime()
    runtime.tick(START)
    assert station.calls == [(START, 25544)]
    assert runtime.switch_off("SAT=SO-50 from the console")
    station.selected = 27607
    station.run(runtime, START + timedelta(hours=6))
    assert station.calls == [(START, 25544)]
    status = runtime.status(station.clock.now())
    assert not status.on and status.off_reason == "SAT=SO-50 from the console"
    assert status.next_pass is not None and status.next_pass.scheduled  # still planned while off
    assert runtime.switch_on() and not runtime.switch_on()
    now = station.clock.now()
    runtime.tick(now)
    assert station.calls[-1] == (now, status.next_pass.catalog_number)
    assert runtime.status(now).off_reason is None


def test_a_failing_plan_is_shown_retried_and_cleared() -> None:
    station = Station(_catalog())
    runtime = station.runtime()
    attempts = []
    real = runtime._planner

    def flaky(now, previous):
        attempts.append(now)
        if len(attempts) < 3:
            raise RuntimeError("no observer")
        return real(now, previous)

    runtime._planner = flaky
    station.run(runtime, START + timedelta(seconds=runtime_module.RETRY_S * 1.5), step_s=1.0)
    assert len(attempts) == 2 and attempts[1] - attempts[0] == timedelta(seconds=runtime_module.RETRY_S)
    assert runtime.status(station.clock.now()).fault == "cannot plan: no observer"
    assert station.calls == []
    station.run(runtime, START + timedelta(seconds=runtime_module.RETRY_S * 2.5), step_s=1.0)
    assert len(attempts) == 3 and runtime.status(station.clock.now()).fault is None
    assert station.calls and station.calls[0][1] == 25544


def test_a_refused_selection_is_shown_retried_and_cleared() -> None:
    station = Station(_catalog())
    runtime = station.runtime()
    station.refuse = "satellite 25544 is not in the catalog"
    station.run(runtime, START + timedelta(seconds=runtime_module.RETRY_S * 1.5), step_s=1.0)
    assert [t for t, _ in station.calls] == [START, START + timedelta(seconds=runtime_module.RETRY_S)]
    assert runtime.status(station.clock.now()).fault == "cannot select ISS: satellite 25544 is not in the catalog"
    station.refuse = None
    station.run(runtime, START + timedelta(seconds=runtime_module.RETRY_S * 3), step_s=1.0)
    assert len(station.calls) == 3 and station.selected == 25544
    assert runtime.status(station.clock.now()).fault is None


def test_the_clock_going_back_plans_again() -> None:
    station = Station(_catalog())
    runtime = station.runtime()
    runtime.tick(START + timedelta(hours=3))
    planned = runtime.schedule
    runtime.tick(START)
    assert runtime.schedule is not planned and runtime.schedule.start < START


def test_a_replan_asked_while_planning_is_not_lost() -> None:
    station = Station(_catalog())
    runtime = station.runtime()
    real = runtime._planner
    plans = []

    def asking(now, previous):  # new elements arrive while the plan is being made
        plans.append(now)
        if len(plans) == 1:
            runtime.replan()
        return real(now, previous)

    runtime._planner = asking
    runtime.tick(START)
    runtime.tick(START + timedelta(seconds=1))
    assert len(plans) == 2
    runtime.tick(START + timedelta(seconds=2))
    assert len(plans) == 2


def test_the_status_names_the_next_scheduled_pass() -> None:
    station = Station(_catalog())
    runtime = station.runtime(on=False)
    assert runtime.status(START).next_pass_text() == "none"  # no plan yet
    assert runtime.status(START).off_reason == runtime_module.NOT_SWITCHED_ON
    runtime.tick(START)
    status = runtime.status(START + timedelta(hours=2, minutes=20))  # after ISS's 02:03-02:14 pass
    assert status.next_pass_text() == "SO-50 02:31-02:43"
    assert not status.on and status.fault is None and status.problems == ()
    settings = AutotrackSettings(("ISS", "NOSUCH", 25544))
    runtime = station.runtime(settings=settings)
    runtime.tick(START)
    assert runtime.status(START).problems == ("NOSUCH is not in the catalog",)


def test_an_empty_list_says_why_nothing_is_planned() -> None:
    station = Station(_catalog())
    runtime = station.runtime(settings=AutotrackSettings(()))
    runtime.tick(START)
    status = runtime.status(START)
    assert status.next_pass is None and station.calls == []
    assert status.problems == ("no satellites to work: list them in [autotrack] satellites or [satellites] "
                               "favourites",)


def test_a_sat_and_auto_on_during_autotrack_own_selection_are_followed_by_a_fresh_selection() -> None:
    """Autotrack selects outside its lock (the station's choice lock is taken there).  A client's SAT= (switching
    it off and selecting another satellite) and an AUTO ON, both arriving while that selection is under way,
    left the runtime believing its satellite was selected: it did not select again until the schedule's
    satellite changed, and the client's satellite stayed on with autotrack on."""
    station = Station(_catalog())
    runtime = station.runtime(on=True)
    raced = []

    def select(number: int) -> str | None:
        why = station.select(number)
        if not raced:  # other threads, between the selection and the runtime's record of it
            raced.append(number)
            runtime.switch_off("SAT=43017 from tcp 127.0.0.1:1 chose the satellite")
            station.selected = 43017
            runtime.switch_on()
        return why

    runtime._select = select
    runtime.tick(START)
    runtime.tick(START + timedelta(seconds=1))
    assert len(station.calls) == 2 and station.selected == raced[0], station.calls

