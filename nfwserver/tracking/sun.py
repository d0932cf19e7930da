"""Low-precision Sun position and the Earth's shadow.

The Sun's direction uses the Astronomical Almanac's low-precision formulae (good to about
0.01 degree between 1950 and 2050), expressed in the mean equator and equinox of date, which is
within 0.005 degree of SGP4's TEME frame; that is far inside what a shadow test needs.
Distances are km; times are split UTC Julian dates (the formulae's TT-UTC difference of about
70 s moves the Sun by 0.001 degree).
"""

from __future__ import annotations

import numpy as np

from nfwserver.tracking.constants import AU_KM, JD_J2000
from nfwserver.tracking.constants import WGS84_A_KM as EARTH_RADIUS_KM  # the shadow's sphere


def sun_position_km(jd: float | np.ndarray, fr: float | np.ndarray = 0.0) -> np.ndarray:
    """Geocentric Sun position (km), mean equator and equinox of date; shape (..., 3)."""
    n = np.asarray(jd, dtype=float) - JD_J2000 + np.asarray(fr, dtype=float)
    mean_lon = np.radians((280.460 + 0.9856474 * n) % 360.0)
    g = np.radians((357.528 + 0.9856003 * n) % 360.0)
    lam = mean_lon + np.radians(1.915) * np.sin(g) + np.radians(0.020) * np.sin(2.0 * g)
    eps = np.radians(23.439 - 0.0000004 * n)
    r = (1.00014 - 0.01671 * np.cos(g) - 0.00014 * np.cos(2.0 * g)) * AU_KM
    return np.stack((r * np.cos(lam), r * np.cos(eps) * np.sin(lam), r * np.sin(eps) * np.sin(lam)), axis=-1)


def is_sunlit(position_km: np.ndarray, sun_km: np.ndarray) -> bool | np.ndarray:
    """True where the straight line from the satellite to the Sun misses the Earth (a sphere).

    ``position_km`` and ``sun_km`` are geocentric, in the same frame, shape (..., 3).
    """
    p = np.asarray(position_km, dtype=float)
    d = np.asarray(sun_km, dtype=float) - p
    d_len = np.linalg.norm(d, axis=-1)
    u = d / d_len[..., None]
    # Closest approach of the ray p + s u (s >= 0) to the Earth's centre.
    s = -np.einsum("...i,...i->...", p, u)
    closest = np.where(s > 0.0, np.linalg.norm(p + np.maximum(s, 0.0)[..., None] * u, axis=-1),
                       np.linalg.norm(p, axis=-1))
    lit = closest > EARTH_RADIUS_KM
    return bool(lit) if lit.ndim == 0 else lit
