"""InstantTrack's realtime values: sub-satellite point, rev and phase, mode, path loss, Doppler, eclipse.

- Sub-satellite point: geodetic latitude/longitude (deg, WGS84) and height (km) under the satellite.
- Rev: revolutions since launch, incremented at each perigee passage (epoch rev + whole mean-anomaly
  turns since the epoch).
- Phase: mean anomaly in 256ths of a circle, 0-255.
- Mode: from a schedule string such as ``003B100J150B240-``: each three-digit phase starts the
  mode named by the following character; the schedule repeats every orbit.
- Path loss: free-space loss (dB) at a frequency over the slant range.
- Doppler: shift (Hz) of a downlink frequency from the range rate.
- Sunlit: whether the satellite is outside the Earth's shadow (:mod:`nfwserver.tracking.sun`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime
from typing import TYPE_CHECKING

import numpy as np

from nfwserver.tracking.bodies import sun_view

if TYPE_CHECKING:
    from sgp4.api import Satrec
from nfwserver.tracking.constants import (
    PREDICT_EARTH_RADIUS_KM,
    PREDICT_FOOTPRINT_FACTOR_KM,
    SECONDS_PER_DAY,
    SPEED_OF_LIGHT_KM_S,
    WGS84_A_KM,
    WGS84_E2,
)
from nfwserver.tracking.doppler import doppler_shift_hz
from nfwserver.tracking.elements import ElementSet
from nfwserver.tracking.frames import ScalarLookAngles, teme_to_itrs
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError
from nfwserver.tracking.maidenhead import latlon_to_locator
from nfwserver.tracking.mode_schedule import mode_at
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.sun import is_sunlit, sun_position_km
from nfwserver.tracking.timescale import julian_date

_E2 = WGS84_E2


@dataclass(frozen=True)
class SubPoint:
    latitude_deg: float  #: geodetic, WGS84
    longitude_deg: float  #: -180..180, east positive
    height_km: float  #: above the ellipsoid
    locator: str  #: 6-character Maidenhead locator


def geodetic_from_itrs(x: float, y: float, z: float) -> tuple[float, float, float]:
    """Geodetic (lat_deg, lon_deg, height_km) of an Earth-fixed point (km), WGS84, iterated to 1e-12 rad."""
    lon = math.atan2(y, x)
    p = math.hypot(x, y)
    lat = math.atan2(z, p * (1.0 - _E2))
    height = 0.0
    for _ in range(10):
        sin_lat = math.sin(lat)
        n = WGS84_A_KM / math.sqrt(1.0 - _E2 * sin_lat * sin_lat)
        height = p / math.cos(lat) - n if abs(lat) < 1.4 else z / sin_lat - n * (1.0 - _E2)
        new = math.atan2(z, p * (1.0 - _E2 * n / (n + height)))
        if abs(new - lat) < 1e-12:
            lat = new
            break
        lat = new
    return math.degrees(lat), math.degrees(lon), height


def sub_satellite_point(satrec: Satrec, when: datetime, ut1_utc: float = 0.0) -> tuple[float, float, float] | None:
    """(geodetic latitude deg, east longitude deg -180..180, altitude km) under the satellite, or None when
    SGP4 fails.  SGP4's TEME position taken to the ITRS by the one rotation of :mod:`~nfwserver.tracking.frames`
    (GMST 1982 at UT1), polar motion neglected (metres)."""
    jd, fr = julian_date(when)
    err, r, _ = satrec.sgp4(jd, fr)
    if err:
        return None
    pos, _ = teme_to_itrs(np.asarray(r, dtype=float), None, jd, fr, ut1_utc)
    lat, lon, alt = geodetic_from_itrs(float(pos[0]), float(pos[1]), float(pos[2]))
    return lat, (lon + 180.0) % 360.0 - 180.0, alt


def revolution_and_phase(elements: ElementSet, when: datetime) -> tuple[int, int]:
    """(rev number, phase 0-255) at ``when`` from the mean motion and its first derivative."""
    dt = (when - elements.epoch).total_seconds() / SECONDS_PER_DAY
    fields_ndot = _ndot(elements)
    turns = elements.mean_anomaly_deg / 360.0 + elements.mean_motion_rev_per_day * dt + fields_ndot * dt * dt
    rev = elements.rev_number + math.floor(turns)
    phase = int((turns - math.floor(turns)) * 256.0) % 256
    return rev, phase


def _ndot(elements: ElementSet) -> float:
    """First derivative of mean motion / 2 (rev/day^2), read back from the canonical line 1."""
    try:
        return float(elements.line1[33:43])
    except ValueError:
        return 0.0


def path_loss_db(range_km: float, frequency_hz: float) -> float:
    """Free-space path loss (dB) over ``range_km`` at ``frequency_hz``."""
    return 20.0 * math.log10(4.0 * math.pi * range_km * frequency_hz / SPEED_OF_LIGHT_KM_S)


@dataclass(frozen=True)
class RealtimeValues:
    """Everything InstantTrack's realtime screen shows for one satellite and instant."""

    time: datetime
    azimuth_deg: float
    elevation_deg: float
    range_km: float
    range_rate_km_s: float
    subpoint: SubPoint
    rev: int
    phase: int
    mode: str | None
    sunlit: bool
    path_loss_db: float | None
    doppler_hz: float | None


