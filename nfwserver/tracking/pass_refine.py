"""Pass search, stage 2: refine brackets of every satellite together.

One solver serves three problems, mixed freely in one batch:

- ``CROSSING``: the root of ``f = elevation - horizon`` (AOS or LOS);
- ``TOP``: the maximum of the elevation, as the root of ``d(sin el)/dt`` (TCA; smooth even for
  near-zenith passes, where the elevation itself has an almost sharp peak);
- ``F_TOP``: the maximum of ``f`` under a non-flat horizon, as the root of ``df/dt``.

Each round evaluates every unfinished bracket at once (:class:`PairEvaluator`: one compiled
SGP4 call per satellite), takes a Newton step with the analytic derivative, and falls back to
bisection when the step would leave the bracket (or, for a maximum, when the curvature has the
wrong sign).  A bracket is finished when its Newton step is below the tolerance or its width is;
finished brackets leave the batch, so the hard ones (grazing passes, long high passes) iterate
as long as they need without slowing the rest.  Hidden-peak brackets are also dropped as soon as
a local quadratic model shows the peak stays more than 2 degrees below the horizon.
Times are seconds after the search start; angles degrees.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from nfwserver.tracking.pass_kinematics import PairEvaluator

CROSSING, TOP, F_TOP = 0, 1, 2
#: Convergence tolerances (s): crossings and maxima.
CROSSING_TOL_S = 1e-4
TOP_TOL_S = 1e-3
_MAX_ROUNDS = 80
#: A hidden peak whose modelled height stays this far below the horizon (deg) is given up.
_HOPELESS_DEG = -2.0


@dataclass
class Solution:
    """Refined times and the values seen there (arrays in the order of the brackets)."""

    t: np.ndarray  #: the root or maximum (s)
    el: np.ndarray  #: elevation at ``t`` (deg)
    az: np.ndarray  #: azimuth at ``t`` (deg)
    f: np.ndarray  #: f at ``t`` (deg)
    el_rate: np.ndarray  #: d(elevation)/dt at ``t`` (deg/s)
    best_f: np.ndarray  #: the largest f seen while iterating (deg)
    best_t: np.ndarray  #: where it was seen (s)
    rounds: int  #: iterations the slowest bracket needed


def solve(ev: PairEvaluator, sat: np.ndarray, a: np.ndarray, b: np.ndarray, ga: np.ndarray, gb: np.ndarray,
          kind: np.ndarray, hidden: np.ndarray | None = None) -> Solution:
    """Refine brackets ``[a, b]`` of satellites ``sat``; ``ga``/``gb`` hold the sign-carrying values at
    the ends (f for crossings, the rising/falling rate for maxima).  ``hidden`` marks hidden-peak
    brackets, which may be abandoned early."""
    n = len(sat)
    # Work in satellite order, so every round's batch is already grouped by satellite.
    perm = np.argsort(sat, kind="stable")
    undo = np.empty_like(perm)
    undo[perm] = np.arange(n)
    sat, kind = sat[perm], kind[perm]
    a, b, ga, gb = a[perm], b[perm], ga[perm], gb[perm]
    hidden = None if hidden is None else hidden[perm]
    a, b = a.astype(float).copy(), b.astype(float).copy()
    ga = np.nan_to_num(ga.astype(float), nan=0.0, neginf=-180.0, posinf=180.0)
    gb = np.nan_to_num(gb.astype(float), nan=0.0, neginf=-180.0, posinf=180.0)
    hidden = np.zeros(n, dtype=bool) if hidden is None else hidden
    tol = np.where(kind == CROSSING, CROSSING_TOL_S, TOP_TOL_S)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(gb != ga, (a * gb - b * ga) / (gb - ga), 0.5 * (a + b))
    c = np.where(np.isfinite(c), np.clip(c, np.minimum(a, b), np.maximum(a, b)), 0.5 * (a + b))
    t_out = c.copy()
    el_out = np.full(n, np.nan)
    az_out = np.full(n, np.nan)
    f_out = np.full(n, -np.inf)
    el_rate_out = np.full(n, np.nan)
    best_f = np.full(n, -np.inf)
    best_t = c.copy()
    active = np.arange(n)
    rounds = 0
    while len(active) and rounds < _MAX_ROUNDS:
        rounds += 1
        ca = c[active]
        k = ev.evaluate(sat[active], ca, grouped=True)
        kd = kind[active]
        f = np.maximum(np.nan_to_num(k.f, nan=-180.0), -180.0)
        g = np.where(kd == CROSSING, f, np.where(kd == TOP, k.s_rate, k.f_rate))
        g1 = np.where(kd == CROSSING, k.f_rate, np.where(kd == TOP, k.s_accel, k.f_accel))
        el_out[active], az_out[active], f_out[active], t_out[active] = k.el, k.az, f, ca
        el_rate_out[active] = k.el_rate
        better = f > best_f[active]
        best_f[active] = np.where(better, f, best_f[active])
        best_t[active] = np.where(better, ca, best_t[active])
        aa, bb, gaa = a[active], b[active], ga[active]
        same_as_a = (g > 0.0) == (gaa > 0.0)
        a[active] = aa = np.where(same_as_a, ca, aa)
        b[active] = bb = np.where(same_as_a, bb, ca)
        ga[active] = np.where(same_as_a, g, gaa)
        gb[active] = np.where(same_as_a, gb[active], g)
        lo, hi = np.minimum(aa, bb), np.maximum(aa, bb)
        with np.errstate(invalid="ignore", divide="ignore"):
            newton = ca - g / g1
        ok = np.isfinite(newton) & (newton > lo) & (newton < hi) & ((kd == CROSSING) | (g1 < 0.0))
        step = np.abs(newton - ca)
        tl = tol[active]
        done = (ok & (step < tl)) | (hi - lo < tl) | (g == 0.0) | ~np.isfinite(g)
        t_out[active] = np.where(ok & done, newton, ca)
        hid = hidden[active]
        if hid.any():
            with np.errstate(invalid="ignore", divide="ignore"):
                model = f + np.where(k.f_accel < 0.0, k.f_rate ** 2 / (-2.0 * k.f_accel), np.inf)
            done |= hid & (best_f[active] <= 0.0) & ok & (step < 120.0) & (model < _HOPELESS_DEG)
        c[active] = np.where(ok, newton, 0.5 * (lo + hi))
        active = active[~done]
    return Solution(t_out[undo], el_out[undo], az_out[undo], f_out[undo], el_rate_out[undo], best_f[undo],
                    best_t[undo], rounds)
