"""Which satellites' positions can be trusted at an instant (InstantTrack's OLD and CRASH checks).

A satellite is *unusable* at ``at`` when SGP4 cannot propagate its set there (decayed, or an
orbit the model refuses) or when the result is implausibly far from the observer: no object in
an SGP4 catalog (Earth orbits) is further than :data:`MAX_PLAUSIBLE_RANGE_KM` (1.5 million km,
about four times the Moon's distance), so a larger range is a set propagated far outside its
validity.  A set is *stale* when its epoch lies more
than ``max_age_days`` (30 by default) before ``at``; stale sets are still used, with a warning.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import datetime, timedelta

import numpy as np

from nfwserver.tracking.catalog import Satellite
from nfwserver.tracking.look_angles import look_angles_array
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.timescale import julian_date

#: Ranges beyond this (km) are treated as propagation failures.
MAX_PLAUSIBLE_RANGE_KM = 1.5e6
#: Element sets older than this (days) before the time asked for are reported as stale.
STALE_AFTER_DAYS = 30.0


@dataclass
class Screened:
    """Satellites split by whether their positions at the screening instant are usable."""

    usable: list[Satellite] = field(default_factory=list)
    unusable: list[Satellite] = field(default_factory=list)


def screen_satellites(satellites: list[Satellite], observer: Observer, at: datetime, ut1_utc: float = 0.0,
                      max_range_km: float = MAX_PLAUSIBLE_RANGE_KM) -> Screened:
    """Split ``satellites`` (objects with ``.satrec``) into usable and unusable at ``at``."""
    result = Screened()
    if not satellites:
        return result
    jd, fr = julian_date(at)
    arr = look_angles_array([s.satrec for s in satellites], observer, np.array([jd]), np.array([fr]), ut1_utc)
    rng = arr.range_km[:, 0]
    with np.errstate(invalid="ignore"):
        good = np.isfinite(rng) & (rng <= max_range_km) & np.isfinite(arr.elevation_deg[:, 0])
    for sat, ok in zip(satellites, good):
        (result.usable if ok else result.unusable).append(sat)
    return result


def stale_satellites(satellites: list[Satellite], at: datetime,
                     max_age_days: float = STALE_AFTER_DAYS) -> list[Satellite]:
    """The satellites whose element epoch is more than ``max_age_days`` before ``at``."""
    oldest = at - timedelta(days=max_age_days)
    return [s for s in satellites if s.elements.epoch < oldest]
