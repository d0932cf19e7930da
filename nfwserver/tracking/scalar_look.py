"""The scalar fast path from SGP4's TEME state to look angles: one state at one instant, pure ``math``.

Used on every publish tick (:class:`ScalarLookAngles.look`) and by the pass search for a few satellites
(:class:`ScalarLookAngles.rise_state`), which must not pay for importing numpy.  Frames and units as in
:mod:`nfwserver.tracking.frames`: TEME rotated into the ITRS by the IAU 1982 GMST at UT1, the observer's
geodetic east-north-up frame; azimuth degrees clockwise from true north (0..360), elevation degrees, range
km, range rate km/s (positive receding); times split UTC Julian dates ``jd + fr``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from nfwserver.tracking.constants import SECONDS_PER_DAY
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.timescale import gmst1982

_DEG = 180.0 / math.pi


class ScalarLookAngles:
    """The scalar fast path: one TEME state at one instant to (az, el, range, range rate).

    Holds only immutable precomputed observer terms, so it is thread-safe.
    """

    __slots__ = ("_ox", "_oy", "_oz", "_e", "_n", "_u", "_ut1_days")

    def __init__(self, observer: Observer, ut1_utc: float = 0.0) -> None:
        self._ut1_days = ut1_utc / SECONDS_PER_DAY
        self._ox, self._oy, self._oz = observer.itrs_km()
        self._e, self._n, self._u = observer.enu_basis()

    def itrs(self, r: Sequence[float], v: Sequence[float], jd: float, fr: float
             ) -> tuple[float, float, float, float, float, float]:
        """ITRS position (km) and velocity (km/s) of the TEME state ``r``, ``v`` at ``jd + fr`` (UTC)."""
        theta, theta_dot = gmst1982(jd, fr + self._ut1_days)
        c, s = math.cos(theta), math.sin(theta)
        x = c * r[0] + s * r[1]
        y = -s * r[0] + c * r[1]
        w = theta_dot / SECONDS_PER_DAY
        return x, y, r[2], c * v[0] + s * v[1] + w * y, -s * v[0] + c * v[1] - w * x, v[2]

    def _topocentric(self, r: Sequence[float], v: Sequence[float], jd: float, fr: float
                     ) -> tuple[float, float, float, float, float]:
        """(azimuth deg, up km, range km, range rate km/s, up rate km/s) of a TEME state: the local frame's
        parts :meth:`look` and :meth:`rise_state` are made of."""
        x, y, z, vx, vy, vz = self.itrs(r, v, jd, fr)
        dx, dy, dz = x - self._ox, y - self._oy, z - self._oz
        e, n, u = self._e, self._n, self._u
        east = e[0] * dx + e[1] * dy
        north = n[0] * dx + n[1] * dy + n[2] * dz
        up = u[0] * dx + u[1] * dy + u[2] * dz
        rng = math.sqrt(dx * dx + dy * dy + dz * dz)
        az = math.atan2(east, north) * _DEG
        if az < 0.0:
            az += 360.0
        return az, up, rng, (dx * vx + dy * vy + dz * vz) / rng, u[0] * vx + u[1] * vy + u[2] * vz

    def look(self, r: Sequence[float], v: Sequence[float], jd: float, fr: float) -> tuple[float, float, float, float]:
        """(azimuth deg, elevation deg, range km, range rate km/s) of a TEME state."""
        az, up, rng, range_rate, _ = self._topocentric(r, v, jd, fr)
        return az, math.asin(up / rng) * _DEG, rng, range_rate

    def rise_state(self, r: Sequence[float], v: Sequence[float], jd: float, fr: float
                   ) -> tuple[float, float, float]:
        """(elevation deg, azimuth deg, d(sin elevation)/dt in 1/s) of a TEME state: the elevation and the
        rate whose sign tells rising from setting (smooth through the zenith, unlike the elevation's)."""
        az, up, rng, range_rate, up_rate = self._topocentric(r, v, jd, fr)
        return math.asin(up / rng) * _DEG, az, (up_rate - up * range_rate / rng) / rng
