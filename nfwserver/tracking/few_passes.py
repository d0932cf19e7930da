"""Passes of a few satellites over a flat horizon, in pure Python: the search ``nfwserver passes --sat`` runs.

The catalog search (:mod:`nfwserver.tracking.passes`) is built for thousands of satellites: it needs numpy,
whose import alone costs more than finding a day of one satellite's passes.  This search finds the same
passes for a handful of satellites with ``sgp4``'s scalar propagator and :mod:`math` only:

The passes and their events are those :mod:`nfwserver.tracking.pass_events` defines, found to its tolerances
(as the catalog search finds them):

1. the elevation and the rate of its sine (:meth:`~nfwserver.tracking.scalar_look.ScalarLookAngles.rise_state`)
   are sampled every :data:`STEP_S` seconds (at most a 40th of the orbital period) over the window extended
   by the look-back, so that passes in progress at either end get their true AOS and LOS;
2. a change of side of the horizon between two samples brackets a crossing; a rate going from rising to
   setting brackets a culmination, and one below the horizon between two samples that are both below
   (a short pass hidden between samples) is refined and, if it rises above, gives two crossings.  An
   elevation has two extrema an orbit, so at most one lies between samples a 40th of a period apart;
3. crossings and culminations (roots of the rate) are refined by Brent's method; rises and sets are paired
   into passes and each pass's TCA is its highest culmination (or its highest end).

Times are seconds after the window start, angles degrees.  A satellite whose position at the start cannot be
computed or is implausibly far is ``skipped``; one that stays above the horizon over the whole extended search
has one pass with neither AOS nor LOS, whose TCA is the highest point inside the window (a culmination there,
or an end), as :mod:`nfwserver.tracking.pass_always_up` gives.  Anything this search does not handle as the
catalog search does (SGP4 failing inside the window, an unpaired event) raises :class:`NeedsCatalogSearch`, and
the caller runs the catalog search instead.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from nfwserver.tracking.constants import SECONDS_PER_DAY
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.pass_events import (
    CROSSING_TOL_S,
    MAX_LOOK_BACK_S,
    MAX_PLAUSIBLE_RANGE_KM,
    TOP_TOL_S,
    look_back_s,
)
from nfwserver.tracking.scalar_look import ScalarLookAngles

#: Largest sampling step (s); the step is also at most a 40th of the orbital period.
STEP_S = 120.0
#: A row: catalog number, AOS (s; None when unknown), TCA, LOS (None when unknown), maximum elevation, azimuths
#: at AOS and LOS (None when unknown).
Row = tuple[int, "float | None", float, "float | None", float, "float | None", "float | None"]


class NeedsCatalogSearch(Exception):
    """This search cannot promise the catalog search's passes for this input: run that one instead."""


@dataclass
class FewPasses:
    """Passes sorted by AOS (TCA when AOS is unknown), then catalog number, and the satellites left out."""

    rows: list[Row] = field(default_factory=list)
    skipped: list[int] = field(default_factory=list)  #: position unusable at the start, ascending


def find_few_passes(satrecs: Sequence[Any], catalog_numbers: Sequence[int], observer: Observer, jd: float,
                    fr: float, window_s: float, min_elevation_deg: float = 0.0, ut1_utc: float = 0.0) -> FewPasses:
    """Passes of each SGP4 model (``sgp4`` Satrec) in the window of ``window_s`` seconds from the UTC Julian date
    ``jd + fr``, above a flat horizon at ``min_elevation_deg``.  Raises :class:`NeedsCatalogSearch`."""
    look = ScalarLookAngles(observer, ut1_utc)
    found = FewPasses()
    for satrec, number in zip(satrecs, catalog_numbers):
        err, r, v = satrec.sgp4(jd, fr)
        if err or not _finite(r) or not look.look(r, v, jd, fr)[2] <= MAX_PLAUSIBLE_RANGE_KM:
            found.skipped.append(number)
            continue
        found.rows += _search(satrec, number, look, jd, fr, window_s, min_elevation_deg)
    found.rows.sort(key=lambda row: (row[2] if row[1] is None else row[1], row[0]))
    found.skipped.sort()
    return found


def _finite(values: Sequence[float]) -> bool:
    return all(math.isfinite(x) for x in values)


