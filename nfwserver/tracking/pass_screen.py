"""Pass search, stage 1: screen a catalog on a coarse grid and bracket every event.

Every satellite is propagated on a common coarse grid (``SatrecArray``, one compiled call), except, under a
flat horizon, the near-circular low orbits whose planes prove most intervals invisible beforehand
(:mod:`~nfwserver.tracking.pass_plane`): those are propagated only at the ends of the intervals left.  From
the Earth-central angle between the observer and the satellite, the largest angle at which it
can be above the lowest horizon point, and a bound on how fast that margin can shrink (the
satellite's angular rate plus the change of the visibility limit with height), each coarse
interval is either proven invisible or kept.

Kept intervals are then sampled: under a flat horizon every 1200 s for a satellite at a low
orbit's angular rate, proportionally longer for slower ones (the coarse points themselves when
that is the coarse step).  The elevation turns only twice an orbit, its maximum and minimum
at least ~2700 s apart even for the lowest orbits, so no step can hold two turns.  Under a
sloping horizon the step is ``fine_step_s`` (60 s) at a low orbit's rate.

Between consecutive samples, the function ``f = elevation - horizon(azimuth)`` and its analytic
rate give three kinds of bracket for :mod:`nfwserver.tracking.pass_refine`:

- **crossings**: ``f`` changes sign (an AOS or a LOS); under a flat horizon at 0 deg each gets a
  first guess, the root of the cubic Hermite interpolant of the height above the observer's
  horizontal plane (smooth, nearly sinusoidal, unlike the elevation);
- **hidden peaks**: ``f`` is negative at both ends but turns from rising to falling in between,
  so a short pass may lie inside;
- **culminations**: the elevation turns from rising to falling with ``f`` positive at an end
  (a maximum inside a pass, a TCA candidate).

Times are seconds after the search start ``t0``; angles degrees; rates degrees per second.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from sgp4.api import SatrecArray

from nfwserver.tracking.constants import SECONDS_PER_DAY, WGS72_MU_KM3_S2
from nfwserver.tracking.frames import TopocentricFrame
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.pass_kinematics import PairEvaluator
from nfwserver.tracking.pass_plane import EARTH_RATE, MAX_ECCENTRICITY, plane_possible, propagate_possible
from nfwserver.tracking.timescale import gmst1982

#: Geocentric angular rate (rad/s) of a low satellite, for which the fine step is ``fine_step_s``.
_LEO_RATE = 1.2e-3
#: Sampling step (s) under a flat horizon for a satellite at ``_LEO_RATE``.
_FLAT_STEP_S = 1200.0
#: Sat-time pairs per compiled screen call (bounds the screen's memory).
_SCREEN_PAIRS = 10000
#: Above this share of a chunk's coarse intervals left possible by the orbits' planes, the whole grid is
#: propagated in one compiled call (cheaper than a call per satellite for the few points saved).
_PLANE_WORTH = 0.8


INTERVAL_FIELDS = ("sat", "a", "b", "ga", "gb", "guess")


@dataclass
class Intervals:
    """Brackets ``[a, b]`` (s) of satellite ``sat`` with the bracketed function's values at the ends."""

    sat: np.ndarray
    a: np.ndarray
    b: np.ndarray
    ga: np.ndarray
    gb: np.ndarray
    guess: np.ndarray  #: first guesses of the solution (s; NaN: none)

    @staticmethod
    def concat(parts: list[Intervals]) -> Intervals:
        return Intervals(*(np.concatenate([getattr(p, k) for p in parts]) for k in INTERVAL_FIELDS))

    @staticmethod
    def empty() -> Intervals:
        return Intervals(np.empty(0, np.intp), *(np.empty(0) for _ in range(5)))

    def select(self, which: np.ndarray) -> Intervals:
        """The intervals picked by a mask or index array."""
        return Intervals(*(getattr(self, k)[which] for k in INTERVAL_FIELDS))

    def __len__(self) -> int:
        return len(self.sat)


