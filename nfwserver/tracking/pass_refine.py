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
wrong sign).  A bracket is finished when its step is below the tolerance (:mod:`~nfwserver.tracking.pass_events`'
``CROSSING_TOL_S`` for crossings, ``TOP_TOL_S`` for maxima) or its width is, or when
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

from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from nfwserver.tracking.pass_events import CROSSING_TOL_S, TOP_TOL_S
from nfwserver.tracking.pass_kinematics import Kinematics, PairEvaluator

CROSSING, TOP, F_TOP = 0, 1, 2
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
#: Brackets evaluated at once within a round (bounds the memory of a round's kinematics and steps).
_SLICE = 4096


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


class _Outputs:
    """The columns of a :class:`Solution` (in the solver's order), filled as brackets finish."""

    def __init__(self, n: int, first: np.ndarray) -> None:
        #: in the order of Solution's fields: t, el, az, f, el_rate, best_f, best_t, best_up, best_up_accel, f_accel
        self.columns = [first.copy(), np.full(n, np.nan), np.full(n, np.nan), np.full(n, -np.inf),
                        np.full(n, np.nan), np.full(n, -np.inf), first.copy(), np.full(n, np.nan),
                        np.full(n, np.nan), np.full(n, np.nan)]

    def store(self, where: np.ndarray, values: tuple[Any, ...], picked: np.ndarray) -> None:
        """Write ``values[j][picked]`` (one array per column, in the order of :attr:`columns`) at ``where``."""
        for column, value in zip(self.columns, values):
            column[where] = value[picked]


@dataclass(slots=True)
class _Live:
    """The unfinished brackets (arrays of one length, in satellite order): what each carries from round to
    round."""

    idx: np.ndarray  #: index among all the brackets (in the order given to :func:`solve`)
    sat: np.ndarray
    cross: np.ndarray  #: a crossing (else a maximum)
    top: np.ndarray  #: a maximum of the elevation (else of f, or a crossing)
    hidden: np.ndarray  #: a hidden peak (may be given up)
    tol: np.ndarray  #: tolerance (s)
    a: np.ndarray  #: bracket ends (s) and the bracketed function's values there
    b: np.ndarray
    ga: np.ndarray
    gb: np.ndarray
    c: np.ndarray  #: the next time to evaluate (s)
    best_f: np.ndarray  #: the largest f seen (deg), where (s), the height above the horizontal plane there
    best_t: np.ndarray  #: (km) and its second derivative (km/s^2)
    best_up: np.ndarray
    best_up_accel: np.ndarray
    prev_step: np.ndarray  #: the previous round's Newton step (inf after a bisection), time and f''
    prev_t: np.ndarray
    prev_accel: np.ndarray

    def part(self, which: slice | np.ndarray) -> _Live:
        """The brackets ``which`` picks (views for a slice: a round updates them in place)."""
        return _Live(*(getattr(self, name)[which] for name in _LIVE))


_LIVE = tuple(f.name for f in fields(_Live))


