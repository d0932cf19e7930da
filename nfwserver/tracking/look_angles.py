"""Look angles from SGP4: azimuth, elevation, range and range rate seen from an observer.

Frames and units: SGP4 gives position (km) and velocity (km/s) in its TEME frame at the UTC
instant it is fed.  TEME is rotated into the Earth-fixed frame by the IAU 1982 GMST at UT1
(:mod:`nfwserver.tracking.timescale`), the Earth's rotation is removed from the velocity, and the
difference from the observer's WGS84 position is expressed in the local geodetic east-north-up
frame.  Azimuth is degrees clockwise from true north (0..360), elevation degrees above the
geodetic horizontal (-90..90), range km, range rate km/s positive when the satellite recedes.
Polar motion and atmospheric refraction are neglected (geometric angles), light time too.
These are the same conventions as skyfield's ``(satellite - topos).at(t).altaz()``.

Two paths: :class:`LookAngleCalculator` for one satellite at one instant (pure ``math``, a few
microseconds, used on every publish tick) and :func:`look_angles_array` for many satellites x
many times through ``sgp4``'s ``SatrecArray`` (numpy).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime

import numpy as np
from sgp4.api import SGP4_ERRORS, Satrec, SatrecArray

from nfwserver.tracking.frames import ScalarLookAngles, itrs_to_topocentric, teme_to_itrs
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.timescale import julian_date


class PropagationError(ArithmeticError):
    """SGP4 could not propagate the elements to the requested time (e.g. the orbit decayed)."""

    def __init__(self, code: int) -> None:
        self.code = code
        super().__init__(f"SGP4 error {code}: {SGP4_ERRORS.get(code, 'unknown error')}")


@dataclass(frozen=True, slots=True)
class LookAngles:
    """Topocentric view of a satellite at one instant."""

    azimuth_deg: float  #: clockwise from true north, 0 <= az < 360
    elevation_deg: float  #: above the geodetic horizontal plane, -90..90
    range_km: float  #: distance observer-satellite
    range_rate_km_s: float  #: d(range)/dt, positive receding


class LookAngleCalculator:
    """Look angles of any satellite from one observer, one instant at a time.

    ``ut1_utc`` is UT1 - UTC in seconds (see :mod:`nfwserver.tracking.timescale` for the effect
    of leaving it at 0).  Thread-safe: holds only immutable precomputed observer terms.
    """

    __slots__ = ("observer", "ut1_utc", "_scalar")

    def __init__(self, observer: Observer, ut1_utc: float = 0.0) -> None:
        if not abs(ut1_utc) <= 1.0:
            raise ValueError(f"UT1-UTC {ut1_utc} s is outside -1..1 s")
        self.observer = observer
        self.ut1_utc = ut1_utc
        self._scalar = ScalarLookAngles(observer, ut1_utc)

    def compute(self, satrec: Satrec, when: datetime) -> LookAngles:
        """Look angles of ``satrec`` (an ``sgp4.api.Satrec``) at ``when`` (aware UTC).

        Raises :class:`PropagationError` when SGP4 fails.
        """
        jd, fr = julian_date(when)
        return self.compute_jd(satrec, jd, fr)

    def compute_jd(self, satrec: Satrec, jd: float, fr: float) -> LookAngles:
        """Like :meth:`compute` for a split UTC Julian date ``jd + fr``."""
        err, r, v = satrec.sgp4(jd, fr)
        if err:
            raise PropagationError(err)
        return LookAngles(*self._scalar.look(r, v, jd, fr))


@dataclass(frozen=True)
class LookAngleArrays:
    """Look angles of many satellites at many times; every array has shape (satellites, times).

    ``error`` holds SGP4's error code (0 = fine); where it is non-zero the other values are NaN.
    """

    azimuth_deg: np.ndarray
    elevation_deg: np.ndarray
    range_km: np.ndarray
    range_rate_km_s: np.ndarray
    error: np.ndarray


def earth_fixed_states(
    satrecs: SatrecArray, jd: np.ndarray, fr: np.ndarray, ut1_utc: float = 0.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Earth-fixed position (km) and velocity (km/s), shapes (sats, times, 3), and error codes."""
    jd = np.atleast_1d(np.asarray(jd, dtype=float))
    fr = np.atleast_1d(np.asarray(fr, dtype=float))
    err, r, v = satrecs.sgp4(jd, fr)
    pos, vel = teme_to_itrs(r, v, jd, fr, ut1_utc)
    assert vel is not None
    return pos, vel, err


def look_angles_array(
    satrecs: SatrecArray | list[Satrec], observer: Observer, jd: np.ndarray, fr: np.ndarray, ut1_utc: float = 0.0
) -> LookAngleArrays:
    """Look angles of every satellite at every time (split UTC Julian dates ``jd + fr``)."""
    if not isinstance(satrecs, SatrecArray):
        satrecs = SatrecArray(list(satrecs))
    pos, vel, err = earth_fixed_states(satrecs, jd, fr, ut1_utc)
    with np.errstate(invalid="ignore"):
        az, el, rng, rr = itrs_to_topocentric(observer, pos, vel)
    bad = err != 0
    if bad.any():
        for a in (az, el, rng, rr):
            a[bad] = np.nan
    return LookAngleArrays(az, el, rng, rr, err)