@dataclass
class Brackets:
    crossings: Intervals  #: values of f at the ends
    peaks: Intervals  #: values of df/dt at the ends
    culminations: Intervals  #: values of d(elevation)/dt at the ends


def _classify(sat: np.ndarray, t: np.ndarray, f: np.ndarray, f_rate: np.ndarray, el_rate: np.ndarray,
              link: np.ndarray, kept: np.ndarray, up: np.ndarray | None = None,
              up_rate: np.ndarray | None = None, up_jerk_rate: np.ndarray | None = None) -> Brackets:
    """Brackets between samples ``i`` and ``i + 1`` wherever ``link[i]`` (same satellite, adjacent).

    With the height above the horizontal plane ``up`` (km) and its rate (km/s) at the samples (a
    flat horizon at 0 deg, where a crossing is a root of ``up``), crossings get a first guess; with a
    bound on the fourth derivative of ``up`` at each sample's satellite too (``up_jerk_rate``, km/s^4),
    hidden peaks that provably stay below the horizon are dropped and the others get a first guess
    (:func:`_can_rise`).
    """
    i = np.flatnonzero(link)
    j = i + 1
    fa, fb = f[i], f[j]
    cross = np.isfinite(fa) & np.isfinite(fb) & ((fa > 0.0) != (fb > 0.0))
    turn = (f_rate[i] >= 0.0) & (f_rate[j] <= 0.0)
    peak = turn & (fa <= 0.0) & (fb <= 0.0) & kept[i] & np.isfinite(fa) & np.isfinite(fb)
    peak_guess = None
    if up is not None and up_rate is not None and up_jerk_rate is not None and peak.any():
        k = i[peak]
        rise, top_at = _can_rise(t[k], t[k + 1], up[k], up[k + 1], up_rate[k], up_rate[k + 1], up_jerk_rate[k])
        peak[peak] = rise
        peak_guess = top_at[rise]
    culm = (el_rate[i] >= 0.0) & (el_rate[j] <= 0.0) & ((fa > 0.0) | (fb > 0.0))

    def pick(mask: np.ndarray, values: np.ndarray, guess: np.ndarray | None = None) -> Intervals:
        k = i[mask]
        return Intervals(sat[k], t[k], t[k + 1], values[k], values[k + 1],
                         np.full(len(k), np.nan) if guess is None else guess)

    guess = None
    if up is not None and up_rate is not None:
        k = i[cross]
        guess = _hermite_root(t[k], t[k + 1], up[k], up[k + 1], up_rate[k], up_rate[k + 1])
    return Brackets(pick(cross, f, guess), pick(peak, f_rate, peak_guess), pick(culm, el_rate))


