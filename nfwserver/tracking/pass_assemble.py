"""Pass search, stage 3: turn brackets into events, pair them into passes, and find each TCA.

Order of work (every step batched over all satellites of the search):

0. brackets of passes that cannot overlap the window are dropped (:func:`_within_window`);
1. crossings and hidden peaks are refined together (:func:`nfwserver.tracking.pass_refine.solve`);
2. culminations are refined next, each from the middle of its (short) pass's refined rise and set
   as first guess, together with the two crossings of each hidden peak that rose above the horizon;
3. rises and sets are paired per satellite (a set with no rise before it in the search is a
   pass whose AOS lies before the search span, a final rise one whose LOS lies after it);
4. passes overlapping the window keep the maxima refined in their culmination brackets; the
   TCA is the highest of the refined maxima and the pass's own ends (a pass under a sloping
   horizon may peak at its AOS or LOS).

Times are seconds after the start of the search span; :func:`assemble` hands back columns for a
:class:`~nfwserver.tracking.pass_records.PassList`, with times in seconds after the window start.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from nfwserver.tracking.pass_batch import Layout
from nfwserver.tracking.pass_events import TOP_TOL_S
from nfwserver.tracking.pass_kinematics import PairEvaluator
from nfwserver.tracking.pass_refine import CROSSING, F_TOP, TOP, solve
from nfwserver.tracking.pass_screen import Brackets, Intervals

#: Passes shorter than this (s) get the middle of their rise and set as the first guess of their TCA.
_SHORT_PASS_S = 1800.0


def _events(ev: PairEvaluator, br: Brackets, flat: bool, layout: Layout) -> tuple[Any, ...]:
    """Refined crossings (sat, t, rising, az, el, el rate), the maxima of the hidden peaks that rose,
    and the refined culminations (t, el)."""
    cr, pk, cu = br.crossings, br.peaks, br.culminations
    nc, npk = len(cr), len(pk)
    kind = np.concatenate((np.full(nc, CROSSING), np.full(npk, TOP if flat else F_TOP)))
    sat_, a, b, ga, gb = (np.concatenate((getattr(cr, x), getattr(pk, x))) for x in ("sat", "a", "b", "ga", "gb"))
    sol = solve(ev, sat_, a, b, ga, gb, kind, np.concatenate((np.zeros(nc, dtype=bool), np.ones(npk, dtype=bool))),
                guess=np.concatenate((cr.guess, pk.guess)))
    sat, t, rising = cr.sat, sol.t[:nc], cr.ga <= 0.0
    az, el, el_rate = sol.az[:nc], sol.el[:nc], sol.el_rate[:nc]
    up = np.flatnonzero(sol.best_f[nc:] > 0.0)
    tops = (pk.sat[up], sol.t[nc:][up], sol.el[nc:][up])
    # Second round: culminations (first guess: the middle of their pass's refined rise and set) and
    # the crossings of the hidden peaks that rose (first guesses from the parabola through the top).
    ps, top_t, f_top = pk.sat[up], sol.best_t[nc:][up], sol.best_f[nc:][up]
    m = len(up)
    with np.errstate(invalid="ignore", divide="ignore"):
        half = np.sqrt(2.0 * f_top / -sol.f_accel[nc:][up])
        if flat and ev.horizon.minimum == 0.0:
            # The height above the horizontal plane follows a parabola over the whole pass far more
            # closely than the elevation does (which is peaked for high passes).
            half_up = np.sqrt(2.0 * sol.best_up[nc:][up] / -sol.best_up_accel[nc:][up])
            half = np.where(np.isfinite(half_up), half_up, half)
    s2 = solve(ev, np.concatenate((cu.sat, ps, ps)), np.concatenate((cu.a, pk.a[up], top_t)),
               np.concatenate((cu.b, top_t, pk.b[up])), np.concatenate((cu.ga, np.full(m, -1.0), f_top)),
               np.concatenate((cu.gb, f_top, np.full(m, -1.0))),
               np.concatenate((np.full(len(cu), TOP), np.full(2 * m, CROSSING))),
               guess=np.concatenate((_middle_of_pass(sat, t, rising, cu, layout), top_t - half, top_t + half)))
    culminations = (s2.t[: len(cu)], s2.el[: len(cu)])
    if m:
        sat = np.concatenate((sat, ps, ps))
        t = np.concatenate((t, s2.t[len(cu):]))
        rising = np.concatenate((rising, np.ones(m, dtype=bool), np.zeros(m, dtype=bool)))
        az = np.concatenate((az, s2.az[len(cu):]))
        el = np.concatenate((el, s2.el[len(cu):]))
        el_rate = np.concatenate((el_rate, s2.el_rate[len(cu):]))
    if not flat:
        tops = (tops[0][:0], tops[1][:0], tops[2][:0])  # f's maximum is not the elevation's
    return sat, t, rising, az, el, el_rate, tops, culminations


def _middle_of_pass(sat: np.ndarray, t: np.ndarray, rising: np.ndarray, cu: Intervals, layout: Layout
                    ) -> np.ndarray:
    """For each culmination bracket, the middle of the pass it lies in (a rise followed by a set
    around one of its ends), when that pass is shorter than ``_SHORT_PASS_S`` and the middle lies in
    the bracket; else NaN.  (The maximum of a short pass lies within seconds of its middle.)"""
    guess = np.full(len(cu), np.nan)
    if not len(t) or not len(cu):
        return guess
    order = np.lexsort((t, sat))
    t_s, up_s, sat_s = t[order], rising[order], sat[order]
    keys = layout.keys(sat_s, t_s)
    n = len(keys)
    for end in (cu.b, cu.a):
        i = layout.search(sat_s, keys, cu.sat, layout.keys(cu.sat, end), "left")
        r, s = np.clip(i - 1, 0, n - 1), np.clip(i, 0, n - 1)
        inside = (i >= 1) & (i < n) & (sat_s[r] == cu.sat) & (sat_s[s] == cu.sat) & up_s[r] & ~up_s[s]
        mid = 0.5 * (t_s[r] + t_s[s])
        inside &= (t_s[s] - t_s[r] < _SHORT_PASS_S) & (mid > np.minimum(cu.a, cu.b)) & (mid < np.maximum(cu.a, cu.b))
        guess = np.where(inside, mid, guess)
    return guess


def _within_window(br: Brackets, win_lo: np.ndarray, win_hi: np.ndarray) -> Brackets:
    """``br`` without the brackets of passes that cannot overlap ``[win_lo, win_hi]``, before refining.

    A hidden peak holds its whole pass.  A set bracket ending before ``win_lo`` ends a pass that is
    over before the window, and a rise bracket starting after ``win_hi`` starts one that begins
    after it: both go, with the rise just before (set just after) them of the same satellite.
    """
    pk, cr = br.peaks, br.crossings
    peaks = pk.select((pk.b >= win_lo[pk.sat]) & (pk.a <= win_hi[pk.sat]))
    n = len(cr)
    if not n:
        return Brackets(cr, peaks, br.culminations)
    order = np.lexsort((cr.a, cr.sat))
    sat, a, b, rising = cr.sat[order], cr.a[order], cr.b[order], cr.ga[order] <= 0.0
    drop = (~rising & (np.maximum(a, b) < win_lo[sat])) | (rising & (np.minimum(a, b) > win_hi[sat]))
    same_prev = np.zeros(n, dtype=bool)
    same_prev[1:] = sat[1:] == sat[:-1]
    # the rise before a dropped early set, the set after a dropped late rise
    drop[:-1] |= drop[1:] & ~rising[1:] & rising[:-1] & same_prev[1:]
    drop[1:] |= drop[:-1] & rising[:-1] & ~rising[1:] & same_prev[1:]
    keep = np.sort(order[~drop])
    return Brackets(cr.select(keep), peaks, br.culminations)


def _pair(sat: np.ndarray, t: np.ndarray, rising: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Passes as (sat, index of the rise or -1, index of the set or -1), events sorted by (sat, t)."""
    n = len(sat)
    first = np.ones(n, dtype=bool)
    first[1:] = sat[1:] != sat[:-1]
    last = np.ones(n, dtype=bool)
    last[:-1] = sat[1:] != sat[:-1]
    idx = np.arange(n)
    sets_after_rise = ~rising & ~first & np.roll(rising, 1)
    sets_alone = ~rising & first
    rises_open = rising & last
    p_sat = np.concatenate((sat[sets_after_rise], sat[sets_alone], sat[rises_open]))
    p_rise = np.concatenate((idx[sets_after_rise] - 1, np.full(sets_alone.sum(), -1), idx[rises_open]))
    p_set = np.concatenate((idx[sets_after_rise], idx[sets_alone], np.full(rises_open.sum(), -1)))
    return p_sat, p_rise, p_set


