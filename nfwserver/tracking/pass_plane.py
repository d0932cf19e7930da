"""Pass search, before the screen's SGP4: coarse intervals proven invisible by the orbit's plane alone.

A satellite always lies in the plane of its osculating orbit (the plane of its position and velocity).  The
angle between the observer's geocentric direction and that plane, ``beta``, is therefore a lower bound on the
Earth-central angle between the observer and the satellite, wherever along its orbit the satellite is.  The
Earth carries the observer across the planes of most orbits twice a day, so for much of the day ``beta``
alone exceeds the largest central angle at which the satellite could be above the lowest horizon point, and
the screen need not propagate the satellite there.

The plane is fixed by SGP4 every :data:`PLANE_STEP_S` seconds (a handful of propagations per satellite instead
of one per coarse grid point); between those samples its unit normal is interpolated linearly.  The
osculating plane departs from that interpolation by J2's short-period terms: measured at most 0.042 deg
over a week, every 97 s, with samples 12 h apart, for the 14,538 near-Earth orbits with ``e < 0.1`` of
tests/data/active.txt (tests/tracking/test_pass_plane.py checks 300 of them, every 300 s, against a fifth
of the allowance); :data:`PLANE_SLACK_RAD` allows 0.5 deg.  Within an
interval the observer's direction moves by at most the Earth's rotation rate times the cosine of its
geocentric latitude, and the plane by its sampled turning rate.

Only near-Earth orbits (SGP4's ``method == "n"``: periods under 225 min, no lunar-solar terms) that are
nearly circular (``e <`` :data:`MAX_ECCENTRICITY`) are judged here; the others are left to the screen.
Times are seconds after the search's reference instant; angles radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from nfwserver.tracking.constants import EARTH_ROTATION_RAD_S, SECONDS_PER_DAY, WGS72_MU_KM3_S2
from nfwserver.tracking.timescale import gmst1982

if TYPE_CHECKING:
    from nfwserver.tracking.pass_kinematics import PairEvaluator

#: Spacing (s) of the SGP4 samples that fix each orbit's plane.
PLANE_STEP_S = 12.0 * 3600.0
#: Allowance (rad) for the osculating plane's departure from the interpolated one (0.5 deg; measured 0.042 deg).
PLANE_SLACK_RAD = math.radians(0.5)
#: Largest mean eccentricity judged here (the screen's rate bound for a partly sampled orbit assumes it).
MAX_ECCENTRICITY = 0.01
#: The Earth's rotation rate (rad/s) rounded up (7.3e-5), for bounds.
EARTH_RATE = math.ceil(EARTH_ROTATION_RAD_S * 1e7) / 1e7
#: Relative allowance on the apogee radius (short-period terms) and an absolute one (km).
_RADIUS_SLACK, _RADIUS_SLACK_KM = 1.01, 20.0
#: Largest relative spread of the osculating semi-major axes at the samples of an orbit judged here.
_STEADY = 0.01


@dataclass
class PlaneGeometry:
    """The observer's angle from the orbits' planes at the middle of each coarse interval, and the angle beyond which
    an interval is proven invisible."""

    rows: np.ndarray  #: the judged satellites (indices into the list given)
    #: (judged, intervals): |sin| of the observer's angle from the interpolated plane (not renormalised, so no
    #: larger than it is; 0 for a satellite whose samples could not be trusted)
    sin_beta: np.ndarray
    limit: np.ndarray  #: (judged,): reach + the motion within half an interval + the slack (rad; >= pi/2: none)


def plane_geometry(satrecs: list[Any], origin: np.ndarray, e_lo: float, jd0: float, fr0: float, grid: np.ndarray,
                   ut1_utc: float) -> PlaneGeometry | None:
    """:class:`PlaneGeometry` of the judged ``satrecs`` over the coarse ``grid`` (s after the UTC Julian date
    ``jd0 + fr0``) for an observer at Earth-fixed ``origin`` (km) and the elevation ``e_lo`` (rad); None when none
    can be judged."""
    if not satrecs or not hasattr(satrecs[0], "_sgp4") or len(grid) < 2:
        return None  # sgp4's pure-Python model (no compiled _sgp4 to call): the screen judges every interval
    judged = np.array([getattr(sr, "method", "d") == "n" and sr.ecco < MAX_ECCENTRICITY for sr in satrecs])
    if not judged.any():
        return None
    from sgp4.api import SatrecArray

    rows = np.flatnonzero(judged)
    part = [satrecs[i] for i in rows.tolist()]
    n_samples = max(2, math.ceil(grid[-1] / PLANE_STEP_S) + 1)
    sample_t = np.arange(n_samples) * PLANE_STEP_S
    err, r, v = SatrecArray(part).sgp4(np.full(n_samples, jd0), fr0 + sample_t / SECONDS_PER_DAY)
    apogee_km, steady = _apogees(part, r, v)
    normal = np.cross(r, v)  # (satellites, samples, 3), TEME
    del r, v
    with np.errstate(invalid="ignore", divide="ignore"):
        normal /= np.sqrt(np.sum(normal * normal, axis=-1, keepdims=True))
    sound = (err == 0).all(axis=1) & np.isfinite(normal).all(axis=(1, 2)) & steady
    normal[~sound] = 0.0
    # The plane's turning rate (rad/s): between two samples an angle alpha apart, the renormalised interpolated
    # normal turns at most 2 tan(alpha / 2) / step.
    cosines = np.clip(np.sum(normal[:, 1:] * normal[:, :-1], axis=-1), -1.0, 1.0)
    turn_rate = np.max(2.0 * np.tan(0.5 * np.arccos(cosines)), axis=1) / PLANE_STEP_S
    # sin(beta) at each interval's middle: the normal interpolated linearly between the samples (not
    # renormalised: shorter than a unit vector, so |sin(beta)| comes out no larger than it is for the
    # interpolated plane, which the slack relates to the osculating one), turned into the Earth-fixed frame and
    # dotted with the observer's direction; one matrix product for all of it.
    mid = 0.5 * (grid[:-1] + grid[1:])
    k = np.minimum((mid // PLANE_STEP_S).astype(np.intp), n_samples - 2)
    w = (mid - sample_t[k]) / PLANE_STEP_S
    weights = np.zeros((n_samples, len(mid)))
    columns = np.arange(len(mid))
    weights[k, columns] = 1.0 - w
    weights[k + 1, columns] += w
    theta, _ = gmst1982(np.full(len(mid), jd0), fr0 + (mid + ut1_utc) / SECONDS_PER_DAY)
    c, s = np.cos(theta), np.sin(theta)
    r_obs = float(np.linalg.norm(origin))
    ox, oy, oz = (origin / r_obs).tolist()
    # Earth-fixed (c nx + s ny, c ny - s nx, nz) . (ox, oy, oz) = nx (c ox - s oy) + ny (s ox + c oy) + nz oz.
    factors = np.concatenate((weights * (c * ox - s * oy), weights * (s * ox + c * oy), weights * oz))
    sin_beta = np.abs(normal.transpose(0, 2, 1).reshape(len(part), 3 * n_samples) @ factors)
    # The largest central angle at which the satellite can be above e_lo: at its highest (apogee, with room),
    # widened by what the observer and the plane can move in half an interval and by the slack.
    reach = np.arccos(np.clip(r_obs * math.cos(e_lo) / apogee_km, -1.0, 1.0)) - e_lo
    half = 0.5 * float(np.max(np.diff(grid)))
    limit = reach + half * (EARTH_RATE * math.hypot(ox, oy) + turn_rate) + PLANE_SLACK_RAD
    return PlaneGeometry(rows, sin_beta, np.where(sound, limit, np.inf))


def _apogees(part: list[Any], r: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The radius (km) no satellite of ``part`` exceeds, with room: the larger of its mean apogee at the epoch and
    the osculating apogees at the samples (TEME ``r`` km, ``v`` km/s, (satellites, samples, 3)); and whether its
    orbit held steady over the samples (osculating semi-major axes within :data:`_STEADY` of each other and
    eccentricities under 0.1).  A set long past its epoch or decayed can give SGP4 orbits that wander; those are
    left to the screen."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        radius = np.sqrt(np.sum(r * r, axis=-1))
        speed2 = np.sum(v * v, axis=-1)
        axis = 1.0 / (2.0 / radius - speed2 / WGS72_MU_KM3_S2)  # vis-viva: negative or inf when unbound
        ecc_vec = ((speed2 - WGS72_MU_KM3_S2 / radius)[..., None] * r
                   - np.sum(r * v, axis=-1)[..., None] * v) / WGS72_MU_KM3_S2
        ecc = np.sqrt(np.sum(ecc_vec * ecc_vec, axis=-1))
        sampled = np.max(axis * (1.0 + ecc), axis=1)
        steady = ((np.min(axis, axis=1) > 0.0) & (np.max(axis, axis=1) <= np.min(axis, axis=1) * (1.0 + _STEADY))
                  & (np.max(ecc, axis=1) < 0.1) & np.isfinite(sampled))
    mean = np.array([(sr.alta + 1.0) * sr.radiusearthkm for sr in part])
    return np.fmax(mean, sampled) * _RADIUS_SLACK + _RADIUS_SLACK_KM, steady


def plane_possible(satrecs: list[Any], origin: np.ndarray, e_lo: float, jd0: float, fr0: float,
                   grid: np.ndarray, ut1_utc: float) -> np.ndarray | None:
    """Which coarse intervals ``[grid[k], grid[k + 1]]`` (s after the UTC Julian date ``jd0 + fr0``) of each of
    ``satrecs`` (``sgp4`` Satrec) may hold a moment when the satellite is above elevation ``e_lo`` (rad) for an
    observer at Earth-fixed ``origin`` (km): a (satellites, intervals) mask, True where the plane proves
    nothing.  None when no satellite can be judged (nothing would be saved)."""
    geometry = plane_geometry(satrecs, origin, e_lo, jd0, fr0, grid, ut1_utc)
    if geometry is None:
        return None
    limit = geometry.limit
    sin_limit = np.where(limit < 0.5 * math.pi, np.sin(np.minimum(limit, 0.5 * math.pi)), 2.0)
    possible = np.ones((len(satrecs), len(grid) - 1), dtype=bool)
    possible[geometry.rows] = ~(geometry.sin_beta > sin_limit[:, None])
    return possible


#: The error code given to the grid points left unpropagated (SGP4's own codes are 0 to 6).
NOT_PROPAGATED = 255


def propagate_possible(evaluator: PairEvaluator, first: int, possible: np.ndarray, grid: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """SGP4 error codes (satellites, times), TEME positions and velocities (satellites, times, 3; km, km/s) of
    the ``evaluator``'s satellites ``first, first + 1, ...`` (one row of ``possible`` each) at the ends of
    their possible intervals only; elsewhere NaN, with the code :data:`NOT_PROPAGATED`.  The values are
    those of one ``SatrecArray`` call over the whole grid, bit for bit (the same compiled SGP4 per pair)."""
    rows, times = possible.shape[0], len(grid)
    need = np.zeros((rows, times), dtype=bool)
    need[:, :-1] = possible
    need[:, 1:] |= possible
    row, col = np.nonzero(need)  # grouped by satellite, as the evaluator wants them
    r_pairs, v_pairs, e_pairs = evaluator.teme(row + first, grid[col], grouped=True)
    err = np.full((rows, times), NOT_PROPAGATED, dtype=np.uint8)
    r = np.full((rows, times, 3), np.nan)
    v = np.full((rows, times, 3), np.nan)
    err[row, col], r[row, col], v[row, col] = e_pairs, r_pairs, v_pairs
    return err, r, v