def solve(ev: PairEvaluator, sat: np.ndarray, a: np.ndarray, b: np.ndarray, ga: np.ndarray, gb: np.ndarray,
          kind: np.ndarray, hidden: np.ndarray | None = None, guess: np.ndarray | None = None) -> Solution:
    """Refine brackets ``[a, b]`` (s after the search start) of satellites ``sat`` (indices into ``ev``).

    ``kind`` says per bracket what is sought (``CROSSING``, ``TOP`` or ``F_TOP``); ``ga``/``gb`` hold the
    sign-carrying values of the bracketed function at the ends: f (deg) for crossings, d(sin el)/dt (1/s)
    for ``TOP``, df/dt (deg/s) for ``F_TOP``.  ``hidden`` marks hidden-peak brackets, which may be abandoned
    early; ``guess`` holds first guesses (s; NaN: none), else the secant of the end values is the first
    guess.  Angles are topocentric (the observer's horizon frame).  The solution's arrays are in the order
    of the brackets given.
    """
    n = len(sat)
    # Work in satellite order, so every round's batch is already grouped by satellite.
    perm = np.argsort(sat, kind="stable")
    live = _start(sat[perm], kind[perm], a[perm], b[perm], ga[perm], gb[perm],
                  np.zeros(n, dtype=bool) if hidden is None else hidden[perm],
                  None if guess is None else guess[perm])
    live.idx = perm  # each bracket's place in the given order: the outputs are written there
    first = np.empty(n)
    first[perm] = live.c
    out = _Outputs(n, first)
    rounds = 0
    while len(live.idx) and rounds < _MAX_ROUNDS:
        rounds += 1
        # A round in slices: its temporaries (the kinematics and the steps) are held for one slice at a time.
        done = np.concatenate([_round(ev, live.part(slice(s0, s0 + _SLICE)), out, rounds == _MAX_ROUNDS)
                               for s0 in range(0, len(live.idx), _SLICE)])
        if done.any():
            live = live.part(~done)
    t, el, az, f_end, el_rate, best_f, best_t, best_up, best_up_accel, f_accel = out.columns
    return Solution(t, el, az, f_end, el_rate, best_f, best_t, best_up, best_up_accel, f_accel, rounds)