def _can_rise(a: np.ndarray, b: np.ndarray, ya: np.ndarray, yb: np.ndarray, da: np.ndarray, db: np.ndarray,
              m4: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Whether the height above the horizontal plane (values ``y`` in km and rates ``d`` in km/s at the ends
    of ``[a, b]``, s) may reach 0 inside: the maximum of its cubic Hermite interpolant plus the
    interpolation error bound ``m4 h^4 / 384`` (``m4``: a bound on the fourth derivative, km/s^4).  A
    hidden peak that cannot rise is dropped here, before any SGP4 call (most hidden peaks are orbits
    passing far from the observer; the refinement would spend two or three evaluations on each).

    Also returns where the interpolant peaks (s): the first guess of the elevation's maximum (the two peak
    within seconds of each other, and the guess saves the refinement about two evaluations a peak)."""
    h = b - a
    p0, p1, m0, m1 = ya, yb, da * h, db * h
    c1 = m0
    c2 = -3.0 * p0 - 2.0 * m0 + 3.0 * p1 - m1
    c3 = 2.0 * p0 + m0 - 2.0 * p1 + m1
    top = np.maximum(p0, p1)
    at = np.where(p0 > p1, 0.0, 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        # Stationary points of the cubic on [0, 1]: roots of c1 + 2 c2 x + 3 c3 x^2.
        disc = c2 * c2 - 3.0 * c3 * c1
        root = np.sqrt(np.maximum(disc, 0.0))
        for x in ((-c2 + root) / (3.0 * c3), (-c2 - root) / (3.0 * c3), -c1 / (2.0 * c2)):
            x = np.clip(np.nan_to_num(x, nan=0.0, posinf=0.0, neginf=0.0), 0.0, 1.0)
            y = p0 + x * (c1 + x * (c2 + x * c3))
            at = np.where(y > top, x, at)
            top = np.maximum(top, y)
    h2 = h * h
    reach: np.ndarray = ~(top + m4 * h2 * h2 / 384.0 < 0.0)  # NaN: kept
    return reach, a + at * h


def _up_jerk_bound(satrecs: list[Any]) -> np.ndarray:
    """A bound (km/s^4) on the fourth time derivative of a satellite's height above any observer's horizontal
    plane: twice that of a Kepler orbit seen from the rotating Earth, ``a (1 + e) (n' + omega)^4`` with the
    mean motion raised to the largest angular rate (perigee) ``n' = n (1 + e)^2 / (1 - e^2)^1.5``; infinite
    (nothing dropped) for orbits with ``e >= 0.1``.  The factor 2 covers SGP4's perturbations (J2's
    short-period terms are ~1e-3 of the motion)."""
    no = np.array([sr.no_kozai for sr in satrecs]) / 60.0  # rad/s
    ecc = np.array([sr.ecco for sr in satrecs])
    with np.errstate(invalid="ignore", divide="ignore"):
        a = (WGS72_MU_KM3_S2 / (no * no)) ** (1.0 / 3.0)
        rate = no * (1.0 + ecc) ** 2 / (1.0 - ecc * ecc) ** 1.5 + EARTH_RATE
        bound = 2.0 * a * (1.0 + ecc) * rate ** 4
    return np.where((ecc < 0.1) & np.isfinite(bound), bound, np.inf)


def _hermite_root(a: np.ndarray, b: np.ndarray, ya: np.ndarray, yb: np.ndarray, da: np.ndarray,
                  db: np.ndarray) -> np.ndarray:
    """The root in ``[a, b]`` of the cubic Hermite interpolant of values ``y`` and rates ``d``
    (signs of ``ya`` and ``yb`` differ): a few Newton steps from the secant, kept inside."""
    h = b - a
    p0, p1, m0, m1 = ya, yb, da * h, db * h
    # y(x) = c0 + c1 x + c2 x^2 + c3 x^3 on x in [0, 1]
    c0, c1 = p0, m0
    c2 = -3.0 * p0 - 2.0 * m0 + 3.0 * p1 - m1
    c3 = 2.0 * p0 + m0 - 2.0 * p1 + m1
    with np.errstate(invalid="ignore", divide="ignore"):
        x = np.clip(p0 / (p0 - p1), 0.0, 1.0)
        for _ in range(4):
            y = c0 + x * (c1 + x * (c2 + x * c3))
            dy = c1 + x * (2.0 * c2 + 3.0 * x * c3)
            x = np.clip(x - y / dy, 0.0, 1.0)
    return np.where(np.isfinite(x), a + x * h, np.nan)


def screen(satrecs: list[Any], frame: TopocentricFrame, horizon: HorizonTable, jd0: float, fr0: float,
           span_s: float, coarse_step_s: float, fine_step_s: float, ut1_utc: float,
           evaluator: PairEvaluator) -> Brackets:
    """Brackets of every event of ``satrecs`` within ``[0, span_s]`` seconds after ``jd0 + fr0``."""
    n_steps = max(1, math.ceil(span_s / coarse_step_s))
    grid = np.linspace(0.0, n_steps * coarse_step_s, n_steps + 1)
    jd = np.full(grid.shape, jd0)
    fr = fr0 + grid / SECONDS_PER_DAY
    # The rotation of TEME into the Earth-fixed frame at each grid time (as frames.teme_to_itrs).
    theta, theta_dot = gmst1982(jd, fr + ut1_utc / SECONDS_PER_DAY)
    rotation = (np.cos(theta), np.sin(theta), theta_dot / SECONDS_PER_DAY)
    flat = horizon.is_flat
    parts: list[Brackets] = []
    chunk = max(1, _SCREEN_PAIRS // len(grid))
    for i0 in range(0, len(satrecs), chunk):
        part = satrecs[i0 : i0 + chunk]
        # Under a flat horizon, the intervals the orbits' planes prove invisible are not propagated (under a
        # sloping one the sampling step depends on the rate bound, which all the grid's points give).
        possible = plane_possible(part, frame.origin, _lowest(horizon), jd0, fr0, grid, ut1_utc) if flat else None
        if possible is not None and possible.mean() <= _PLANE_WORTH:
            err, r, v = propagate_possible(evaluator, i0, possible, grid)
        else:
            possible = None
            err, r, v = SatrecArray(part).sgp4(jd, fr)
        pos, vel = _earth_fixed(r, v, rotation)
        del r, v
        ecc = np.array([sr.ecco for sr in part])
        partly: np.ndarray | None = None if possible is None else ~np.all(possible, axis=1)
        kept, bound = _visibility(frame, horizon, pos, vel, err == 0, ecc, coarse_step_s, partly)
        if possible is not None:
            kept &= possible
        # Sampling step: under a flat horizon f turns only where the elevation does, twice an orbit,
        # so a step under half the time between the turns (1200 s at a low orbit's rate) leaves at
        # most one turn per step; a sloping horizon adds turns at its own corners.
        base = _FLAT_STEP_S if flat else fine_step_s
        wanted = base * np.clip(_LEO_RATE / np.maximum(bound, 1e-9), 1.0, max(coarse_step_s / base, 1.0))
        per_sat = np.maximum(1, np.round(coarse_step_s / wanted)).astype(np.intp)
        coarse_only = per_sat == 1
        jerk = _up_jerk_bound(part)
        if coarse_only.all():
            parts.append(_classify_grid(i0, grid, kept, *_coarse_kinematics(frame, horizon, pos, vel, err), jerk))
        elif coarse_only.any():
            sel = np.flatnonzero(coarse_only)
            coarse = _coarse_kinematics(frame, horizon, tuple(c[sel] for c in pos), tuple(c[sel] for c in vel),
                                        err[sel])
            parts.append(_classify_grid(sel + i0, grid, kept[sel], *coarse, jerk[sel]))
        fine = np.flatnonzero(~coarse_only)
        if len(fine):
            parts.append(_fine_samples(fine + i0, kept[fine], per_sat[fine], grid, coarse_step_s, evaluator))
        del pos, vel
    if not parts:
        empty = Intervals.empty()
        return Brackets(empty, empty, empty)
    return Brackets(*(Intervals.concat([getattr(p, k) for p in parts])
                      for k in ("crossings", "peaks", "culminations")))


def _earth_fixed(r: np.ndarray, v: np.ndarray, rotation: tuple[np.ndarray, np.ndarray, np.ndarray]
                 ) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
    """Earth-fixed position (km) and velocity (km/s) components, each (sats, times), of TEME states (sats,
    times, 3) with the rotation's cosine, sine and rate (rad/s) at each time (as frames.teme_to_itrs)."""
    c, s, w = rotation
    ms = -s
    rx, ry, vx, vy = r[..., 0], r[..., 1], v[..., 0], v[..., 1]
    x = c * rx + s * ry
    y = ms * rx + c * ry
    return (x, y, r[..., 2]), (c * vx + s * vy + w * y, ms * vx + c * vy - w * x, v[..., 2])


