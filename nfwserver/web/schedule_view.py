"""The autotrack schedule as the page's timeline: the passes of the next hours, scheduled or left out with why.

``/api/passes`` carries it as ``schedule`` (docs/WEB.md): ``null`` when the station has no autotrack schedule,
else the window (``from``, ``to``: ISO-8601 UTC) and every candidate pass overlapping it, in AOS order, with its
satellite (catalog number, DDE name, priority: 0 highest), AOS and LOS (``null`` when beyond the search),
highest elevation (degrees), whether it is scheduled and, when not, the reason (clock times UTC).
"""

from __future__ import annotations

import math
from datetime import datetime, timedelta

from nfwserver.autotrack.schedule import Schedule
from nfwserver.web.state_view import iso

__all__ = ["timeline_part"]


def timeline_part(schedule: Schedule | None, now: datetime, hours: float) -> dict[str, object] | None:
    """The timeline of ``schedule`` from ``now`` for ``hours`` (None without a schedule)."""
    if schedule is None:
        return None
    end = now + timedelta(hours=hours)
    cols = schedule.columns
    start_s, end_s = (now - schedule.start).total_seconds(), (end - schedule.start).total_seconds()
    rows = []
    for row, (aos, los) in enumerate(zip(cols["aos_s"].tolist(), cols["los_s"].tolist())):
        if (not math.isnan(los) and los <= start_s) or (not math.isnan(aos) and aos >= end_s):
            continue
        p = schedule.pass_at(row)
        rows.append({"catalog_number": p.catalog_number, "name": p.name, "priority": p.priority,
                     "aos": iso(p.aos), "los": iso(p.los), "max_el": round(p.max_elevation_deg, 1),
                     "scheduled": p.scheduled, "reason": p.reason})
    return {"from": iso(now), "to": iso(end), "passes": rows}
