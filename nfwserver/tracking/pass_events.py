"""What a pass is and how precisely its events are found: the one definition both pass searches use.

A pass is an interval during which the satellite's topocentric elevation is above the horizon (a flat
horizon at one elevation, or a horizon table's elevation at the satellite's azimuth):

- AOS is the upward crossing, LOS the downward one: a root of ``elevation - horizon``, found to within
  :data:`CROSSING_TOL_S` seconds;
- TCA is the instant of the pass's highest elevation: its highest culmination (a root of the rate of
  ``sin(elevation)``, found to within :data:`TOP_TOL_S` seconds) or, if that is higher, one of its ends;
  a culmination belongs to a pass when it lies inside it, give or take :data:`TOP_TOL_S`;
- a pass in progress at either end of the window gets its true AOS and LOS: each satellite is searched
  from :func:`look_back_s` (at most :data:`MAX_LOOK_BACK_S`) before the window to as long after it; a rise
  or set beyond that is unknown
  (``None``), and a satellite up over the whole extended search has one pass with neither;
- a satellite whose position at the window's start cannot be computed, or lies further than
  :data:`MAX_PLAUSIBLE_RANGE_KM`, is left out (``skipped``).

Two searches find these events: :mod:`nfwserver.tracking.passes` for catalogs (numpy, every satellite at once:
second-order steps with analytic derivatives) and :mod:`nfwserver.tracking.few_passes` for ``passes --sat``
(pure Python, one satellite at a time: Brent's method), which imports no numpy, and so neither does this
module.  Both stop at the same tolerances, so their times agree within twice them;
tests/tracking/test_one_pass_definition.py compares their rows on the whole catalog.
"""

from __future__ import annotations

from nfwserver.tracking.constants import SECONDS_PER_DAY

#: Tolerance (s) of AOS and LOS.  Not idle: loosened to 1 s, it moves 105 of the catalog's 187,696 AOS and
#: LOS of a day by more than 80 us (up to 1.4 ms: the written milliseconds).
CROSSING_TOL_S = 1e-4
#: Tolerance (s) of a culmination's time (TCA); the elevation there is off by far less than 1e-6 deg.
TOP_TOL_S = 1e-3
#: Ranges beyond this (km; about four times the Moon's distance) are propagation failures: no object of an
#: SGP4 catalog (Earth orbits) is further.
MAX_PLAUSIBLE_RANGE_KM = 1.5e6
#: Orbits up to this period (s) that are near-circular (eccentricity below :data:`NEAR_CIRCULAR_ECC`) have
#: passes shorter than half a period, so half a period of look-back finds the AOS of a pass in progress.
SHORT_PERIOD_S = 3.0 * 3600.0
NEAR_CIRCULAR_ECC = 0.05
#: The search never reaches further than this (s) before or after the window.
MAX_LOOK_BACK_S = SECONDS_PER_DAY


def look_back_s(period_s: float, eccentricity: float) -> float:
    """How far (s) the search of a satellite with this orbital period (s) should reach before and after the
    window: half a period for short near-circular orbits, else a period (searches stop at
    :data:`MAX_LOOK_BACK_S`)."""
    return (0.5 if eccentricity < NEAR_CIRCULAR_ECC and period_s <= SHORT_PERIOD_S else 1.0) * period_s
