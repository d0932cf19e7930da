"""Skyfield as the independent oracle for look angles and passes (test-only helper)."""

from __future__ import annotations

from datetime import datetime, timezone

import numpy as np
from skyfield.api import EarthSatellite, load, wgs84

from nfwserver.tracking.elements import ElementSet
from nfwserver.tracking.observer import Observer

TS = load.timescale(builtin=True)


def skyfield_satellite(es: ElementSet) -> EarthSatellite:
    return EarthSatellite(es.line1, es.line2, es.name, TS)


def skyfield_topos(observer: Observer):
    return wgs84.latlon(observer.latitude_deg, observer.longitude_deg, elevation_m=observer.altitude_m)


def skyfield_look_angles(es: ElementSet, observer: Observer, times: list[datetime]):
    """(az_deg, el_deg, range_km, range_rate_km_s, dut1_s) arrays from skyfield."""
    t = TS.from_datetimes([w.astimezone(timezone.utc) for w in times])
    topos = skyfield_topos(observer)
    rel = (skyfield_satellite(es) - topos).at(t)
    el, az, dist, _, _, rate = rel.frame_latlon_and_rates(topos)
    return az.degrees, el.degrees, dist.km, rate.km_per_s, np.asarray(t.dut1, dtype=float)
