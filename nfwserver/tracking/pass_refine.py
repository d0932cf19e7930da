"""Pass search, stage 2: refine brackets of every satellite together.

One solver serves three problems, mixed freely in one batch:

- ``CROSSING``: the root of ``f = elevation - horizon`` (AOS or LOS);
- ``TOP``: the maximum of the elevation, as the root of ``d(sin el)/dt`` (TCA; smooth even for
  near-zenith passes, where the elevation itself has an almost sharp peak);
- ``F_TOP``: the maximum of ``f`` under a non-flat horizon, as the root of ``df/dt``.

Each round evaluates every unfinished bracket at once (:class:`PairEvaluator`: one compiled
SGP4 call per satellite).  A crossing steps to the root of the second-order Taylor polynomial of
``f`` (analytic f' and f''; cubic convergence), a maximum takes a Newton step; either falls back
to bisection when the step would leave the bracket (or, for a maximum, when the curvature has the
wrong sign).  A bracket is finished when its step is below the tolerance or its width is, or when
the step is small and the error bounded for it is well below the tolerance: for a crossing the
bounds on the errors of f' (SGP4's velocity is not the exact derivative of its position) and of
f'' (approximate acceleration), and f''' estimated from two rounds; for a maximum the error that
the quadratic convergence seen in its last two Newton steps predicts.  The root is then the
step's end, with the values there from a second-order Taylor series; finished brackets leave the
batch, so the hard ones (grazing passes, long high passes) iterate as long as they need without
slowing the rest.  Hidden-peak brackets are also dropped as soon as
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
#: A Newton step is taken as final when it is below this (s) and the error its quadratic
#: convergence predicts for it is below ``_SAFETY`` times the tolerance.
_QUADRATIC_S = 2.0
_SAFETY = 0.01
#: A crossing's step is final when the error bounded for it is below this fraction of the tolerance.
_CROSSING_SAFETY = 0.5
#: Largest accepted final Newton step (s) towards a maximum (the elevation there comes from a
#: second-order Taylor series of sin(elevation), exact to ~1e-9 over such a step).
_TOP_STEP_S = 0.05
#: Margin on the third derivative of f estimated from the change of f'' between two rounds.
_JERK_MARGIN = 3.0
#: Largest error of sin(elevation) (~radians of elevation) that a maximum's final step may bring from
#: the error of s' (SGP4's velocity): 3.5e-8 rad = 2e-6 deg.
_TOP_S_TOL = 3.5e-8
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
    best_up: np.ndarray  #: height above the horizontal plane there (km)
    best_up_accel: np.ndarray  #: its second derivative there (km/s^2)
    f_accel: np.ndarray  #: d2f/dt2 at ``t`` (deg/s^2)
    rounds: int  #: iterations the slowest bracket needed


#: Rows of the per-bracket state matrix (one column per unfinished bracket, compacted every round).
(_IDX, _SAT, _KIND, _HID, _A, _B, _GA, _GB, _C, _TOL, _BEST_F, _BEST_T, _BEST_UP, _BEST_UP_ACCEL, _PREV_STEP,
 _PREV_T, _PREV_ACCEL) = range(17)
#: Rows of the result matrix, in the order of the fields of :class:`Solution`.
_RESULTS = 10


def solve(ev: PairEvaluator, sat: np.ndarray, a: np.ndarray, b: np.ndarray, ga: np.ndarray, gb: np.ndarray,
          kind: np.ndarray, hidden: np.ndarray | None = None, guess: np.ndarray | None = None) -> Solution:
    """Refine brackets ``[a, b]`` of satellites ``sat``; ``ga``/``gb`` hold the sign-carrying values at
    the ends (f for crossings, the rising/falling rate for maxima).  ``hidden`` marks hidden-peak
    brackets, which may be abandoned early; ``guess`` holds first guesses (NaN: none), else the
    secant of the end values is the first guess."""
    n = len(sat)
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ga = np.nan_to_num(np.asarray(ga, dtype=float), nan=0.0, neginf=-180.0, posinf=180.0)
    gb = np.nan_to_num(np.asarray(gb, dtype=float), nan=0.0, neginf=-180.0, posinf=180.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(gb != ga, (a * gb - b * ga) / (gb - ga), 0.5 * (a + b))
    if guess is not None:
        c = np.where(np.isfinite(guess), guess, c)
    c = np.where(np.isfinite(c), np.clip(c, np.minimum(a, b), np.maximum(a, b)), 0.5 * (a + b))
    # The state of every unfinished bracket is one column of ``st`` (indices and flags as exact floats),
    # so that one gather per round drops the finished ones.  Columns run in satellite order, so every
    # round's batch is already grouped by satellite.
    st = np.empty((17, n))
    st[_IDX] = np.arange(n)
    st[_SAT], st[_KIND], st[_HID] = sat, kind, False if hidden is None else hidden
    st[_A], st[_B], st[_GA], st[_GB], st[_C] = a, b, ga, gb, c
    st[_TOL] = np.where(st[_KIND] == CROSSING, CROSSING_TOL_S, TOP_TOL_S)
    st[_BEST_F], st[_BEST_T], st[_BEST_UP:_BEST_UP_ACCEL + 1] = -np.inf, c, np.nan
    st[_PREV_STEP] = np.inf  # the previous round's Newton step (inf after a bisection)
    st[_PREV_T:_PREV_ACCEL + 1] = np.nan  # the previous round's time and f'' there (crossings)
    st = st[:, np.argsort(sat, kind="stable")]
    out = np.full((_RESULTS, n), np.nan)
    out[3] = out[5] = -np.inf  # f and best_f of brackets never evaluated
    rounds = 0
    while st.shape[1] and rounds < _MAX_ROUNDS:
        rounds += 1
        (_, s_, kd, hid, a, b, ga, gb, ca, tol, best_f, best_t, best_up, best_up_accel, ps, prev_t,
         prev_accel) = st
        k = ev.evaluate(s_.astype(np.intp), ca, grouped=True)
        cross, top = kd == CROSSING, kd == TOP
        f = np.fmax(k.f, -180.0)  # NaN and -inf (SGP4 failed) count as -180
        g = np.where(cross, f, np.where(top, k.s_rate, k.f_rate))
        g1 = np.where(cross, k.f_rate, np.where(top, k.s_accel, k.f_accel))
        better = f > best_f
        np.copyto(best_f, f, where=better)
        np.copyto(best_t, ca, where=better)
        np.copyto(best_up, k.up, where=better)
        np.copyto(best_up_accel, k.up_accel, where=better)
        same_as_a = (g > 0.0) == (ga > 0.0)
        new_b = ~same_as_a
        np.copyto(a, ca, where=same_as_a)
        np.copyto(b, ca, where=new_b)
        np.copyto(ga, g, where=same_as_a)
        np.copyto(gb, g, where=new_b)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        with np.errstate(invalid="ignore", divide="ignore"):
            newton = ca - g / g1
            # Crossings: the root of the second-order Taylor polynomial (Halley-like, cubic convergence).
            disc = g1 * g1 - 2.0 * g * k.f_accel
            quad = ca - 2.0 * g / (g1 + np.copysign(np.sqrt(np.maximum(disc, 0.0)), g1))
            np.copyto(newton, quad, where=cross & (disc > 0.0) & np.isfinite(quad))
        ok = np.isfinite(newton) & (newton > lo) & (newton < hi) & (cross | (g1 < 0.0))
        step = np.abs(newton - ca)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            # A maximum's Newton step leaves an error ~C step^2, C = step / previous step^2 as observed
            # once two Newton steps were taken.
            predicted = step / (ps * ps) * step * step
            # A crossing's step solves the second-order Taylor polynomial of f: its error comes from
            # the error of f' (SGP4's velocity), of f'' (the approximate acceleration) and from f'''
            # (the change of f'' since the previous round, with a margin).  Before a second round,
            # Newton's C = |f''/2f'| stands in for the last two.
            jerk = _JERK_MARGIN * np.abs((k.f_accel - prev_accel) / (ca - prev_t))
            curve = np.where(np.isfinite(jerk), (0.5 * k.f_accel_err + jerk * step / 6.0) * step,
                             0.5 * np.abs(k.f_accel) * step)
            cross_err = (k.f_rate_err + curve) * step / np.abs(k.f_rate)
        close = ok & np.where(cross, (step < _QUADRATIC_S) & (cross_err < _CROSSING_SAFETY * tol),
                              top & (step < _TOP_STEP_S) & (predicted < _SAFETY * tol) & (step < 0.25 * ps)
                              & (k.s_rate_err * step < _TOP_S_TOL * np.cos(np.radians(k.el))))
        done = (ok & (step < tol)) | close | (hi - lo < tol) | (g == 0.0) | ~np.isfinite(g)
        t_out = np.where(ok & done, newton, ca)
        if hid.any():
            with np.errstate(invalid="ignore", divide="ignore"):
                model = f + np.where(k.f_accel < 0.0, k.f_rate ** 2 / (-2.0 * k.f_accel), np.inf)
            done |= (hid != 0.0) & (best_f <= 0.0) & ok & (step < 120.0) & (model < _HOPELESS_DEG)
        if rounds == _MAX_ROUNDS:
            done[:] = True
        if done.any():
            fin = st[_IDX, done].astype(np.intp)
            out[:, fin] = np.stack((t_out, k.el, k.az, f, k.el_rate, best_f, best_t, best_up, best_up_accel,
                                    k.f_accel))[:, done]
        if close.any():
            _finish_close(out, np.stack((newton, ca, k.el, k.el_rate, k.el_accel, k.s_rate, k.s_accel, k.az,
                                         k.az_rate, k.az_accel, f, best_f, best_t, kd, st[_IDX]))[:, close])
        np.copyto(ps, step)
        np.copyto(ps, np.inf, where=~ok)
        np.copyto(prev_t, ca)
        np.copyto(prev_accel, k.f_accel)
        np.copyto(ca, np.where(ok, newton, 0.5 * (lo + hi)))
        st = st[:, ~done]
    return Solution(*out, rounds)


def _finish_close(out: np.ndarray, v: np.ndarray) -> None:
    """Write into ``out`` the values at the accepted roots of brackets finished by a final step, carried over
    from the evaluated time by Taylor's formula.  ``v`` holds, one column per bracket: the root, the time
    evaluated, the elevation with its two derivatives, s' and s'', the azimuth with its two derivatives,
    f, the best f and its time so far, the kind and the bracket's index."""
    newton, ca, el0, el1, el2, s1, s2, az0, az1, az2, f, best_f, best_t, kd, idx = v
    dt = newton - ca
    cross = kd == CROSSING
    el_cross = el0 + (el1 + 0.5 * el2 * dt) * dt
    s_top = np.sin(np.radians(el0)) + (s1 + 0.5 * s2 * dt) * dt
    el_top = np.degrees(np.arcsin(np.clip(s_top, -1.0, 1.0)))
    el = np.where(cross, el_cross, np.maximum(el_top, el0))
    f_out = np.where(cross, 0.0, f + el - el0)
    up = f_out > best_f
    out[1:7, idx.astype(np.intp)] = (el, (az0 + (az1 + 0.5 * az2 * dt) * dt) % 360.0, f_out, el1 + el2 * dt,
                                     np.where(up, f_out, best_f), np.where(up, newton, best_t))
