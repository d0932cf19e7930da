"""Where the Sun and the Moon are in an observer's sky (PREDICT's ``GET_SUN`` / ``GET_MOON`` values).

Inputs are geocentric positions (km) in the mean equator and equinox of date from
:mod:`nfwserver.tracking.sun` and :mod:`nfwserver.tracking.moon`; that frame is treated as TEME
(within 0.005 degree) and rotated to the Earth-fixed frame by :mod:`nfwserver.tracking.frames`.
Angles are degrees; the observer's position is subtracted, so the Moon's parallax is included.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime

import numpy as np

from nfwserver.tracking.constants import SECONDS_PER_DAY
from nfwserver.tracking.frames import TopocentricFrame, teme_to_itrs
from nfwserver.tracking.moon import moon_position_km
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.sun import sun_position_km
from nfwserver.tracking.timescale import gmst1982, julian_date


@dataclass(frozen=True)
class BodyView:
    """A body seen from the observer, and its equatorial coordinates of date."""

    azimuth_deg: float  #: clockwise from true north, 0..360
    elevation_deg: float  #: above the geodetic horizontal, topocentric
    declination_deg: float  #: geocentric
    greenwich_hour_angle_deg: float  #: 0..360
    right_ascension_deg: float  #: 0..360


def body_view(position_km: np.ndarray | tuple[float, float, float], observer: Observer, when: datetime,
              ut1_utc: float = 0.0) -> BodyView:
    """View of a body at geocentric ``position_km`` (mean equator of date) at ``when`` (UTC)."""
    jd, fr = julian_date(when)
    x, y, z = (float(v) for v in position_km)
    r = math.sqrt(x * x + y * y + z * z)
    dec = math.degrees(math.asin(z / r))
    ra = math.degrees(math.atan2(y, x)) % 360.0
    theta, _ = gmst1982(jd, fr + ut1_utc / SECONDS_PER_DAY)
    gha = (math.degrees(theta) - ra) % 360.0
    fixed, _ = teme_to_itrs(np.array([x, y, z]), None, jd, fr, ut1_utc)
    az, el, _, _ = TopocentricFrame(observer).look_angles(fixed)
    return BodyView(float(az), float(el), dec, gha, ra)


def sun_view(observer: Observer, when: datetime, ut1_utc: float = 0.0) -> BodyView:
    """The Sun's :class:`BodyView` (low-precision ephemeris, about 0.01 degree)."""
    return body_view(sun_position_km(*julian_date(when)), observer, when, ut1_utc)


def moon_view(observer: Observer, when: datetime, ut1_utc: float = 0.0) -> BodyView:
    """The Moon's :class:`BodyView` (low-precision ephemeris, about 0.3 degree)."""
    return body_view(moon_position_km(*julian_date(when)), observer, when, ut1_utc)