def assemble(ev: PairEvaluator, br: Brackets, flat: bool, layout: Layout) -> dict[str, np.ndarray]:
    """Passes overlapping each satellite's window from the brackets of a search (``layout``: the satellites'
    catalog numbers, spans and windows), as :class:`~nfwserver.tracking.pass_records.PassList` columns
    (unsorted)."""
    span, win_lo, win_hi = layout.span, layout.win_lo, layout.win_hi
    br = _within_window(br, win_lo, win_hi)
    sat, t, rising, az, el, el_rate, tops, (cu_t, cu_el) = _events(ev, br, flat, layout)
    order = np.lexsort((t, sat))
    sat, t, rising, az, el, el_rate = sat[order], t[order], rising[order], az[order], el[order], el_rate[order]
    p_sat, p_rise, p_set = _pair(sat, t, rising)
    lo = np.where(p_rise >= 0, t[p_rise], -np.inf)
    hi = np.where(p_set >= 0, t[p_set], np.inf)
    keep = (hi >= win_lo[p_sat]) & (lo <= win_hi[p_sat])
    p_sat, p_rise, p_set, lo, hi = p_sat[keep], p_rise[keep], p_set[keep], lo[keep], hi[keep]
    if not len(p_sat):
        return {}
    porder = np.lexsort((lo, p_sat))
    p_sat, p_rise, p_set, lo, hi = p_sat[porder], p_rise[porder], p_set[porder], lo[porder], hi[porder]
    lo_c, hi_c = np.maximum(lo, 0.0), np.minimum(hi, span[p_sat])
    # Candidates for each pass's TCA: its known ends, refined culminations, hidden-peak maxima.
    best_el = np.full(len(p_sat), -np.inf)
    best_t = 0.5 * (lo_c + hi_c)
    for ends in (p_rise, p_set):
        known = ends >= 0
        # The elevation at an end equals the horizon there; an end is the TCA only if nothing beats it.
        end_el = np.where(known, el[np.maximum(ends, 0)], -np.inf)
        better = end_el > best_el
        best_el, best_t = np.where(better, end_el, best_el), np.where(better, t[np.maximum(ends, 0)], best_t)
    cu = br.culminations
    owner = _owner(p_sat, lo_c, hi_c, cu.sat, cu.a, cu.b, layout)
    cand_pass = [owner[owner >= 0]]
    sel = owner >= 0
    cand_t, cand_el = [cu_t[sel]], [cu_el[sel]]
    tp = _owner(p_sat, lo_c, hi_c, tops[0], tops[1], tops[1], layout)
    cand_pass.append(tp[tp >= 0])
    cand_t.append(tops[1][tp >= 0])
    cand_el.append(tops[2][tp >= 0])
    # A pass whose elevation rises at AOS and falls at LOS but showed no culmination bracket.
    has = np.zeros(len(p_sat), dtype=bool)
    has[np.concatenate(cand_pass)] = True
    rate_lo = np.where(p_rise >= 0, el_rate[np.maximum(p_rise, 0)], np.nan)
    rate_hi = np.where(p_set >= 0, el_rate[np.maximum(p_set, 0)], np.nan)
    rescue = np.flatnonzero(~has & (rate_lo > 0.0) & (rate_hi < 0.0))
    if len(rescue):
        s2 = solve(ev, p_sat[rescue], lo_c[rescue], hi_c[rescue], rate_lo[rescue], rate_hi[rescue],
                   np.full(len(rescue), TOP))
        cand_pass.append(rescue)
        cand_t.append(s2.t)
        cand_el.append(s2.el)
    cp, ct, ce = np.concatenate(cand_pass), np.concatenate(cand_t), np.concatenate(cand_el)
    inside = (ct >= lo_c[cp] - TOP_TOL_S) & (ct <= hi_c[cp] + TOP_TOL_S) & np.isfinite(ce)
    cp, ct, ce = cp[inside], ct[inside], ce[inside]
    srt = np.lexsort((ce, cp))  # the last entry of each pass is its highest candidate
    cp, ct, ce = cp[srt], ct[srt], ce[srt]
    top = np.ones(len(cp), dtype=bool)
    top[:-1] = cp[1:] != cp[:-1]
    cp, ct, ce = cp[top], ct[top], ce[top]
    better = ce > best_el[cp]
    best_el[cp[better]], best_t[cp[better]] = ce[better], ct[better]
    return _records(p_sat, p_rise, p_set, t, az, best_t, best_el, layout.catalog_numbers, win_lo[p_sat])