def _search(satrec: Any, number: int, look: ScalarLookAngles, jd: float, fr: float, window_s: float,
            h0: float) -> list[Row]:
    """The passes of one satellite overlapping ``[0, window_s]``."""
    period = 2.0 * math.pi / max(satrec.no_kozai, 1e-9) * 60.0
    extension = min(look_back_s(period, satrec.ecco), MAX_LOOK_BACK_S)
    t_lo, t_hi = -extension, window_s + extension
    n = max(2, math.ceil((t_hi - t_lo) / min(STEP_S, period / 40.0)))

    def state(t: float) -> tuple[float, float, float]:
        at = fr + t / SECONDS_PER_DAY
        err, r, v = satrec.sgp4(jd, at)
        if err or not _finite(r):
            raise NeedsCatalogSearch(f"SGP4 fails for {number} inside the search")
        return look.rise_state(r, v, jd, at)

    def height(t: float) -> float:
        return state(t)[0] - h0

    def rate(t: float) -> float:
        return state(t)[2]

    times = [t_lo + (t_hi - t_lo) * k / n for k in range(n + 1)]
    samples = [state(t) for t in times]
    events: list[tuple[float, bool, float, float]] = []  # (t, rising, azimuth, elevation)
    tops: list[tuple[float, float]] = []  # (t, elevation) of culminations
    for (a, sa), (b, sb) in zip(zip(times, samples), zip(times[1:], samples[1:])):
        ga, gb = sa[0] - h0, sb[0] - h0
        peak = sa[2] > 0.0 >= sb[2]
        top = _root(rate, a, b, sa[2], sb[2], TOP_TOL_S) if peak else None
        top_state = state(top) if top is not None else None
        if (ga > 0.0) != (gb > 0.0):
            events.append(_crossing(height, state, a, b, ga, gb))
        elif peak and ga <= 0.0 and top is not None and top_state is not None and top_state[0] - h0 > 0.0:
            g_top = top_state[0] - h0
            events.append(_crossing(height, state, a, top, ga, g_top))
            events.append(_crossing(height, state, top, b, g_top, gb))
        if top is not None and top_state is not None:
            tops.append((top, top_state[0]))
    if not events:
        if samples[0][0] - h0 <= 0.0:
            return []
        # Up throughout: the highest point inside the window (the start first, then the end, then turns).
        best_t, best_el = max(((0.0, state(0.0)[0]), (window_s, state(window_s)[0])), key=lambda c: c[1])
        for t, el in sorted(tops, key=lambda c: c[1]):
            if 0.0 <= t <= window_s and el > best_el:
                best_t, best_el = t, el
        return [(number, None, best_t, None, best_el, None, None)]
    return _passes(number, events, tops, t_lo, t_hi, window_s)


def _crossing(height: Callable[[float], float], state: Callable[[float], tuple[float, float, float]], a: float,
              b: float, ga: float, gb: float) -> tuple[float, bool, float, float]:
    t = _root(height, a, b, ga, gb, CROSSING_TOL_S)
    el, az, _ = state(t)
    return t, gb > 0.0, az, el


def _passes(number: int, events: list[tuple[float, bool, float, float]], tops: list[tuple[float, float]],
            t_lo: float, t_hi: float, window_s: float) -> list[Row]:
    """Rises and sets paired into passes overlapping the window, each with its TCA."""
    pairs: list[tuple[tuple[float, bool, float, float] | None, tuple[float, bool, float, float] | None]] = []
    rise = None
    for event in events:
        if event[1]:
            if rise is not None:
                raise NeedsCatalogSearch(f"two rises in a row for {number}")
            rise = event
        else:
            pairs.append((rise, event))
            rise = None
    if rise is not None:
        pairs.append((rise, None))
    rows: list[Row] = []
    for rise, fall in pairs:
        lo = rise[0] if rise is not None else -math.inf
        hi = fall[0] if fall is not None else math.inf
        if hi < 0.0 or lo > window_s:
            continue
        lo_c, hi_c = max(lo, t_lo), min(hi, t_hi)
        best_el, best_t = -math.inf, 0.5 * (lo_c + hi_c)
        for end in (rise, fall):  # an end is the TCA only if nothing is higher
            if end is not None and end[3] > best_el:
                best_el, best_t = end[3], end[0]
        inside = [(el, t) for t, el in tops if lo_c - TOP_TOL_S <= t <= hi_c + TOP_TOL_S]
        if inside:
            el, t = max(inside)
            if el > best_el:
                best_el, best_t = el, t
        if not math.isfinite(best_el):
            raise NeedsCatalogSearch(f"no culmination found for a pass of {number}")
        rows.append((number, None if rise is None else rise[0], best_t, None if fall is None else fall[0], best_el,
                     None if rise is None else rise[2], None if fall is None else fall[2]))
    return rows


def _root(f: Callable[[float], float], a: float, b: float, fa: float, fb: float, tol: float) -> float:
    """A root of ``f`` in ``[a, b]``, where ``fa`` and ``fb`` differ in sign (or one is 0), to ``tol``: Brent's
    method (inverse quadratic interpolation and secant steps, bisection when they would be slow)."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    c, fc = a, fa
    d = e = b - a
    for _ in range(200):
        if (fb > 0.0) == (fc > 0.0):
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        m = 0.5 * (c - b)
        tol1 = 2.0 * 2.2e-16 * abs(b) + 0.5 * tol
        if abs(m) <= tol1 or fb == 0.0:
            return b
        if abs(e) >= tol1 and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:
                p, q = 2.0 * m * s, 1.0 - s
            else:
                q, r = fa / fc, fb / fc
                p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0))
                q = (q - 1.0) * (r - 1.0) * (s - 1.0)
            if p > 0.0:
                q = -q
            p = abs(p)
            if 2.0 * p < min(3.0 * m * q - abs(tol1 * q), abs(e * q)):
                e, d = d, p / q
            else:
                d = e = m
        else:
            d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol1 else math.copysign(tol1, m)
        fb = f(b)
    return b
