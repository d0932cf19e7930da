"""Pass prediction: AOS, TCA, LOS against a horizon table, for one satellite or whole catalogs.

A pass is an interval during which the satellite's elevation is above the horizon table's minimum
elevation at its azimuth (:mod:`nfwserver.tracking.horizon`): AOS is the upward crossing, LOS the
downward one, TCA the instant of maximum elevation in between.  Times are aware UTC datetimes,
angles degrees.

How the search works, all satellites at once where it can be:

1. **Coarse screen.**  Every satellite is propagated on a coarse grid (``coarse_step_s``) with
   ``SatrecArray``.  From the Earth-central angle between the observer and the satellite, the
   largest angle at which the satellite can be above the lowest horizon point, and a bound on how
   fast that margin can shrink (the satellite's angular rate plus the change of the visibility
   limit with height), each coarse interval is either proven invisible or kept as a candidate.
2. **Fine grid.**  Candidate intervals are sampled every ``fine_step_s`` (longer for slow
   satellites) with the full look-angle computation and the horizon table, giving the function
   ``f = elevation - horizon(azimuth)``.  Near-circular orbits under a flat horizon skip this
   step: their elevation rises and falls in one smooth hump several coarse steps wide, so the
   coarse points already bracket every event.
3. **Events.**  Every sign change of ``f`` is a crossing, refined by safeguarded Newton iteration
   with the analytic rate of ``f`` to well under a millisecond.  Every local maximum of ``f`` on
   the samples that is below zero but could reach it between samples is refined by parabolic
   search, so passes shorter than the sampling step are found.  TCA is the root of the
   elevation rate, found by the Illinois method around the best of nine samples of the pass.

Passes already in progress at ``start`` are reported with their true AOS before ``start``
(``aos_before_start``), passes in progress at ``end`` with their LOS after it: the search looks
back and ahead by one orbital period (at most a day).  A satellite that stays up over the whole
extended search (a geostationary satellite, say) has no AOS or LOS and gets no pass, rather than
bogus events; one whose rise or set lies beyond the extension gets ``None`` for that time.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone

import numpy as np
from sgp4.api import Satrec, SatrecArray

from nfwserver.tracking.constants import SECONDS_PER_DAY
from nfwserver.tracking.frames import itrs_to_topocentric, teme_to_itrs
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.timescale import julian_date

_FLAT = HorizonTable()


@dataclass(frozen=True)
class Pass:
    """One pass of one satellite over the horizon table."""

    catalog_number: int
    aos: datetime | None  #: rise above the horizon table (None: earlier than the search reached)
    tca: datetime  #: maximum elevation
    los: datetime | None  #: set below the horizon table (None: later than the search reached)
    max_elevation_deg: float
    aos_azimuth_deg: float | None
    los_azimuth_deg: float | None
    aos_before_start: bool = False  #: the pass was in progress at the window start
    los_after_end: bool = False  #: the pass is still in progress at the window end

    @property
    def duration_s(self) -> float | None:
        """LOS - AOS in seconds, when both are known."""
        if self.aos is None or self.los is None:
            return None
        return (self.los - self.aos).total_seconds()


class _Evaluator:
    """Look angles for (satellite index, seconds after t0) pairs, batched per satellite."""

    def __init__(self, satrecs: list[Satrec], observer: Observer, t0: datetime, ut1_utc: float,
                 horizon: HorizonTable) -> None:
        self.satrecs = satrecs
        self.observer = observer
        self.jd0, self.fr0 = julian_date(t0)
        self.ut1_days = ut1_utc / SECONDS_PER_DAY
        self.horizon = horizon
        self._groups_for: np.ndarray | None = None
        self._groups: list[tuple[int, np.ndarray]] = []

    def states(self, sat: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Earth-fixed position and velocity (n, 3) and SGP4 error codes (n,)."""
        n = len(t)
        r = np.empty((n, 3))
        v = np.empty((n, 3))
        err = np.zeros(n, dtype=np.uint8)
        fr = self.fr0 + t / SECONDS_PER_DAY
        jd = np.full(n, self.jd0)
        # Iterative refinements call again and again with the same satellite array: group it once.
        if self._groups_for is not sat:
            order = np.argsort(sat, kind="stable")
            bounds = np.flatnonzero(np.diff(sat[order])) + 1
            self._groups = [(int(sat[g[0]]), g) for g in np.split(order, bounds) if len(g)]
            self._groups_for = sat
        satrecs = self.satrecs
        for index, group in self._groups:
            e, rr, vv = satrecs[index].sgp4_array(jd[group], fr[group])
            r[group], v[group], err[group] = rr, vv, e
        pos, vel = teme_to_itrs(r, v, jd, fr, self.ut1_days * SECONDS_PER_DAY)
        return pos, vel, err

    def look(self, sat: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(azimuth, elevation, f = elevation - horizon) in degrees; NaN/-inf where SGP4 failed."""
        pos, vel, err = self.states(sat, t)
        with np.errstate(invalid="ignore"):
            az, el, _, _ = itrs_to_topocentric(self.observer, pos, vel)
        f = el - self.horizon.min_elevation_array(az)
        bad = err != 0
        if bad.any():
            f[bad] = -np.inf
            el[bad] = np.nan
        return az, el, f

    def look_rates(self, sat: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(elevation, f, d(elevation)/dt, df/dt): degrees and degrees per second."""
        pos, vel, err = self.states(sat, t)
        d = pos - np.array(self.observer.itrs_km())
        e, n, u = (np.array(b) for b in self.observer.enu_basis())
        east, north, up = d @ e, d @ n, d @ u
        ve, vn, vu = vel @ e, vel @ n, vel @ u
        horiz2 = east * east + north * north
        rng2 = horiz2 + up * up
        with np.errstate(invalid="ignore", divide="ignore"):
            el = np.degrees(np.arcsin(up / np.sqrt(rng2)))
            rho_dot_over_rho = (east * ve + north * vn + up * vu) / rng2
            el_rate = np.degrees((vu - up * rho_dot_over_rho) / np.sqrt(horiz2))
            az = np.degrees(np.arctan2(east, north)) % 360.0
            az_rate = np.degrees((north * ve - east * vn) / horiz2)
        f = el - self.horizon.min_elevation_array(az)
        f_rate = el_rate - self.horizon.slope_array(az) * az_rate
        bad = err != 0
        if bad.any():
            f[bad] = -np.inf
            el[bad] = np.nan
            el_rate[bad] = f_rate[bad] = np.nan
        return el, f, el_rate, f_rate


def _crossings(ev: _Evaluator, sat: np.ndarray, lo: np.ndarray, hi: np.ndarray,
               iterations: int = 6, f_lo: np.ndarray | None = None, f_hi: np.ndarray | None = None) -> np.ndarray:
    """Times where f = 0 inside brackets [lo, hi] whose ends have opposite signs.

    Safeguarded Newton iteration with the analytic rate of f, starting from linear
    interpolation: a step that would leave the current bracket bisects it instead.
    """
    a, b = lo.astype(float).copy(), hi.astype(float).copy()
    if f_lo is None or f_hi is None:
        _, f_ab = ev.look(np.concatenate((sat, sat)), np.concatenate((a, b)))[1:]
        f_lo, f_hi = f_ab[: len(a)], f_ab[len(a) :]
    fa, fb = np.maximum(f_lo, -180.0), np.maximum(f_hi, -180.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(fb != fa, (a * fb - b * fa) / (fb - fa), 0.5 * (a + b))
    a_up = fa > 0.0
    for _ in range(iterations):
        c = np.clip(c, np.minimum(a, b), np.maximum(a, b))
        _, fc, _, rate = ev.look_rates(sat, c)
        same_as_a = (fc > 0.0) == a_up
        a = np.where(same_as_a, c, a)
        b = np.where(same_as_a, b, c)
        with np.errstate(invalid="ignore", divide="ignore"):
            step = c - fc / rate
        inside = np.isfinite(step) & (step >= np.minimum(a, b)) & (step <= np.maximum(a, b))
        c = np.where(inside, step, 0.5 * (a + b))
    return np.clip(c, np.minimum(a, b), np.maximum(a, b))


def _culminations(ev: _Evaluator, sat: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                  iterations: int = 8, samples: int = 9) -> tuple[np.ndarray, np.ndarray]:
    """Time and value of the maximum elevation in [lo, hi]: best of ``samples`` samples, then the root of
    d(elevation)/dt around it by the Illinois method."""
    n = len(sat)
    frac = np.linspace(0.0, 1.0, samples)
    probe_t = (lo[:, None] + frac[None, :] * (hi - lo)[:, None]).ravel()
    probe_el = np.nan_to_num(ev.look(np.repeat(sat, samples), probe_t)[1].reshape(n, samples), nan=-1e3)
    best = np.argmax(probe_el, axis=1)
    step = (hi - lo) / (samples - 1)
    centre = lo + best * step
    a, b = np.maximum(centre - step, lo), np.minimum(centre + step, hi)
    rates = ev.look_rates(np.concatenate((sat, sat)), np.concatenate((a, b)))[2]
    ra, rb = np.nan_to_num(rates[:n]), np.nan_to_num(rates[n:])
    bracketed = (ra > 0.0) & (rb < 0.0)
    c = centre
    side = np.zeros(n)
    for _ in range(iterations):
        with np.errstate(invalid="ignore", divide="ignore"):
            c = np.where(bracketed & (rb != ra), (a * rb - b * ra) / (rb - ra), centre)
        c = np.clip(c, a, b)
        rc = np.nan_to_num(ev.look_rates(sat, c)[2])
        rising = rc > 0.0  # the maximum lies after c: c replaces a
        # Illinois: an end kept twice in a row has its rate halved, which keeps convergence fast.
        rb = np.where(rising & (side > 0), rb * 0.5, rb)
        ra = np.where(~rising & (side < 0), ra * 0.5, ra)
        a, ra = np.where(rising, c, a), np.where(rising, rc, ra)
        b, rb = np.where(rising, b, c), np.where(rising, rb, rc)
        side = np.where(rising, 1.0, -1.0)
    t = np.where(bracketed, c, centre)
    return t, ev.look(sat, t)[1]


def _peaks(ev: _Evaluator, sat: np.ndarray, centre: np.ndarray, half_width: np.ndarray, use_f: bool,
           lo: np.ndarray | None = None, hi: np.ndarray | None = None,
           rounds: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Time and value of the maximum of f (``use_f``) or of the elevation near ``centre``.

    Each round fits a parabola through three samples ``half_width`` apart, moves to its vertex
    (kept within the bracket) and shrinks the spacing fourfold.
    """
    lo = centre - half_width if lo is None else lo
    hi = centre + half_width if hi is None else hi
    t = centre.astype(float).copy()
    h = half_width.astype(float).copy()
    n = len(t)
    for _ in range(rounds):
        probe = np.concatenate((t - h, t, t + h))
        _, el, f = ev.look(np.concatenate((sat, sat, sat)), np.clip(probe, np.tile(lo, 3), np.tile(hi, 3)))
        v = f if use_f else el
        v = np.nan_to_num(v, nan=-1e3, neginf=-1e3)
        y0, y1, y2 = v[:n], v[n : 2 * n], v[2 * n :]
        curv = y0 - 2.0 * y1 + y2
        with np.errstate(invalid="ignore", divide="ignore"):
            shift = np.where(curv < 0.0, 0.5 * h * (y0 - y2) / curv, np.where(y2 > y0, h, -h))
        t = np.clip(t + np.clip(shift, -h, h), lo, hi)
        h = np.maximum(h / 4.0, 0.02)
    _, el, f = ev.look(sat, t)
    return t, (f if use_f else el)


def _visibility_screen(satrecs: list[Satrec], observer: Observer, t0: datetime, span_s: float,
                       coarse_step_s: float, horizon: HorizonTable, ut1_utc: float
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Coarse grid times (s), a mask (sats, intervals) of intervals where the satellite may rise or
    set, each satellite's bound on the rate of its visibility margins (rad/s), and
    f = elevation - horizon (deg) at every coarse point (sats, times).

    An interval is dropped when the satellite is provably below the lowest horizon point
    throughout, or provably above the highest one throughout (1 degree of slack covers the
    difference between geocentric and geodetic elevation, at most 0.2 degree).
    """
    n_steps = max(1, math.ceil(span_s / coarse_step_s))
    t = np.linspace(0.0, n_steps * coarse_step_s, n_steps + 1)
    jd0, fr0 = julian_date(t0)
    jd = np.full(t.shape, jd0)
    fr = fr0 + t / SECONDS_PER_DAY
    obs = np.array(observer.itrs_km())
    r_obs = float(np.linalg.norm(obs))
    obs_unit = obs / r_obs
    e_lo = math.radians(max(horizon.minimum - 1.0, -89.0))
    e_hi = math.radians(min(max(p[1] for p in horizon.points) + 1.0 if horizon.points else 1.0, 89.0))
    k_lo, k_hi = r_obs * math.cos(e_lo), r_obs * math.cos(e_hi)
    mask = np.zeros((len(satrecs), n_steps), dtype=bool)
    rates_out = np.zeros(len(satrecs))
    f_out = np.empty((len(satrecs), n_steps + 1))
    east_u, north_u, up_u = (np.array(b) for b in observer.enu_basis())
    chunk = max(1, 400_000 // len(t))
    for i0 in range(0, len(satrecs), chunk):
        part = satrecs[i0 : i0 + chunk]
        err, r, v = SatrecArray(part).sgp4(jd, fr)
        pos, vel = teme_to_itrs(r, v, jd, fr, ut1_utc)
        x, y, z = pos[..., 0], pos[..., 1], pos[..., 2]
        vx, vy, vz = vel[..., 0], vel[..., 1], vel[..., 2]
        rad = np.sqrt(x * x + y * y + z * z)
        with np.errstate(invalid="ignore"):
            cos_psi = (x * obs_unit[0] + y * obs_unit[1] + z * obs_unit[2]) / rad
            psi = np.arccos(np.clip(cos_psi, -1.0, 1.0))
            ratio_lo = np.clip(k_lo / rad, -1.0, 1.0)
            ratio_hi = np.clip(k_hi / rad, -1.0, 1.0)
            margin_lo = psi - (np.arccos(ratio_lo) - e_lo)  # > 0: below the lowest horizon point
            margin_hi = psi - (np.arccos(ratio_hi) - e_hi)  # < 0: above the highest horizon point
            # Angular rate of the satellite's direction plus the rate of change of psi_max.
            cx = y * vz - z * vy
            cy = z * vx - x * vz
            cz = x * vy - y * vx
            ang_rate = np.sqrt(cx * cx + cy * cy + cz * cz) / (rad * rad)
            rdot = (x * vx + y * vy + z * vz) / rad
            dpsi_lo = np.abs(k_lo / (rad * rad * np.sqrt(np.maximum(1.0 - ratio_lo * ratio_lo, 1e-12))) * rdot)
            dpsi_hi = np.abs(k_hi / (rad * rad * np.sqrt(np.maximum(1.0 - ratio_hi * ratio_hi, 1e-12))) * rdot)
            rate = ang_rate + np.maximum(dpsi_lo, dpsi_hi)
        # Sampled maxima miss the peak between samples by little on near-circular orbits; eccentric
        # orbits (fast perigee passages) get a wider safety factor.
        ecc = np.array([sr.ecco for sr in part])
        safety = 1.1 + 2.0 * ecc
        rate_bound = np.nanmax(np.where(err == 0, rate, np.nan), axis=1, initial=0.0) * safety + 1e-5
        margin_lo = np.where(err == 0, margin_lo, np.inf)
        margin_hi = np.where(err == 0, margin_hi, np.inf)
        reach = rate_bound[:, None] * coarse_step_s
        below = (margin_lo[:, :-1] + margin_lo[:, 1:] - reach) * 0.5 > 0.0
        above = (margin_hi[:, :-1] + margin_hi[:, 1:] + reach) * 0.5 < 0.0
        candidate = ~(below | above)
        # A failed propagation at one end hides nothing: keep the interval if the other end is close.
        candidate |= (np.isinf(margin_lo[:, :-1]) & (margin_lo[:, 1:] <= reach)) | (
            np.isinf(margin_lo[:, 1:]) & (margin_lo[:, :-1] <= reach)
        )
        mask[i0 : i0 + len(part)] = candidate
        rates_out[i0 : i0 + len(part)] = rate_bound
        # f = elevation - horizon at the coarse points, for satellites sampled on this grid alone.
        dx, dy, dz = x - obs[0], y - obs[1], z - obs[2]
        east = dx * east_u[0] + dy * east_u[1]
        north = dx * north_u[0] + dy * north_u[1] + dz * north_u[2]
        upc = dx * up_u[0] + dy * up_u[1] + dz * up_u[2]
        with np.errstate(invalid="ignore"):
            el = np.degrees(np.arctan2(upc, np.hypot(east, north)))
            az = np.degrees(np.arctan2(east, north)) % 360.0
        f = el - horizon.min_elevation_array(np.nan_to_num(az))
        f_out[i0 : i0 + len(part)] = np.where(err == 0, f, -np.inf)
    return t, mask, rates_out, f_out


#: Satellites with periods up to this (s) are searched together with a short look-back.
_SHORT_PERIOD_S = 3.0 * 3600.0
#: Screen step for low orbits, and the sampling step of near-circular ones under a flat horizon (s).
_LEO_COARSE_S = 600.0
_CIRCULAR_STEP_S = 300.0
#: Geocentric angular rate (rad/s) of a low satellite, for which the fine step is ``fine_step_s``.
_LEO_RATE = 1.2e-3


#: Fork-time hand-over of the work to worker processes (Satrec objects cannot be pickled); set only
#: for the duration of one parallel :func:`find_passes` call.
_FORK_JOB: tuple | None = None


def _fork_worker(indices: list[int]) -> list[Pass]:
    assert _FORK_JOB is not None
    satrecs, args = _FORK_JOB
    return find_passes([satrecs[i] for i in indices], *args)


def find_passes(
    satellites: Sequence,
    observer: Observer,
    start: datetime,
    end: datetime,
    horizon: HorizonTable | None = None,
    ut1_utc: float = 0.0,
    fine_step_s: float = 60.0,
    workers: int = 1,
) -> list[Pass]:
    """Passes of ``satellites`` (``sgp4`` Satrecs, or objects with a ``.satrec``) between ``start`` and ``end``.

    Returns the passes overlapping the window, sorted by AOS (TCA when AOS is unknown).  See the
    module docstring for the method and for passes cut by the window.  ``fine_step_s`` is the
    sampling step for low orbits; slower satellites are sampled proportionally more coarsely.

    ``workers`` > 1 splits large catalogs over that many forked processes (POSIX only; meant for
    command-line use).  Forking a process that runs other threads can deadlock the child, so the
    work stays in this process unless it is single-threaded.  The passes found are the same as
    with one worker (times equal within the refinement tolerance).
    """
    global _FORK_JOB
    if workers > 1 and len(satellites) >= 200 * workers and _FORK_JOB is None and threading.active_count() == 1:
        import multiprocessing

        if "fork" in multiprocessing.get_all_start_methods():
            satrecs_all = [getattr(s, "satrec", s) for s in satellites]
            _FORK_JOB = (satrecs_all, (observer, start, end, horizon, ut1_utc, fine_step_s))
            try:
                chunks = [list(range(k, len(satrecs_all), workers)) for k in range(workers)]
                with multiprocessing.get_context("fork").Pool(workers) as pool:
                    parts = pool.map(_fork_worker, chunks)
            finally:
                _FORK_JOB = None
            merged = [p for part in parts for p in part]
            merged.sort(key=lambda p: (p.aos or p.tca, p.catalog_number))
            return merged
    horizon = horizon or _FLAT
    if start.tzinfo is None:
        start = start.replace(tzinfo=timezone.utc)
    if end.tzinfo is None:
        end = end.replace(tzinfo=timezone.utc)
    if end <= start or not satellites:
        return []
    satrecs = [getattr(s, "satrec", s) for s in satellites]
    periods = np.array([2.0 * math.pi / max(sr.no_kozai, 1e-9) * 60.0 for sr in satrecs])  # seconds
    passes: list[Pass] = []
    short = periods <= _SHORT_PERIOD_S
    for group, coarse in ((short, _LEO_COARSE_S), (~short, 1200.0)):
        members = [satrecs[i] for i in np.flatnonzero(group)]
        if members:
            extension = float(min(np.max(periods[group]), SECONDS_PER_DAY))
            passes += _find_group(members, observer, start, end, horizon, ut1_utc, fine_step_s, coarse, extension)
    passes.sort(key=lambda p: (p.aos or p.tca, p.catalog_number))
    return passes


def _find_group(satrecs: list[Satrec], observer: Observer, start: datetime, end: datetime,
                horizon: HorizonTable, ut1_utc: float, fine_step_s: float, coarse_step_s: float,
                extension: float) -> list[Pass]:
    t0 = start - timedelta(seconds=extension)
    window_s = (end - start).total_seconds()
    span = window_s + 2.0 * extension
    ev = _Evaluator(satrecs, observer, t0, ut1_utc, horizon)

    grid, mask, rates, coarse_f = _visibility_screen(satrecs, observer, t0, span, coarse_step_s, horizon,
                                                     ut1_utc)
    # Fine samples over every candidate coarse interval; a run of consecutive candidate intervals
    # shares its inner edges, so each sample appears once and the arrays stay sorted by (sat, t).
    # Slow satellites get proportionally longer fine steps (a divisor of the coarse step).
    wanted = fine_step_s * np.clip(_LEO_RATE / np.maximum(rates, 1e-9), 1.0, coarse_step_s / fine_step_s)
    per_sat = np.maximum(1, np.round(coarse_step_s / wanted)).astype(np.intp)
    # Near-circular orbits under a flat horizon have one smooth elevation hump per pass, several
    # coarse steps wide: the coarse points themselves are enough to bracket every event.
    if horizon.is_flat:
        circular = np.array([sr.ecco < 0.05 for sr in satrecs])
        per_sat = np.where(circular, max(1, int(round(coarse_step_s / _CIRCULAR_STEP_S))), per_sat)
    sat_idx, interval_idx = np.nonzero(mask)
    if len(sat_idx) == 0:
        return []
    run_end = np.ones(len(sat_idx), dtype=bool)
    run_end[:-1] = (sat_idx[1:] != sat_idx[:-1]) | (interval_idx[1:] != interval_idx[:-1] + 1)
    per = per_sat[sat_idx]
    counts = np.where(run_end, per + 1, per)
    fine_sat = np.repeat(sat_idx, counts)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    step_in = np.arange(len(fine_sat)) - first
    sample_step = coarse_step_s / per_sat[fine_sat]
    fine_t = grid[np.repeat(interval_idx, counts)] + step_in * sample_step
    ratio = fine_t / coarse_step_s
    on_grid = np.abs(ratio - np.rint(ratio)) < 1e-9
    f = np.empty(len(fine_t))
    el = np.full(len(fine_t), np.nan)
    k = np.rint(fine_t[on_grid] / coarse_step_s).astype(np.intp)
    f[on_grid] = coarse_f[fine_sat[on_grid], k]
    if (~on_grid).any():
        _, el[~on_grid], f[~on_grid] = ev.look(fine_sat[~on_grid], fine_t[~on_grid])
    same = (fine_sat[1:] == fine_sat[:-1]) & (np.abs(fine_t[1:] - fine_t[:-1] - sample_step[1:]) < 1e-3)

    up = f > 0.0
    # Crossings between consecutive samples of one segment.
    cross = same & (up[1:] != up[:-1])
    ci = np.flatnonzero(cross)
    rising = ~up[ci]
    times = _crossings(ev, fine_sat[ci], fine_t[ci], fine_t[ci + 1], f_lo=f[ci], f_hi=f[ci + 1]) if len(ci) \
        else np.empty(0)
    events_sat = list(fine_sat[ci])
    events_t = list(times)
    events_rise = list(rising)

    # Short passes hidden between samples: local maxima of f below zero that could reach zero.
    if len(f) >= 3:
        mid = np.arange(1, len(f) - 1)
        inner = same[:-1] & same[1:]
        local = inner & (f[mid] >= f[mid - 1]) & (f[mid] >= f[mid + 1]) & ~up[mid] & np.isfinite(f[mid])
        # Elevation can change by at most ~ (v / range) over half a step; be generous.
        local &= f[mid] > np.where(on_grid[mid], -15.0, -8.0)
        li = mid[local]
        if len(li):
            half = 0.5 * (fine_t[li + 1] - fine_t[li - 1])
            t_max, f_max = _peaks(ev, fine_sat[li], fine_t[li], half, True, fine_t[li - 1], fine_t[li + 1])
            hit = np.flatnonzero(f_max > 0.0)
            if len(hit):
                s_h = fine_sat[li[hit]]
                peak = t_max[hit]
                a = _crossings(ev, s_h, fine_t[li[hit] - 1], peak)
                b = _crossings(ev, s_h, peak, fine_t[li[hit] + 1])
                events_sat += list(s_h) * 2
                events_t += list(a) + list(b)
                events_rise += [True] * len(hit) + [False] * len(hit)

    return _assemble(ev, satrecs, np.array(events_sat, dtype=np.intp), np.array(events_t),
                     np.array(events_rise, dtype=bool), fine_sat, fine_t, el, up, t0, extension, window_s,
                     span)


def _assemble(ev: _Evaluator, satrecs: list[Satrec], ev_sat: np.ndarray, ev_t: np.ndarray,
              ev_rise: np.ndarray, fine_sat: np.ndarray, fine_t: np.ndarray, fine_el: np.ndarray,
              fine_up: np.ndarray, t0: datetime, extension: float, window_s: float, span: float) -> list[Pass]:
    """Pair rises with sets per satellite, refine TCAs, and keep passes overlapping the window."""
    order = np.lexsort((ev_t, ev_sat))
    ev_sat, ev_t, ev_rise = ev_sat[order], ev_t[order], ev_rise[order]
    win_lo, win_hi = extension, extension + window_s
    raw: list[tuple[int, float | None, float | None]] = []
    for s in np.unique(ev_sat):
        sel = ev_sat == s
        times, rises = ev_t[sel], ev_rise[sel]
        pending: float | None = None
        started = False
        for t, is_rise in zip(times, rises):
            if is_rise:
                pending, started = t, True
            else:
                if pending is not None or not started:
                    raw.append((int(s), pending, t))
                pending, started = None, True
        if pending is not None:
            raw.append((int(s), pending, None))
    # Keep passes overlapping the window; an unknown AOS/LOS lies outside the search span.
    kept = []
    for s, a, b in raw:
        lo = a if a is not None else -np.inf
        hi = b if b is not None else np.inf
        if hi >= win_lo and lo <= win_hi:
            kept.append((s, a, b))
    if not kept:
        return []
    # TCA: golden-section search of the elevation around the highest fine sample inside the pass.
    sats = np.array([k[0] for k in kept], dtype=np.intp)
    lo = np.array([k[1] if k[1] is not None else 0.0 for k in kept])
    hi = np.array([k[2] if k[2] is not None else span for k in kept])
    t_tca, el_tca = _culminations(ev, sats, lo, hi)
    known_a = np.array([k[1] if k[1] is not None else 0.0 for k in kept])
    known_b = np.array([k[2] if k[2] is not None else 0.0 for k in kept])
    az_a, _, _ = ev.look(sats, known_a)
    az_b, _, _ = ev.look(sats, known_b)

    def when(seconds: float) -> datetime:
        return t0 + timedelta(seconds=float(seconds))

    passes = []
    for j, (s, a, b) in enumerate(kept):
        passes.append(
            Pass(
                catalog_number=int(satrecs[s].satnum),
                aos=when(a) if a is not None else None,
                tca=when(t_tca[j]),
                los=when(b) if b is not None else None,
                max_elevation_deg=float(el_tca[j]),
                aos_azimuth_deg=float(az_a[j]) if a is not None else None,
                los_azimuth_deg=float(az_b[j]) if b is not None else None,
                aos_before_start=bool(a is None or a < win_lo),
                los_after_end=bool(b is None or b > win_hi),
            )
        )
    passes.sort(key=lambda p: (p.aos or p.tca, p.catalog_number))
    return passes