def _lowest(horizon: HorizonTable) -> float:
    """An elevation (rad) a degree below the horizon's lowest point: what the screen proves a satellite under."""
    return math.radians(max(horizon.minimum - 1.0, -89.0))


def _visibility(frame: TopocentricFrame, horizon: HorizonTable, pos: tuple[Any, ...], vel: tuple[Any, ...],
                ok: np.ndarray, ecc: np.ndarray, coarse_step_s: float, partly: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """Which coarse intervals (sats, times - 1) may hold visibility, and each satellite's bound on how fast its
    visibility margin can shrink (rad/s), from Earth-fixed positions and velocities at the grid times.

    ``partly``: the satellites propagated at some grid points only (near-circular orbits, ``e`` under
    :data:`~nfwserver.tracking.pass_plane.MAX_ECCENTRICITY`): their sampled rates may all lie on one side of the
    orbit, so the largest is raised by what the orbit's eccentricity (``((1 + e) / (1 - e))^2``, the ratio of the
    angular rates at perigee and apogee) and the Earth's rotation (twice its rate) can add elsewhere."""
    obs = frame.origin
    r_obs = float(np.linalg.norm(obs))
    obs_unit = obs / r_obs
    e_lo = _lowest(horizon)
    k_lo = r_obs * math.cos(e_lo)
    x, y, z = pos
    vx, vy, vz = vel
    with np.errstate(invalid="ignore", divide="ignore"):
        rad = np.sqrt(x * x + y * y + z * z)
        psi = np.arccos(np.clip((x * obs_unit[0] + y * obs_unit[1] + z * obs_unit[2]) / rad, -1.0, 1.0))
        ratio = np.clip(k_lo / rad, -1.0, 1.0)
        margin = np.where(ok, psi - (np.arccos(ratio) - e_lo), np.inf)  # > 0: below the lowest point
        del psi, ratio
        # Angular rate of the satellite's direction plus the rate of change of the visibility limit.
        cx, cy, cz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
        rdot = (x * vx + y * vy + z * vz) / rad
        rate = (np.sqrt(cx * cx + cy * cy + cz * cz) + np.abs(k_lo * rdot) * rad / np.sqrt(
            np.maximum(rad * rad - k_lo * k_lo, 1e-6 * rad * rad))) / (rad * rad)
        del cx, cy, cz, rdot, rad
    # Sampled maxima miss the true one by little on near-circular orbits; eccentric orbits
    # (fast perigee passages) get a wider safety factor.
    fastest = np.nanmax(np.where(ok, rate, np.nan), axis=1, initial=0.0)
    if partly is not None:
        e = np.minimum(ecc, MAX_ECCENTRICITY)
        fastest = np.where(partly, fastest * ((1.0 + e) / (1.0 - e)) ** 2 + 2.0 * EARTH_RATE, fastest)
    bound = fastest * (1.1 + 2.0 * ecc) + 1e-5
    reach = bound[:, None] * coarse_step_s
    kept = (margin[:, :-1] + margin[:, 1:] - reach) * 0.5 <= 0.0
    # A failed propagation at one end hides nothing: keep the interval if the other end is close.
    kept |= (np.isinf(margin[:, :-1]) & (margin[:, 1:] <= reach)) | (
        np.isinf(margin[:, 1:]) & (margin[:, :-1] <= reach))
    return kept, bound


def _coarse_kinematics(frame: TopocentricFrame, horizon: HorizonTable, pos: tuple[Any, ...], vel: tuple[Any, ...],
                       err: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None,
                                                 np.ndarray | None]:
    """f, df/dt and d(elevation)/dt (deg, deg/s), each (sats, times), at the coarse points of some satellites
    from their Earth-fixed position and velocity components; and under a flat horizon at 0 deg the height
    above the horizontal plane (km) and its rate (km/s) (None otherwise)."""
    (ex, ey, ez), (nx, ny, nz), (ux, uy, uz) = frame.axes
    ox, oy, oz = frame.origin.tolist()
    dx, dy, dz = pos[0] - ox, pos[1] - oy, pos[2] - oz
    # As frames.TopocentricFrame.components (every term, a zero coefficient too).
    e, n, u = dx * ex + dy * ey + dz * ez, dx * nx + dy * ny + dz * nz, dx * ux + dy * uy + dz * uz
    del dx, dy, dz
    vx, vy, vz = vel
    e1, n1, u1 = vx * ex + vy * ey + vz * ez, vx * nx + vy * ny + vz * nz, vx * ux + vy * uy + vz * uz
    q = e * e + n * n
    rho2 = q + u * u
    flat = horizon.is_flat
    with np.errstate(invalid="ignore", divide="ignore"):
        hz = np.sqrt(q)
        el = np.degrees(np.arctan2(u, hz))
        # d(el)/dt = (u' rho^2 - u rho rho') / (rho^2 hz) = (u' q - u (e e' + n n')) / (rho^2 hz)
        el_rate = np.degrees((u1 * q - u * (e * e1 + n * n1)) / (rho2 * hz))
        if flat:  # the table's one minimum elevation everywhere (min_elevation_array gives copies of it)
            f = el - horizon.minimum
            f_rate = el_rate
        else:
            az = np.degrees(np.arctan2(e, n)) % 360.0
            f = el - horizon.min_elevation_array(np.nan_to_num(az))
            f_rate = el_rate - horizon.slope_array(np.nan_to_num(az)) * np.degrees((n * e1 - e * n1) / q)
    bad = err != 0
    f[bad] = -np.inf
    el_rate[bad] = np.nan
    if flat and horizon.minimum == 0.0:
        return f, f_rate, el_rate, u, u1
    return f, f_rate, el_rate, None, None


def _classify_grid(sats: int | np.ndarray, grid: np.ndarray, kept: np.ndarray, f: np.ndarray, f_rate: np.ndarray,
                   el_rate: np.ndarray, up: np.ndarray | None, up_rate: np.ndarray | None,
                   up_jerk: np.ndarray) -> Brackets:
    """Brackets between consecutive coarse points (arrays (sats, times)); ``sats``: the satellite index of
    each row, or of the first row (the rows are then consecutive satellites); ``up_jerk``: each row's bound
    on the fourth derivative of ``up`` (km/s^4, :func:`_up_jerk_bound`)."""
    rows, m = f.shape
    sat_ids = np.repeat(np.arange(sats, sats + rows) if isinstance(sats, int) else sats, m)
    kept_full = np.zeros((rows, m), dtype=bool)
    kept_full[:, :-1] = kept
    link = np.ones((rows, m), dtype=bool)
    link[:, -1] = False
    flat_up = None if up is None else up.ravel()
    flat_up_rate = None if up_rate is None else up_rate.ravel()
    return _classify(sat_ids, np.tile(grid, rows), f.ravel(), f_rate.ravel(), el_rate.ravel(), link.ravel(),
                     kept_full.ravel(), flat_up, flat_up_rate, np.repeat(up_jerk, m))


def _fine_samples(sats: np.ndarray, kept: np.ndarray, per_sat: np.ndarray, grid: np.ndarray,
                  coarse_step_s: float, evaluator: PairEvaluator) -> Brackets:
    """Sample the kept coarse intervals of ``sats`` ``per_sat`` times each and classify the samples.

    A run of consecutive kept intervals shares its inner edges, so each sample appears once and
    the samples stay sorted by (satellite, time).
    """
    row, interval = np.nonzero(kept)
    if len(row) == 0:
        empty = Intervals.empty()
        return Brackets(empty, empty, empty)
    run_end = np.ones(len(row), dtype=bool)
    run_end[:-1] = (row[1:] != row[:-1]) | (interval[1:] != interval[:-1] + 1)
    per = per_sat[row]
    counts = np.where(run_end, per + 1, per)
    sample_row = np.repeat(row, counts)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    step_in = np.arange(len(sample_row)) - first
    step = coarse_step_s / per_sat[sample_row]
    t = grid[np.repeat(interval, counts)] + step_in * step
    k = evaluator.evaluate(sats[sample_row], t)
    link = np.zeros(len(t), dtype=bool)
    link[:-1] = (sample_row[1:] == sample_row[:-1]) & (np.abs(t[1:] - t[:-1] - step[1:]) < 1e-3)
    return _classify(sats[sample_row], t, k.f, k.f_rate, k.el_rate, link, np.ones(len(t), dtype=bool))
