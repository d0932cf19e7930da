"""Time scales for SGP4: UTC datetimes to split Julian dates, UT1, and GMST (IAU 1982).

SGP4 element epochs are UTC, so the propagator is fed the UTC Julian date, as the ``sgp4``
package and skyfield do.  Rotating SGP4's TEME frame into the Earth-fixed frame needs the
Greenwich mean sidereal angle at UT1 = UTC + (UT1 - UTC).  |UT1 - UTC| stays below 0.9 s by
definition of UTC; leaving it at 0 rotates the Earth by up to 0.9 s x 15.04"/s = 0.0038 deg,
which moves a LEO satellite's azimuth and elevation by about 0.002 deg and its range rate by
up to about 0.2 m/s.  Pass ``ut1_utc`` (IERS Bulletin A, seconds) to remove that error.
"""

from __future__ import annotations

import math
from datetime import datetime, timezone
from typing import Any

from nfwserver.tracking.constants import DAYS_PER_JULIAN_CENTURY, JD_J2000, SECONDS_PER_DAY

#: Julian date of 2000-01-01T00:00:00 UTC.
_JD_2000 = 2451544.5
_EPOCH_2000 = datetime(2000, 1, 1, tzinfo=timezone.utc)
_TAU = 2.0 * math.pi


def julian_date(when: datetime) -> tuple[float, float]:
    """Split Julian date ``(jd, fraction)`` of ``when`` (naive datetimes are taken as UTC).

    ``jd`` ends in .5 (the preceding midnight) and ``fraction`` is the day fraction since then,
    so that microsecond resolution survives in double precision.
    """
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    delta = when - _EPOCH_2000
    return _JD_2000 + delta.days, (delta.seconds + delta.microseconds * 1e-6) / SECONDS_PER_DAY


def gmst1982(jd_ut1: Any, fraction_ut1: Any = 0.0) -> tuple[Any, Any]:
    """Greenwich mean sidereal angle (radians, 0..2pi) and its rate (radians per UT1 day).

    Takes floats or numpy arrays (element-wise, broadcasting) and returns the same kind.

    The IAU 1982 expression that defines SGP4's TEME frame (AIAA 2006-6753 appendix C), in the
    same arithmetic as skyfield's ``theta_GMST1982`` so both agree to the last bit.
    """
    t = (jd_ut1 - JD_J2000 + fraction_ut1) / DAYS_PER_JULIAN_CENTURY
    g = 67310.54841 + (8640184.812866 + (0.093104 + (-6.2e-6) * t) * t) * t
    dg = 8640184.812866 + (0.093104 * 2.0 + (-6.2e-6 * 3.0) * t) * t
    theta = (jd_ut1 % 1.0 + fraction_ut1 + g / SECONDS_PER_DAY % 1.0) % 1.0 * _TAU
    theta_dot = (1.0 + dg / (SECONDS_PER_DAY * DAYS_PER_JULIAN_CENTURY)) * _TAU
    return theta, theta_dot