def realtime_values(elements: ElementSet, observer: Observer, when: datetime, ut1_utc: float = 0.0,
                    frequency_hz: float | None = None, schedule: str | None = None) -> RealtimeValues:
    """Compute the realtime screen for ``elements`` at ``when``; raises PropagationError if SGP4 fails."""
    la = LookAngleCalculator(observer, ut1_utc).compute(elements.satrec, when)
    jd, fr = julian_date(when)
    _, r_teme, v_teme = elements.satrec.sgp4(jd, fr)
    x, y, z, _, _, _ = ScalarLookAngles(observer, ut1_utc).itrs(r_teme, v_teme, jd, fr)
    lat, lon, height = geodetic_from_itrs(x, y, z)
    sunlit = bool(is_sunlit(np.array(r_teme), sun_position_km(jd, fr)))
    rev, phase = revolution_and_phase(elements, when)
    return RealtimeValues(
        time=when, azimuth_deg=la.azimuth_deg, elevation_deg=la.elevation_deg, range_km=la.range_km,
        range_rate_km_s=la.range_rate_km_s,
        subpoint=SubPoint(lat, (lon + 180.0) % 360.0 - 180.0, height, latlon_to_locator(lat, lon, 6)),
        rev=rev, phase=phase, mode=mode_at(schedule, phase) if schedule else None, sunlit=sunlit,
        path_loss_db=path_loss_db(la.range_km, frequency_hz) if frequency_hz else None,
        doppler_hz=doppler_shift_hz(frequency_hz, la.range_rate_km_s) if frequency_hz else None,
    )


def footprint_km(height_km: float) -> float:
    """PREDICT's footprint diameter (km) for a satellite ``height_km`` above the ellipsoid."""
    return PREDICT_FOOTPRINT_FACTOR_KM * math.acos(PREDICT_EARTH_RADIUS_KM / (PREDICT_EARTH_RADIUS_KM + height_km))


def visibility_code(elevation_deg: float, sunlit: bool, sun_elevation_deg: float) -> str:
    """PREDICT's visibility letter: ``V`` up, lit and the sky dark (Sun at or below -12 deg), ``D`` up and
    lit in daylight or twilight, ``N`` otherwise."""
    if elevation_deg >= 0.0 and sunlit:
        return "V" if sun_elevation_deg <= -12.0 else "D"
    return "N"


@dataclass(frozen=True)
class SatelliteReport:
    """What PREDICT's ``GET_SAT`` reports about a satellite at one instant (besides the next event)."""

    azimuth_deg: float
    elevation_deg: float
    range_km: float
    latitude_deg: float  #: sub-satellite point, geodetic
    longitude_deg: float  #: sub-satellite point, east positive, -180..180
    height_km: float  #: above the WGS84 ellipsoid
    footprint_km: float
    speed_km_s: float  #: TEME (inertial) speed
    rev: int
    phase: int
    sunlit: bool
    visibility: str


def satellite_report(elements: ElementSet, observer: Observer, when: datetime,
                     ut1_utc: float = 0.0) -> SatelliteReport:
    """Look angles, sub-satellite point, footprint, speed, orbit number, phase and visibility.

    Raises :class:`PropagationError` when SGP4 fails.
    """
    jd, fr = julian_date(when)
    err, r, v = elements.satrec.sgp4(jd, fr)
    if err:
        raise PropagationError(err)
    scalar = ScalarLookAngles(observer, ut1_utc)
    az, el, rng, _ = scalar.look(r, v, jd, fr)
    x, y, z, _, _, _ = scalar.itrs(r, v, jd, fr)
    lat, lon, height = geodetic_from_itrs(x, y, z)
    sunlit = bool(is_sunlit(np.array(r), sun_position_km(jd, fr)))
    sun_el = sun_view(observer, when, ut1_utc).elevation_deg
    rev, phase = revolution_and_phase(elements, when)
    return SatelliteReport(az, el, rng, lat, (lon + 180.0) % 360.0 - 180.0, height, footprint_km(height),
                           math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), rev, phase, sunlit,
                           visibility_code(el, sunlit, sun_el))