def _owner(p_sat: np.ndarray, lo: np.ndarray, hi: np.ndarray, sat: np.ndarray, a: np.ndarray,
           b: np.ndarray, layout: Layout) -> np.ndarray:
    """Index of the pass (sorted by sat, lo) overlapping each interval ``[a, b]`` of ``sat``, or -1."""
    if not len(sat) or not len(p_sat):
        return np.full(len(sat), -1)
    keys = layout.keys(p_sat, lo)
    i = layout.search(p_sat, keys, sat, layout.keys(sat, b), "right") - 1
    ic = np.maximum(i, 0)
    ok = (i >= 0) & (p_sat[ic] == sat) & (hi[ic] >= a)
    return np.where(ok, i, -1)


def _records(p_sat: np.ndarray, p_rise: np.ndarray, p_set: np.ndarray, t: np.ndarray, az: np.ndarray,
             tca_t: np.ndarray, tca_el: np.ndarray, catalog_numbers: np.ndarray, win_lo: np.ndarray
             ) -> dict[str, np.ndarray]:
    """PassList columns (times in s after the window start, ``win_lo`` after the search start)."""
    rise, fall = p_rise >= 0, p_set >= 0
    ri, si = np.maximum(p_rise, 0), np.maximum(p_set, 0)
    return {"catalog_number": catalog_numbers[p_sat],
            "aos_s": np.where(rise, t[ri] - win_lo, np.nan), "tca_s": tca_t - win_lo,
            "los_s": np.where(fall, t[si] - win_lo, np.nan), "max_elevation_deg": tca_el,
            "aos_azimuth_deg": np.where(rise, az[ri], np.nan), "los_azimuth_deg": np.where(fall, az[si], np.nan)}
