"""The console's pass work and pass table.

:func:`search_passes` is the slow part (a pass search over the favourites and the selected
satellite, and the sky track of the selected satellite's next pass); the console runs it on a
worker thread and hands the :class:`PassSearch` back to the UI thread, where :func:`pass_table`
formats it.  Names are returned as :class:`rich.text.Text`, so they are shown literally.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import datetime, timedelta

from rich.text import Text

from nfwserver.config.table import default
from nfwserver.console.time_display import TimeDisplay
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import Pass, find_passes

#: How far ahead the pass list looks (h), the next-pass search for the selected satellite (h) and
#: the sky track's sampling step (s).
LIST_HOURS = 12.0
NEXT_PASS_HOURS = 24.0
TRACK_STEP_S = 20.0
#: Rows of the pass list.
MAX_ROWS = 8
NAME_WIDTH = 9  #: a row with both marks is 34 characters, the pass pane's width at 80 columns
#: What the marks on a pass row mean (the pass pane's subtitle).
LEGEND = "* in progress  ! old elements"
#: Element sets older than this (days) are flagged under the list (``[elements] stale_days``' default).
STALE_DAYS: float = default("elements", "stale_days")


@dataclass(frozen=True)
class PassSearch:
    """What one search found, for the instant ``now``."""

    now: datetime
    selected: int | None
    passes: list[Pass] = field(default_factory=list)  #: favourites and selected, not yet over, by AOS
    next_pass: Pass | None = None  #: of the selected satellite (in progress or next)
    track: list[tuple[float, float]] = field(default_factory=list)  #: (az, el) deg along next_pass
    #: catalog numbers the search left out: their positions at ``now`` cannot be computed (decayed, or
    #: elements far outside their validity)
    left_out: tuple[int, ...] = ()


def _not_over(passes: Sequence[Pass], now: datetime) -> list[Pass]:
    return [p for p in passes if p.los is None or p.los > now]


def search_passes(catalog: Catalog, observer: Observer, horizon: HorizonTable, ut1_utc: float,
                  wanted: Sequence[int], selected: int | None, now: datetime) -> PassSearch:
    """Passes of ``wanted`` + ``selected`` over the next 12 h, and the selected one's next pass and track."""
    numbers = list(dict.fromkeys([*wanted, *([selected] if selected is not None else [])]))
    sats = [s for s in (catalog.get(n) for n in numbers) if s is not None]
    found = find_passes(sats, observer, now, now + timedelta(hours=LIST_HOURS), horizon=horizon,
                        ut1_utc=ut1_utc) if sats else None
    passes = _not_over(found, now) if found is not None else []
    sat = catalog.get(selected) if selected is not None else None
    next_pass = None
    track: list[tuple[float, float]] = []
    if sat is not None:
        own = [p for p in passes if p.catalog_number == selected]
        if not own:
            own = _not_over(find_passes([sat], observer, now, now + timedelta(hours=NEXT_PASS_HOURS),
                                        horizon=horizon, ut1_utc=ut1_utc), now)
        next_pass = own[0] if own else None
        if next_pass is not None and next_pass.aos is not None and next_pass.los is not None:
            calc = LookAngleCalculator(observer, ut1_utc)
            t = next_pass.aos
            try:
                while t <= next_pass.los:
                    la = calc.compute(sat.satrec, t)
                    track.append((la.azimuth_deg, la.elevation_deg))
                    t += timedelta(seconds=TRACK_STEP_S)
            except PropagationError:
                track = []
    return PassSearch(now, selected, passes, next_pass, track, found.skipped if found is not None else ())


def pass_table(search: PassSearch | None, catalog: Catalog, times: TimeDisplay, now: datetime,
               stale_days: float = STALE_DAYS) -> Text:
    """The pass list under a header: satellite, date, AOS, max elevation, LOS (the pane's title names
    the zone).  A pass already in progress is marked ``*``; a satellite whose elements are more than
    ``stale_days`` old is marked ``!`` (:data:`LEGEND` explains both), and a line under the list says how old
    and what to run; another names
    the satellites the search left out because their positions cannot be computed.
    """
    out = Text()
    out.append(f"{'Satellite':{NAME_WIDTH}} {'Date':5} {'AOS':5} {'Max':>3} {'LOS':5}\n", style="bold")
    if search is None:
        out.append("searching...")
        return out
    rows = [p for p in search.passes if p.los is None or p.los > now][:MAX_ROWS]
    if not rows:
        out.append(f"none in the next {LIST_HOURS:g} h")
        return _left_out(out, search, catalog)
    oldest = 0.0
    for i, p in enumerate(rows):
        sat = catalog.get(p.catalog_number)
        name = sat.dde_name if sat is not None else str(p.catalog_number)
        age = sat.age_days(now) if sat is not None else 0.0
        oldest = max(oldest, age)
        in_progress = p.aos is None or p.aos <= now
        start = p.aos if p.aos is not None else now
        out.append(f"{name[:NAME_WIDTH]:{NAME_WIDTH}} ")
        out.append(f"{times.date(start):5} {times.short(p.aos):5} {p.max_elevation_deg:3.0f} {times.short(p.los):5}")
        if in_progress or age > stale_days:  # the marks' column, no trailing blanks
            out.append(f" {'*' if in_progress else ' '}")
        if age > stale_days:
            out.append("!", style="bold yellow")
        if i < len(rows) - 1:
            out.append("\n")
    if oldest > stale_days:
        out.append(f"\n! elements up to {oldest:.0f} days old (over {stale_days:g}): positions drift; "
                   "run `nfwserver elements update`", style="yellow")
    return _left_out(out, search, catalog)


def _left_out(out: Text, search: PassSearch, catalog: Catalog) -> Text:
    """``out`` with a line naming the satellites the search left out (at most five), when there are some."""
    if search.left_out:
        names = [sat.dde_name if (sat := catalog.get(n)) is not None else str(n) for n in search.left_out[:5]]
        more = ", ..." if len(search.left_out) > 5 else ""
        out.append(f"\n! left out, position cannot be computed now: {', '.join(names)}{more}", style="yellow")
    return out


def next_pass_text(search: PassSearch | None, times: TimeDisplay, now: datetime) -> str:
    """``Next pass 05-08 19:30:39 max 39 deg LOS 19:41:12 UTC`` (or in progress, up for the whole window, or
    none)."""
    if search is None:
        return "Next pass: searching..."
    p = search.next_pass
    if p is None:
        return f"Next pass: none in the next {NEXT_PASS_HOURS:g} h"
    zone = times.zone(now)
    if p.aos is None and p.los is None:  # above the horizon throughout the search (a geostationary satellite)
        return f"Up for the whole window: max {p.max_elevation_deg:.0f} deg at {times.clock(p.tca)} {zone}"
    if p.aos is None or p.aos <= now:
        return (f"Pass in progress: max {p.max_elevation_deg:.0f} deg at {times.clock(p.tca)}, "
                f"LOS {times.clock(p.los)} {zone}")
    return (f"Next pass {times.date(p.aos)} AOS {times.clock(p.aos)} max {p.max_elevation_deg:.0f} deg "
            f"LOS {times.clock(p.los)} {zone}")
