"""Planning a schedule: the listed satellites' passes found by the catalog pass search, then the rule.

The candidate passes are those :func:`nfwserver.tracking.passes.find_passes` (the search ``nfwserver passes``
runs) finds over the horizon table between the window's start and end, whose highest elevation reaches
``min_el_deg``: AOS and LOS are the search's, to the bit.  :mod:`nfwserver.autotrack.rule` decides them.

A re-plan (new elements, a changed configuration) keeps the decisions of the passes already begun: a pass
scheduled stays scheduled and one left out stays out (with its reason), so that a pass is worked whole or not
at all.  The station's planner (:class:`StationPlanner`) starts its window ``min_gap_s`` before the instant, so
that a pass that has just ended still keeps a pass of lower priority too close to it out.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta
from typing import TYPE_CHECKING

import numpy as np

from nfwserver.autotrack.rule import decide
from nfwserver.autotrack.schedule import Schedule
from nfwserver.config.table import default

if TYPE_CHECKING:
    from nfwserver.config.schema import Config
    from nfwserver.tracking.catalog import Catalog, Satellite
    from nfwserver.tracking.horizon import HorizonTable
    from nfwserver.tracking.observer import Observer

__all__ = ["AutotrackSettings", "StationPlanner", "plan_schedule", "resolve_satellites"]

#: A begun pass of a new plan is the same pass as one of the previous plan when their AOS differ by at most this
#: (s): new elements move a pass by seconds at most.
SAME_PASS_S = 120.0


@dataclass(frozen=True)
class AutotrackSettings:
    """What the rule needs from ``[autotrack]``: the satellites, highest priority first (catalog numbers, or
    names as ``SAT=`` takes them), the lowest highest-elevation of a pass worth working (deg) and the gap the
    rotor needs between two passes (s)."""

    satellites: tuple[int | str, ...]
    min_el_deg: float = default("autotrack", "min_el_deg")
    min_gap_s: float = default("autotrack", "min_gap_s")

    @classmethod
    def of(cls, config: Config) -> AutotrackSettings:
        """The settings of ``config`` (satellites: ``[autotrack] satellites``, else the favourites)."""
        return cls(config.autotrack_satellites(), config.autotrack.min_el_deg, config.autotrack.min_gap_s)


#: Why a schedule is empty when the list is.
NO_SATELLITES = "no satellites to work: list them in [autotrack] satellites or [satellites] favourites"


def list_warning(values: Sequence[int | str], catalog: Catalog) -> str | None:
    """What ``AUTO ON`` says about the list ``values`` (highest priority first) in ``catalog``: that autotrack
    has nothing to work and why, or which listed names it leaves out (at most three named); None when it can
    use every one."""
    if not values:
        return f"autotrack is on but has nothing to work: {NO_SATELLITES}"
    sats, problems = resolve_satellites(values, catalog)
    if not problems:
        return None
    said = "; ".join(problems[:3]) + (f"; and {len(problems) - 3} more" if len(problems) > 3 else "")
    return f"autotrack is on; left out: {said}" if sats else f"autotrack is on but has nothing to work: {said}"


def resolve_satellites(values: Sequence[int | str], catalog: Catalog) -> tuple[list[Satellite], list[str]]:
    """The satellites ``values`` name, in order and each once, as ``SAT=`` resolves them (a catalog number; a
    name matching one satellite only), and a sentence for each value that names none or several."""
    found: dict[int, Satellite] = {}
    problems = []
    for value in values:
        text = str(value).strip()
        if isinstance(value, int) or text.isdigit():
            sat = catalog.get(int(text))
            matches = [sat] if sat is not None else []
        else:
            matches = catalog.named(text)
        if len(matches) == 1:
            found.setdefault(matches[0].catalog_number, matches[0])
        elif not matches:
            problems.append(f"{text} is not in the catalog")
        else:
            shown = ", ".join(str(s.catalog_number) for s in matches[:5])
            problems.append(f"{text} names {len(matches)} satellites ({shown}): give a catalog number")
    return list(found.values()), problems


def plan_schedule(catalog: Catalog, observer: Observer, horizon: HorizonTable | None, ut1_utc: float,
                  settings: AutotrackSettings, start: datetime, end: datetime, previous: Schedule | None = None,
                  begun_before: datetime | None = None, workers: int = 1) -> Schedule:
    """The schedule of ``settings`` between ``start`` and ``end`` (aware UTC).  With ``previous``, the passes
    that began before ``begun_before`` (default ``start``) keep their decision in ``previous``."""
    from nfwserver.tracking.passes import find_passes

    sats, problems = resolve_satellites(settings.satellites, catalog)
    if not settings.satellites:
        problems.append(NO_SATELLITES)
    found = find_passes(sats, observer, start, end, horizon=horizon, ut1_utc=ut1_utc, workers=workers)
    problems += [f"{catalog.dde_names_of([n])[0]} has no usable position at the start (decayed, or elements far "
                 "outside their validity)" for n in found.skipped]
    cols = found.columns
    if settings.min_el_deg != 0.0:
        keep = cols["max_elevation_deg"] >= settings.min_el_deg
        cols = {key: value[keep] for key, value in cols.items()}
    numbers = [s.catalog_number for s in sats]
    rank = {n: i for i, n in enumerate(numbers)}
    priority = np.array([rank[n] for n in cols["catalog_number"].tolist()], dtype=np.int64)
    fixed, carried = _carried(cols, start, previous, begun_before or start)
    decisions = decide(cols["aos_s"], cols["los_s"], priority, settings.min_gap_s, fixed)
    names = {s.catalog_number: s.dde_name for s in sats}
    return Schedule(start, end, cols, decisions, tuple(numbers), names, settings.min_el_deg, settings.min_gap_s,
                    carried, tuple(problems))


def _carried(cols: dict[str, np.ndarray], start: datetime, previous: Schedule | None, begun_before: datetime
             ) -> tuple[np.ndarray, dict[int, str]]:
    """For each pass of ``cols`` (times after ``start``): its decision in ``previous`` if it began before
    ``begun_before`` and ``previous`` has it (1 scheduled, 0 left out), else -1; and the carried reasons."""
    fixed = np.full(len(cols["tca_s"]), -1, dtype=np.int64)
    carried: dict[int, str] = {}
    if previous is None or not len(fixed):
        return fixed, carried
    shift = (start - previous.start).total_seconds()  # previous time = this time + shift
    limit = (begun_before - start).total_seconds()
    old = previous.columns
    for row in np.flatnonzero(np.isnan(cols["aos_s"]) | (cols["aos_s"] < limit)).tolist():
        number = int(cols["catalog_number"][row])
        aos = float(cols["aos_s"][row]) + shift
        same = np.flatnonzero(old["catalog_number"] == number)
        for k in same.tolist():
            old_aos = float(old["aos_s"][k])
            if (math.isnan(aos) and math.isnan(old_aos)) or abs(old_aos - aos) <= SAME_PASS_S:
                fixed[row] = int(bool(previous.decisions.scheduled[k]))
                if not fixed[row]:
                    carried[row] = previous.reason(k)
                break
    return fixed, carried


class StationPlanner:
    """The plan provider of a running station: plans from ``min_gap_s`` before the instant to ``hours`` after
    it, from what the callables give at each plan (the live catalog, station and settings); keeps the decisions
    of the previous plan's begun passes."""

    def __init__(self, catalog: Callable[[], Catalog], station: Callable[[], tuple[Observer, HorizonTable, float]],
                 settings: Callable[[], AutotrackSettings], hours: float = 24.0) -> None:
        self.catalog, self.station, self.settings, self.hours = catalog, station, settings, hours

    def __call__(self, now: datetime, previous: Schedule | None) -> Schedule:
        settings = self.settings()
        observer, horizon, ut1_utc = self.station()
        start = now - timedelta(seconds=settings.min_gap_s)
        return plan_schedule(self.catalog(), observer, horizon, ut1_utc, settings, start,
                             now + timedelta(hours=self.hours), previous, begun_before=now)

