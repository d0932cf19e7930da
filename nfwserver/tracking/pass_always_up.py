"""Satellites above the horizon for the whole window (a geostationary satellite in view, say): one pass each.

The pass search pairs crossings into passes, so a satellite that never crosses the horizon over the whole
extended search has none.  When such a satellite is above the horizon at the window start it is above it
throughout: its pass has neither AOS nor LOS (both beyond the search, as for a pass cut by it), and its TCA
and maximum elevation are those of the highest point inside the window: the elevation is sampled every
:data:`STEP_S` seconds over the window (it turns only twice an orbit, and these orbits last a day or so),
every turn from rising to falling is refined as the search refines culminations
(:func:`nfwserver.tracking.pass_refine.solve`, to 1 ms), and the window's ends are candidates too.

Times are seconds after the chunk's reference instant on input, after the window start in the columns
returned (:class:`~nfwserver.tracking.pass_records.PassList` columns); angles degrees.
"""

from __future__ import annotations

import math

import numpy as np

from nfwserver.tracking.pass_kinematics import PairEvaluator
from nfwserver.tracking.pass_refine import TOP, solve
from nfwserver.tracking.pass_screen import Brackets

#: Sampling step (s) of the elevation over the window: such a satellite is near-geosynchronous or higher, and its
#: elevation turns about twice a day (as the screen samples its group, passes._SLOW_STEP_S).
STEP_S = 3600.0


def always_up_columns(ev: PairEvaluator, brackets: Brackets, satellites: int, catalog_numbers: np.ndarray,
                      win_lo: float, window_s: float) -> dict[str, np.ndarray]:
    """The passes of the satellites (indices ``0 .. satellites - 1`` into ``ev``) that the screen found neither a
    crossing nor a hidden peak for (``brackets``), and that are above the horizon at ``win_lo``: PassList
    columns, or {}."""
    crosses = np.zeros(satellites, dtype=bool)  # a mask, not np.setdiff1d (which imports numpy.ma)
    crosses[brackets.crossings.sat] = True
    crosses[brackets.peaks.sat] = True
    candidates = np.flatnonzero(~crosses)
    if not len(candidates):
        return {}
    with np.errstate(invalid="ignore"):
        up = ev.evaluate(candidates, np.full(len(candidates), win_lo)).f > 0.0
    sats = candidates[up]
    if not len(sats):
        return {}
    n = max(1, math.ceil(window_s / STEP_S))
    grid = win_lo + window_s * np.arange(n + 1) / n
    pair_sat, pair_t = np.repeat(sats, n + 1), np.tile(grid, len(sats))
    kin = ev.evaluate(pair_sat, pair_t, grouped=True)
    el, rate = kin.el.reshape(len(sats), n + 1), kin.s_rate.reshape(len(sats), n + 1)
    # The window's ends, then every refined turn from rising to falling: the highest is the TCA.
    ends = np.where(el[:, -1] > el[:, 0], n, 0)
    rows = np.arange(len(sats))
    best_t, best_el = grid[ends], el[rows, ends]
    row, k = np.nonzero((rate[:, :-1] > 0.0) & (rate[:, 1:] <= 0.0))
    if len(row):
        top = solve(ev, sats[row], grid[k], grid[k + 1], rate[row, k], rate[row, k + 1], np.full(len(row), TOP))
        inside = np.isfinite(top.el) & (top.t >= win_lo) & (top.t <= win_lo + window_s)
        order = np.lexsort((top.el[inside], row[inside]))  # the last of each row is its highest
        for r, t, e in zip(row[inside][order].tolist(), top.t[inside][order].tolist(), top.el[inside][order].tolist()):
            if e > best_el[r]:
                best_t[r], best_el[r] = t, e
    nan = np.full(len(sats), np.nan)
    return {"catalog_number": catalog_numbers[sats], "aos_s": nan, "tca_s": best_t - win_lo, "los_s": nan,
            "max_elevation_deg": best_el, "aos_azimuth_deg": nan, "los_azimuth_deg": nan}
