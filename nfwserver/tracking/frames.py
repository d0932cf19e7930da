"""Frame rotations: SGP4's TEME to the Earth-fixed ITRS, and ITRS to the observer's topocentric frame.

TEME is rotated into the Earth-fixed frame about the z axis by the IAU 1982 Greenwich mean
sidereal angle at UT1 (:func:`nfwserver.tracking.timescale.gmst1982`); velocities lose the
Earth's rotation (``v_itrs = R v_teme - omega x r_itrs``).  Polar motion is neglected, as in
skyfield's default ``TEME -> ITRS`` path.  The topocentric frame is the observer's geodetic
east-north-up frame; azimuth is degrees clockwise from true north (0..360), elevation degrees
above the geodetic horizontal, range km, range rate km/s (positive receding).

This module holds the one vectorised implementation (numpy, any leading shape); the one
hand-written scalar fast path (:class:`ScalarLookAngles`, pure ``math``, used on every publish
tick) lives in :mod:`nfwserver.tracking.scalar_look`, which imports no numpy, and is re-exported here.
Positions are km, velocities km/s, times split UTC Julian dates ``jd + fr``.
"""

from __future__ import annotations

import numpy as np

from nfwserver.tracking.constants import SECONDS_PER_DAY
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.scalar_look import ScalarLookAngles
from nfwserver.tracking.timescale import gmst1982

__all__ = ["ScalarLookAngles", "TopocentricFrame", "itrs_to_topocentric", "teme_to_itrs"]


def teme_to_itrs(r: np.ndarray, v: np.ndarray | None, jd: float | np.ndarray, fr: float | np.ndarray,
                 ut1_utc: float = 0.0
                 ) -> tuple[np.ndarray, np.ndarray | None]:
    """Rotate TEME states (..., 3) into the ITRS at the UTC instants ``jd + fr``.

    ``jd``/``fr`` broadcast against ``r[..., 0]`` (e.g. shape (times,) for r of shape
    (sats, times, 3)).  ``v`` may be None (positions only, e.g. the Sun or the Moon).
    """
    theta, theta_dot = gmst1982(jd, np.asarray(fr) + ut1_utc / SECONDS_PER_DAY)
    c, s = np.cos(theta), np.sin(theta)
    x = c * r[..., 0] + s * r[..., 1]
    y = -s * r[..., 0] + c * r[..., 1]
    pos = np.stack((x, y, r[..., 2]), axis=-1)
    if v is None:
        return pos, None
    w = theta_dot / SECONDS_PER_DAY
    vel = np.stack((c * v[..., 0] + s * v[..., 1] + w * y, -s * v[..., 0] + c * v[..., 1] - w * x, v[..., 2]),
                   axis=-1)
    return pos, vel


class TopocentricFrame:
    """An observer's east-north-up frame as numpy vectors, for many positions at once."""

    __slots__ = ("origin", "east", "north", "up", "axes")

    def __init__(self, observer: Observer) -> None:
        self.origin = np.array(observer.itrs_km())
        self.east, self.north, self.up = (np.array(b) for b in observer.enu_basis())
        #: the (east, north, up) unit vectors as tuples of floats (for sums of products)
        self.axes = tuple(tuple(float(c) for c in b) for b in observer.enu_basis())

    def components(self, vectors: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(east, north, up) components of ITRS vectors (..., 3), in their unit (km, km/s, ...).

        Written as sums of products rather than matrix products: numpy hands a large matrix product to
        BLAS, whose worker threads then keep spinning on the other cores after a few microseconds of work.
        """
        x, y, z = vectors[..., 0], vectors[..., 1], vectors[..., 2]
        (ex, ey, ez), (nx, ny, nz), (ux, uy, uz) = self.axes
        return x * ex + y * ey + z * ez, x * nx + y * ny + z * nz, x * ux + y * uy + z * uz

    def look_angles(self, pos: np.ndarray, vel: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """Azimuth (deg), elevation (deg), range (km), range rate (km/s; None without ``vel``)."""
        d = pos - self.origin
        east, north, up = self.components(d)
        rng = np.sqrt(east * east + north * north + up * up)
        az = np.degrees(np.arctan2(east, north)) % 360.0
        el = np.degrees(np.arcsin(up / rng))
        rr = None if vel is None else np.einsum("...i,...i->...", d, vel) / rng
        return az, el, rng, rr


def itrs_to_topocentric(observer: Observer, pos: np.ndarray, vel: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Azimuth (deg), elevation (deg), range (km), range rate (km/s) of ITRS states (..., 3)."""
    az, el, rng, rr = TopocentricFrame(observer).look_angles(pos, vel)
    assert rr is not None
    return az, el, rng, rr
