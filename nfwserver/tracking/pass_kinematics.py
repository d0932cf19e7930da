"""Topocentric angles and their first and second time derivatives, for pass searches.

For (satellite, time) pairs this module propagates SGP4 (one compiled call per satellite and
batch), rotates to the Earth-fixed frame (:mod:`nfwserver.tracking.frames`) and returns, per
pair: elevation and azimuth (deg), their rates (deg/s) and second derivatives (deg/s^2),
``f = elevation - horizon(azimuth)`` with ``f'`` and ``f''``, and ``s = sin(elevation)`` with
``s'`` and ``s''`` (1/s, 1/s^2).  ``s`` has the same maxima as the elevation but stays smooth
through near-zenith passes, where the elevation itself has an almost sharp peak.

Second derivatives use an approximate Earth-fixed acceleration (two-body gravity plus the
centrifugal and Coriolis terms; J2 and drag, at most ~0.5 % of it, are left out).  They steer the
refinement's steps, and each pair carries bounds on the errors of ``f'`` (SGP4's velocity differs
from the derivative of its position by up to ~2 m/s) and ``f''`` so that the refinement can tell
when a step is final.  Times are seconds after a reference UTC instant.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from nfwserver.tracking.constants import EARTH_ROTATION_RAD_S, SECONDS_PER_DAY, WGS72_MU_KM3_S2
from nfwserver.tracking.frames import TopocentricFrame
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.timescale import gmst1982

_DEG = 180.0 / np.pi
#: Bound on the acceleration SGP4 adds to two-body gravity (J2 and its short-period terms, drag),
#: relative to the two-body term (J2 alone gives at most ~3 * 1.5 * J2 = 0.5 % at the surface).
_ACC_REL = 6e-3
#: Bound (km/s) on how far SGP4's velocity differs from the time derivative of its position (its
#: short-period terms are not differentiated exactly): measured up to 2.1 m/s over the catalog.
_VEL_ERR_KM_S = 3e-3
#: The Earth's rotation rate (rad/s), for the centrifugal and Coriolis terms of the acceleration.
_OMEGA = EARTH_ROTATION_RAD_S


@dataclass
class Kinematics:
    """Angles and derivatives for a batch of pairs (arrays of one length); NaN/-inf where SGP4 failed.

    The azimuth's derivatives are computed when first read (a pass search needs them only at the
    few pairs whose refinement ends in a round), from the east/north components kept in ``plane``.
    """

    el: np.ndarray
    az: np.ndarray
    el_rate: np.ndarray
    f: np.ndarray
    f_rate: np.ndarray
    f_accel: np.ndarray
    s_rate: np.ndarray
    s_accel: np.ndarray
    el_accel: np.ndarray  #: d2(elevation)/dt2 (deg/s^2)
    f_rate_err: np.ndarray  #: bound on the error of ``f_rate`` from SGP4's velocity (deg/s)
    s_rate_err: np.ndarray  #: bound on the error of ``s_rate`` from SGP4's velocity (1/s)
    up: np.ndarray  #: height above the observer's horizontal plane (km)
    up_accel: np.ndarray  #: its second derivative (km/s^2)
    f_accel_err: np.ndarray  #: bound on the error of ``f_accel`` from the approximate acceleration (deg/s^2)
    #: (e, n, e', n', e'', n'', e^2 + n^2, e e' + n n', SGP4 failed) for the azimuth's derivatives
    plane: tuple[Any, ...] = field(default=(), repr=False)
    _az_rates: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)

    @classmethod
    def empty(cls) -> Kinematics:
        """No pairs."""
        e = np.empty(0)
        return cls(e, e, e, e, e, e, e, e, e, e, e, e, e, e, _az_rates=(e, e))

    @property
    def az_rate(self) -> np.ndarray:
        """d(azimuth)/dt (deg/s)."""
        return self._azimuth_rates()[0]

    @property
    def az_accel(self) -> np.ndarray:
        """d2(azimuth)/dt2 (deg/s^2)."""
        return self._azimuth_rates()[1]

    def azimuth_rates(self, picked: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """d(azimuth)/dt (deg/s) and d2(azimuth)/dt2 (deg/s^2) at the pairs ``picked`` (indices), computed for
        those pairs only unless they are known already."""
        if self._az_rates is not None:
            return self._az_rates[0][picked], self._az_rates[1][picked]
        e, n, e1, n1, e2, n2, q, h, bad = self.plane
        az1, az2 = _azimuth_derivatives(e[picked], n[picked], e1[picked], n1[picked], e2[picked], n2[picked],
                                        q[picked], h[picked], None if bad is None else bad[picked])
        return az1 * _DEG, az2 * _DEG

    def _azimuth_rates(self) -> tuple[np.ndarray, np.ndarray]:
        if self._az_rates is None:
            az1, az2 = _azimuth_derivatives(*self.plane)
            self._az_rates = (az1 * _DEG, az2 * _DEG)
        return self._az_rates


def _azimuth_derivatives(e: np.ndarray, n: np.ndarray, e1: np.ndarray, n1: np.ndarray, e2: np.ndarray,
                         n2: np.ndarray, q: np.ndarray, h: np.ndarray, bad: np.ndarray | None
                         ) -> tuple[np.ndarray, np.ndarray]:
    """First and second time derivatives of the azimuth (rad/s, rad/s^2) from the east and north components
    and their derivatives; ``q = e^2 + n^2``, ``h = e e' + n n'``; NaN where ``bad``."""
    with np.errstate(invalid="ignore", divide="ignore"):
        az1 = (n * e1 - e * n1) / q
        az2 = (n * e2 - e * n2) / q - az1 * 2.0 * h / q
    if bad is not None:
        az1[bad] = np.nan
        az2[bad] = np.nan
    return az1, az2


class PairEvaluator:
    """Propagates (satellite index, seconds after the satellite's reference instant) pairs of a list of ``Satrec``.

    ``jd0 + fr0`` is the reference instant (split UTC Julian date): one for every satellite, or an
    array holding each satellite's own (searches of several groups refined together); ``ut1_utc`` seconds.
    """

    def __init__(self, satrecs: list[Any], observer: Observer, jd0: float | np.ndarray, fr0: float | np.ndarray,
                 ut1_utc: float, horizon: HorizonTable) -> None:
        self.satrecs = satrecs
        self.frame = TopocentricFrame(observer)
        self.jd0, self.fr0, self.ut1_utc = jd0, fr0, ut1_utc
        self.horizon = horizon
        self.calls = 0  #: compiled SGP4 calls made (for profiling and tests)
        self.pairs = 0  #: satellite-time pairs propagated

    def _epoch(self, sat: np.ndarray) -> tuple[float | np.ndarray, float | np.ndarray]:
        """The reference instant (jd0, fr0) of each pair's satellite (one pair of floats when all share it)."""
        jd0, fr0 = self.jd0, self.fr0
        if isinstance(jd0, np.ndarray) and isinstance(fr0, np.ndarray):
            return jd0[sat], fr0[sat]
        return jd0, fr0

    def teme(self, sat: np.ndarray, t: np.ndarray, grouped: bool = False
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """TEME position (n, 3), velocity (n, 3) and SGP4 error codes (n,), in the input order.

        ``grouped``: the pairs of each satellite are already contiguous (no sorting needed).
        """
        if grouped:
            jd0, fr0 = self._epoch(sat)
            return self._propagate(sat, jd0, fr0 + t / SECONDS_PER_DAY)
        order = np.argsort(sat, kind="stable")
        sat_sorted = sat[order]
        jd0, fr0 = self._epoch(sat_sorted)
        r, v, e = self._propagate(sat_sorted, jd0, fr0 + t[order] / SECONDS_PER_DAY)
        back = np.empty_like(order)
        back[order] = np.arange(len(t))
        return r[back], v[back], e[back]

    def _propagate(self, sat: np.ndarray, jd0: float | np.ndarray, fr: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """SGP4 at UTC ``jd0 + fr`` (days) for pairs grouped by satellite: one compiled call per satellite.

        The calls get memoryview slices (the extension reads any buffer of the right length; slicing a
        memoryview costs less than slicing an array, which counts at a few pairs per call).
        """
        n = len(fr)
        e = np.zeros(n, dtype=np.uint8)
        r = np.empty((n, 3))
        v = np.empty((n, 3))
        edges = np.flatnonzero(sat[1:] != sat[:-1]) + 1
        starts = np.concatenate(([0], edges))
        stops = np.concatenate((edges, [n]))
        jd = np.ascontiguousarray(np.broadcast_to(jd0, (n,)), dtype=np.float64)
        jd_m, fr_m, e_m = jd.data, np.ascontiguousarray(fr).data, e.data
        r_m, v_m = r.reshape(-1).data, v.reshape(-1).data
        satrecs = self.satrecs
        if not hasattr(satrecs[0], "_sgp4"):  # sgp4's pure-Python model (sgp4_selfcheck's last resort)
            for a, b, i in zip(starts.tolist(), stops.tolist(), sat[starts].tolist()):
                e[a:b], r[a:b], v[a:b] = satrecs[i].sgp4_array(jd[a:b], fr[a:b])
            return r, v, e
        for a, b, a3, b3, i in zip(starts.tolist(), stops.tolist(), (3 * starts).tolist(), (3 * stops).tolist(),
                                   sat[starts].tolist()):
            satrecs[i]._sgp4(jd_m[a:b], fr_m[a:b], e_m[a:b], r_m[a3:b3], v_m[a3:b3])
        self.calls += len(starts)
        self.pairs += n
        return r, v, e

    def evaluate(self, sat: np.ndarray, t: np.ndarray, grouped: bool = False) -> Kinematics:
        """Angles and derivatives at each pair (``sat`` intp, ``t`` float seconds; see :meth:`teme`)."""
        if not len(sat):
            return Kinematics.empty()
        jd0, fr0 = self._epoch(sat)
        fr = fr0 + t / SECONDS_PER_DAY
        r, v, err = self._propagate(sat, jd0, fr) if grouped else self.teme(sat, t)
        # TEME to ITRS as in frames.teme_to_itrs (the same arithmetic), kept as separate components.
        theta, theta_dot = gmst1982(jd0, fr + self.ut1_utc / SECONDS_PER_DAY)
        c, s = np.cos(theta), np.sin(theta)
        ms = -s
        rx, ry, vx, vy = r[:, 0], r[:, 1], v[:, 0], v[:, 1]
        x = c * rx + s * ry
        y = ms * rx + c * ry
        w = theta_dot / SECONDS_PER_DAY
        vel = (c * vx + s * vy + w * y, ms * vx + c * vy - w * x, v[:, 2])
        return topocentric_derivatives(self.frame, self.horizon, (x, y, r[:, 2]), vel, err)


def _project(axes: tuple[Any, ...], x: np.ndarray, y: np.ndarray, z: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(east, north, up) components of the vectors (x, y, z) on the frame's ``axes``; a zero
    coefficient (the east axis has no z) is skipped."""
    return tuple(x * ax + y * ay + z * az if az else x * ax + y * ay for ax, ay, az in axes)


def topocentric_derivatives(frame: TopocentricFrame, horizon: HorizonTable, pos: tuple[Any, ...], vel: tuple[Any, ...],
                            err: np.ndarray) -> Kinematics:
    """Angles and derivatives from Earth-fixed position (km) and velocity (km/s), each given as its
    (x, y, z) component arrays."""
    x, y, z = pos
    vx, vy, vz = vel
    rad2 = x * x + y * y + z * z
    r_len = np.sqrt(rad2)
    g = -WGS72_MU_KM3_S2 / (rad2 * r_len)
    acc = (g * x + 2.0 * _OMEGA * vy + _OMEGA * _OMEGA * x, g * y - 2.0 * _OMEGA * vx + _OMEGA * _OMEGA * y, g * z)
    ox, oy, oz = frame.origin.tolist()
    axes = frame.axes
    e, n, u = _project(axes, x - ox, y - oy, z - oz)
    e1, n1, u1 = _project(axes, vx, vy, vz)
    e2, n2, u2 = _project(axes, *acc)
    q = e * e + n * n
    h = e * e1 + n * n1
    rho = np.sqrt(q + u * u)
    rho1 = (h + u * u1) / rho
    rho2 = (e1 * e1 + n1 * n1 + u1 * u1 + e * e2 + n * n2 + u * u2 - rho1 * rho1) / rho
    s = u / rho
    s1 = (u1 - s * rho1) / rho
    s2 = (u2 - 2.0 * s1 * rho1 - s * rho2) / rho
    with np.errstate(invalid="ignore", divide="ignore"):
        hz = np.sqrt(q)
        cos_el = hz / rho
        el1 = s1 / cos_el
        el2 = (s2 + s * el1 * el1) / cos_el
        # The acceleration left out (J2, drag) is under _ACC_REL of the two-body one; it enters f''
        # divided by the horizontal distance (and scaled by the horizon's slope).
        f_accel_err = (_ACC_REL * _DEG) * (-g * r_len) / hz
        f_rate_err = (_VEL_ERR_KM_S * _DEG) / hz
        s_rate_err = _VEL_ERR_KM_S * (1.0 + np.abs(s)) / rho
    el = np.degrees(np.arcsin(np.clip(s, -1.0, 1.0)))
    az = np.degrees(np.arctan2(e, n)) % 360.0
    # A flat table's minimum is one number (min_elevation_array would interpolate between copies of it).
    f = el - horizon.minimum if horizon.is_flat else el - horizon.min_elevation_array(az)
    bad = (err != 0) if err.any() else None
    plane = (e, n, e1, n1, e2, n2, q, h, bad)
    az_rates = None
    if horizon.is_flat:
        f_rate, f_accel = el1 * _DEG, el2 * _DEG
    else:
        az1, az2 = _azimuth_derivatives(*plane)
        az_rates = (az1 * _DEG, az2 * _DEG)
        slope = horizon.slope_array(az)
        f_rate = (el1 - slope * az1) * _DEG
        f_accel = (el2 - slope * az2) * _DEG
        f_accel_err = f_accel_err * (1.0 + np.abs(slope))
        f_rate_err = f_rate_err * (1.0 + np.abs(slope))
    if bad is not None:
        f[bad] = -np.inf
        for a in (el, el1, el2, f_rate, f_accel, s1, s2, f_rate_err, s_rate_err, u, u2, f_accel_err):
            a[bad] = np.nan
    return Kinematics(el, az, el1 * _DEG, f, f_rate, f_accel, s1, s2, el2 * _DEG, f_rate_err, s_rate_err, u, u2,
                      f_accel_err, plane, az_rates)
