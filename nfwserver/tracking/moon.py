"""Low-precision geocentric Moon position (Astronomical Almanac formulae, about 0.3 degree).

Returns the position in km in the mean equator and equinox of date, good enough for PREDICT's
``GET_MOON`` (EME operators aim wide beams); the topocentric parallax (up to 1 degree) is applied
by the caller by subtracting the observer's position.
"""

from __future__ import annotations

import math

from nfwserver.tracking.constants import ALMANAC_EARTH_RADIUS_KM as EARTH_RADIUS_KM
from nfwserver.tracking.constants import DAYS_PER_JULIAN_CENTURY, JD_J2000


def moon_position_km(jd: float, fr: float = 0.0) -> tuple[float, float, float]:
    """Geocentric Moon position (km), mean equator and equinox of date, at UTC ``jd + fr``."""
    t = (jd - JD_J2000 + fr) / DAYS_PER_JULIAN_CENTURY

    def s(a: float, b: float) -> float:
        return math.sin(math.radians(a + b * t))

    def c(a: float, b: float) -> float:
        return math.cos(math.radians(a + b * t))

    lam = (218.32 + 481267.881 * t + 6.29 * s(135.0, 477198.87) - 1.27 * s(259.3, -413335.36)
           + 0.66 * s(235.7, 890534.22) + 0.21 * s(269.9, 954397.74) - 0.19 * s(357.5, 35999.05)
           - 0.11 * s(186.5, 966404.03))
    beta = (5.13 * s(93.3, 483202.02) + 0.28 * s(228.2, 960400.89) - 0.28 * s(318.3, 6003.15)
            - 0.17 * s(217.6, -407332.21))
    parallax = (0.9508 + 0.0518 * c(135.0, 477198.87) + 0.0095 * c(259.3, -413335.36)
                + 0.0078 * c(235.7, 890534.22) + 0.0028 * c(269.9, 954397.74))
    r = EARTH_RADIUS_KM / math.sin(math.radians(parallax))
    lam_r, beta_r = math.radians(lam), math.radians(beta)
    eps = math.radians(23.439 - 0.0130 * t)
    x = r * math.cos(beta_r) * math.cos(lam_r)
    y_ecl = r * math.cos(beta_r) * math.sin(lam_r)
    z_ecl = r * math.sin(beta_r)
    return x, y_ecl * math.cos(eps) - z_ecl * math.sin(eps), y_ecl * math.sin(eps) + z_ecl * math.cos(eps)