def _start(sat: np.ndarray, kind: np.ndarray, a: np.ndarray, b: np.ndarray, ga: np.ndarray, gb: np.ndarray,
           hidden: np.ndarray, guess: np.ndarray | None) -> _Live:
    """Every bracket live, with its first point to evaluate: ``guess`` (s) where finite, else the secant
    through the ends' values, else the middle; always inside the bracket.  Infinite end values (SGP4
    failed) are clipped to +-180 and NaN ones read as 0, so the bracket keeps a sign to follow."""
    n = len(sat)
    a, b = a.astype(float).copy(), b.astype(float).copy()
    ga = np.nan_to_num(ga.astype(float), nan=0.0, neginf=-180.0, posinf=180.0)
    gb = np.nan_to_num(gb.astype(float), nan=0.0, neginf=-180.0, posinf=180.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(gb != ga, (a * gb - b * ga) / (gb - ga), 0.5 * (a + b))
    if guess is not None:
        c = np.where(np.isfinite(guess), guess, c)
    c = np.where(np.isfinite(c), np.clip(c, np.minimum(a, b), np.maximum(a, b)), 0.5 * (a + b))
    return _Live(idx=np.arange(n), sat=sat, cross=kind == CROSSING, top=kind == TOP, hidden=hidden,
                 tol=np.where(kind == CROSSING, CROSSING_TOL_S, TOP_TOL_S), a=a, b=b, ga=ga, gb=gb, c=c,
                 best_f=np.full(n, -np.inf), best_t=c.copy(), best_up=np.full(n, np.nan),
                 best_up_accel=np.full(n, np.nan), prev_step=np.full(n, np.inf), prev_t=np.full(n, np.nan),
                 prev_accel=np.full(n, np.nan))


def _round(ev: PairEvaluator, v: _Live, out: _Outputs, last: bool) -> np.ndarray:
    """One round for the brackets ``v`` (views, updated in place); the finished ones are written to ``out``.

    Evaluates every bracket at its point ``c`` (s), narrows the bracket, takes the next step, decides which
    brackets are finished (step or bracket below the tolerance, a final step accepted, a hopeless hidden
    peak, or the last round).  Returns which finished.
    """
    ca = v.c.copy()
    k = ev.evaluate(v.sat, ca, grouped=True)
    f = np.fmax(k.f, -180.0)  # NaN and -inf (SGP4 failed) count as -180
    g = np.where(v.cross, f, np.where(v.top, k.s_rate, k.f_rate))
    g1 = np.where(v.cross, k.f_rate, np.where(v.top, k.s_accel, k.f_accel))
    _note_best(v, ca, k, f)
    lo, hi = _narrow(v, ca, g)
    newton = _next_point(v.cross, ca, g, g1, k.f_accel)
    ok = np.isfinite(newton) & (newton > lo) & (newton < hi) & (v.cross | (g1 < 0.0))
    step = np.abs(newton - ca)
    close = ok & _final_step(v, k, ca, step)
    v.prev_t[:], v.prev_accel[:] = ca, k.f_accel
    done = (ok & (step < v.tol)) | close | (hi - lo < v.tol) | (g == 0.0) | ~np.isfinite(g)
    values = [np.where(ok & done, newton, ca), k.el, k.az, f, k.el_rate]
    if close.any():
        values = _carry_to_root(v, k, ca, newton, f, np.flatnonzero(close), values)
    v.prev_step[:] = np.where(ok, step, np.inf)
    if v.hidden.any():
        done |= _hopeless(v, k, f, ok, step)
    v.c[:] = np.where(ok, newton, 0.5 * (lo + hi))
    if last:
        done[:] = True
    if done.any():
        out.store(v.idx[done], (*values, v.best_f, v.best_t, v.best_up, v.best_up_accel, k.f_accel), done)
    finished: np.ndarray = done
    return finished


def _note_best(v: _Live, ca: np.ndarray, k: Kinematics, f: np.ndarray) -> None:
    """Keep, per bracket, the largest f (deg) seen so far, its time ``ca`` (s), and the height above the
    observer's horizontal plane there (km) with its second derivative (km/s^2)."""
    better = f > v.best_f
    v.best_f[:] = np.where(better, f, v.best_f)
    v.best_t[:] = np.where(better, ca, v.best_t)
    v.best_up[:] = np.where(better, k.up, v.best_up)
    v.best_up_accel[:] = np.where(better, k.up_accel, v.best_up_accel)


def _narrow(v: _Live, ca: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Replace by ``ca`` (s) the bracket end whose value has the sign of ``g``, the bracketed function's
    value there; returns the bracket's lower and upper ends (s)."""
    same_as_a = (g > 0.0) == (v.ga > 0.0)
    v.a[:] = np.where(same_as_a, ca, v.a)
    v.b[:] = np.where(same_as_a, v.b, ca)
    v.ga[:] = np.where(same_as_a, g, v.ga)
    v.gb[:] = np.where(same_as_a, v.gb, g)
    return np.minimum(v.a, v.b), np.maximum(v.a, v.b)


def _next_point(cross: np.ndarray, ca: np.ndarray, g: np.ndarray, g1: np.ndarray, f_accel: np.ndarray
                ) -> np.ndarray:
    """The time (s) one step from ``ca`` leads to.

    For a maximum, Newton's step on ``g`` (d(sin el)/dt in 1/s or df/dt in deg/s) with its derivative
    ``g1``; for a crossing (``g`` = f in deg, ``g1`` = f' in deg/s, ``f_accel`` = f'' in deg/s^2) the nearer
    root of the second-order Taylor polynomial of f (Halley-like, cubic convergence), or Newton's step where
    that has no real root.  May be NaN or outside the bracket: the caller checks.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        newton = ca - g / g1
        disc = g1 * g1 - 2.0 * g * f_accel
        quad = ca - 2.0 * g / (g1 + np.copysign(np.sqrt(np.maximum(disc, 0.0)), g1))
        point: np.ndarray = np.where(cross & (disc > 0.0) & np.isfinite(quad), quad, newton)
    return point


def _final_step(v: _Live, k: Kinematics, ca: np.ndarray, step: np.ndarray) -> np.ndarray:
    """Which steps (s, from ``ca``) may be taken as final, their bounded error being well below the tolerance.

    A maximum's Newton step leaves an error ~C step^2, C = step / previous step^2 as observed once two
    Newton steps were taken; the step must also be short enough for the second-order Taylor series of
    sin(elevation) and for the error of s' (1/s, from SGP4's velocity).  A crossing's step solves the
    second-order Taylor polynomial of f: its error comes from the error of f' (deg/s, SGP4's velocity),
    of f'' (deg/s^2, the approximate acceleration) and from f''' (the change of f'' since the previous
    round, with a margin).  Before a second round, Newton's C = |f''/2f'| stands in for the last two.
    Reads the previous round's step, time and f'' from ``v``; the caller updates them afterwards.
    """
    prev_step = v.prev_step.copy()
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        predicted = step / (prev_step * prev_step) * step * step
        jerk = _JERK_MARGIN * np.abs((k.f_accel - v.prev_accel) / (ca - v.prev_t))
        curve = np.where(np.isfinite(jerk), (0.5 * k.f_accel_err + jerk * step / 6.0) * step,
                         0.5 * np.abs(k.f_accel) * step)
        cross_err = (k.f_rate_err + curve) * step / np.abs(k.f_rate)
    del jerk, curve
    final: np.ndarray = np.where(
        v.cross, (step < _QUADRATIC_S) & (cross_err < _CROSSING_SAFETY * v.tol),
        v.top & (step < _TOP_STEP_S) & (predicted < _SAFETY * v.tol) & (step < 0.25 * prev_step)
        & (k.s_rate_err * step < _TOP_S_TOL * np.cos(np.radians(k.el))))
    return final


def _carry_to_root(v: _Live, k: Kinematics, ca: np.ndarray, newton: np.ndarray, f: np.ndarray, sel: np.ndarray,
                   values: list[np.ndarray]) -> list[np.ndarray]:
    """The values at the accepted roots ``newton[sel]`` (s), carried over from ``ca`` by second-order Taylor
    series: topocentric elevation (deg; for a maximum through sin(elevation)), azimuth (deg, 0..360), f
    (deg; 0 at a crossing) and the elevation rate (deg/s).

    ``values`` holds (t, el, az, f, el_rate) at ``ca``; returns them with the entries ``sel`` replaced (new
    arrays: those of ``k`` and ``f`` are not written).  The largest f seen is raised where the root's is
    larger.
    """
    dt = (newton - ca)[sel]
    el0, cross_c = k.el[sel], v.cross[sel]
    el_cross = el0 + (k.el_rate[sel] + 0.5 * k.el_accel[sel] * dt) * dt
    s_top = np.sin(np.radians(el0)) + (k.s_rate[sel] + 0.5 * k.s_accel[sel] * dt) * dt
    el_top = np.degrees(np.arcsin(np.clip(s_top, -1.0, 1.0)))
    el_c = np.where(cross_c, el_cross, np.maximum(el_top, el0))
    az_rate, az_accel = k.azimuth_rates(sel)
    f_c = np.where(cross_c, 0.0, f[sel] + el_c - el0)
    values = [values[0], *(x.copy() for x in values[1:])]
    values[1][sel] = el_c
    values[2][sel] = (k.az[sel] + (az_rate + 0.5 * az_accel * dt) * dt) % 360.0
    values[3][sel] = f_c
    values[4][sel] = k.el_rate[sel] + k.el_accel[sel] * dt
    up = f_c > v.best_f[sel]
    v.best_f[sel[up]] = f_c[up]
    v.best_t[sel[up]] = newton[sel][up]
    return values


def _hopeless(v: _Live, k: Kinematics, f: np.ndarray, ok: np.ndarray, step: np.ndarray) -> np.ndarray:
    """Hidden peaks to give up: never above the horizon so far, converging (a step under 120 s), with a
    peak that a local quadratic model of f (deg) puts more than 2 degrees below the horizon."""
    with np.errstate(invalid="ignore", divide="ignore"):
        model = f + np.where(k.f_accel < 0.0, k.f_rate ** 2 / (-2.0 * k.f_accel), np.inf)
    given_up: np.ndarray = v.hidden & (v.best_f <= 0.0) & ok & (step < 120.0) & (model < _HOPELESS_DEG)
    return given_up
