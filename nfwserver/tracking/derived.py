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
import re
from dataclasses import dataclass
from datetime import datetime

import numpy as np
from sgp4.api import SatrecArray

from nfwserver.tracking.doppler import SPEED_OF_LIGHT_KM_S, doppler_shift_hz
from nfwserver.tracking.elements import ElementSet
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError, earth_fixed_states
from nfwserver.tracking.maidenhead import latlon_to_locator
from nfwserver.tracking.observer import WGS84_A_KM, WGS84_F, Observer
from nfwserver.tracking.sun import is_sunlit, sun_position_km
from nfwserver.tracking.timescale import julian_date

_E2 = WGS84_F * (2.0 - WGS84_F)
_SCHEDULE = re.compile(r"(\d{3})(.)")


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


def revolution_and_phase(elements: ElementSet, when: datetime) -> tuple[int, int]:
    """(rev number, phase 0-255) at ``when`` from the mean motion and its first derivative."""
    dt = (when - elements.epoch).total_seconds() / 86400.0
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
    pos, _, err = earth_fixed_states(SatrecArray([elements.satrec]), np.array([jd]), np.array([fr]), ut1_utc)
    if err[0, 0]:
        raise PropagationError(int(err[0, 0]))
    lat, lon, height = geodetic_from_itrs(*pos[0, 0])
    _, r_teme, _ = elements.satrec.sgp4(jd, fr)
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
