"""PREDICT's position listings: ``predict -f`` (``GET_SAT_POS``) and ``predict -p`` (``PREDICT``).

PREDICT 2.2's UDP server answers these two commands by running ``predict -f``/``-p`` and sending the
output one line per datagram.  This module reproduces what those two modes print, line by line,
from PREDICT 2.2.4's ``QuickFind``/``QuickPredict``/``FindAOS``/``FindLOS`` (kd2bd/predict, predict.c):

- every line is ``%ld %s %4d %4d %4d %4d %4d %6ld %6ld %c`` + LF: Unix time (s), ``Www DDMonYY HH:MM:SS``
  (UTC), elevation, azimuth (deg), phase (256ths of an orbit), sub-satellite latitude (deg north),
  longitude (deg *west*, 1..360), range (km), orbit number, and ``+`` (sunlit, up, sky dark: Sun at or
  below -12 deg), ``*`` (sunlit otherwise) or a blank (eclipsed); degrees and km are rounded with C's
  ``rint`` (half to even); the time text is the Unix time after PREDICT's round trip through its day
  number (``(time_t)(86400*(t/86400-3651+3651))``), which can be one second earlier;
- ``-f name start [end]``: one line at ``start`` (0 = now) when no end is given and the start lies
  within a year of now; otherwise a line every second (every minute when the end ends in ``m``) from
  start to end; an end ``+N`` counts N steps from the start; a start ``+N[m]`` means now to now + N
  steps, refused (no lines) when over 24 hours;
- ``-p name start``: the pass under way at ``start`` or the next one: from AOS (found by PREDICT's
  iteration), lines while the rounded elevation is at least 0, stepping ``cos(el - 1 deg) *
  sqrt(height km) / 25000`` days, then the LOS line (found by PREDICT's iteration) unless the last line
  was already at 0 deg; nothing for a satellite that never rises here, a geostationary one or a decayed one;
- lines at instants where PREDICT judges the satellite decayed (epoch + (16.666666 - n) / (10 |n'/2|)
  days) are left out.

Our readings: a list longer than 24 hours gives no lines for any end (PREDICT bounds only the ``+``
form); each search gives up (no further lines) after :data:`MAX_CALCULATIONS` positions, where PREDICT
would spin; an instant SGP4 cannot propagate is left out like a decayed one.  Astronomy comes from
:func:`nfwserver.tracking.derived.satellite_report`; the phase is its whole 256ths of the mean anomaly
(PREDICT rounds its own, so they can differ by one).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import datetime, timezone

from nfwserver.tracking.bodies import sun_view
from nfwserver.tracking.constants import WGS84_A_KM  # PREDICT's xkmper (predict.c: 6.378137E3)
from nfwserver.tracking.derived import satellite_report
from nfwserver.tracking.elements import ElementSet
from nfwserver.tracking.look_angles import PropagationError
from nfwserver.tracking.observer import Observer

DAYNUM_OFFSET = 3651.0  #: PREDICT's day 0 is 31Dec79 00:00 UTC: daynum = unix / 86400 - 3651
ONE_YEAR_S = 31557600  #: QuickFind/QuickPredict accept a start within this of now
MAX_SPAN_S = 86400  #: longest list (PREDICT's limit for ``+`` starts; ours for every list)
MAX_CALCULATIONS = 5000  #: positions one listing may compute before giving up
_ATOL = re.compile(r"[ \t\n\v\f\r]*([+-]?\d+)", re.ASCII)
_DAYS = ("Mon", "Tue", "Wed", "Thu", "Fri", "Sat", "Sun")
_MONTHS = ("Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec")


class GiveUp(Exception):
    """A listing ran out of its calculation budget."""


def atol(text: str) -> int:
    """C's ``atol``: optional blanks, sign and digits; 0 when there are none."""
    match = _ATOL.match(text)
    return int(match.group(1)) if match else 0


def daynum_text(daynum: float) -> str:
    """PREDICT's ``Daynum2String``: ``Tue 12Oct99 17:22:37`` for the whole second the day number falls in."""
    t = datetime.fromtimestamp(math.trunc(86400.0 * (daynum + DAYNUM_OFFSET)), tz=timezone.utc)
    return f"{_DAYS[t.weekday()]} {t.day:02d}{_MONTHS[t.month - 1]}{t.year % 100:02d} {t:%H:%M:%S}"


def _ndot_half(elements: ElementSet) -> float:
    """The TLE's first derivative of mean motion / 2 (rev/day^2), PREDICT's ``drag``."""
    try:
        return float(elements.line1[33:43])
    except ValueError:
        return 0.0


def decayed(elements: ElementSet, daynum: float) -> bool:
    """PREDICT's ``Decayed``: epoch + (16.666666 - n) / (10 |drag|) days is before ``daynum``."""
    epoch = elements.epoch.timestamp() / 86400.0 - DAYNUM_OFFSET
    numerator, denominator = 16.666666 - elements.mean_motion_rev_per_day, 10.0 * abs(_ndot_half(elements))
    if denominator == 0.0:  # C: +inf, -inf or nan
        return numerator < 0.0
    return epoch + numerator / denominator < daynum


def aos_happens(elements: ElementSet, observer: Observer) -> bool:
    """PREDICT's ``AosHappens``: the orbit's apogee and inclination can bring it above this latitude's horizon."""
    n = elements.mean_motion_rev_per_day
    if n <= 0.0:
        return False
    inclination = elements.inclination_deg if elements.inclination_deg < 90.0 else 180.0 - elements.inclination_deg
    sma = 331.25 * math.exp(math.log(1440.0 / n) * (2.0 / 3.0))
    apogee = sma * (1.0 + elements.eccentricity) - WGS84_A_KM
    ratio = WGS84_A_KM / (apogee + WGS84_A_KM)
    if not 0.0 < ratio <= 1.0:  # C's acos gives nan: the comparison fails
        return False
    return math.acos(ratio) + math.radians(inclination) > abs(math.radians(observer.latitude_deg))


def geostationary(elements: ElementSet) -> bool:
    """PREDICT's ``Geostationary``: mean motion within 0.0002 rev/day of 1.0027."""
    return abs(elements.mean_motion_rev_per_day - 1.0027) < 0.0002


@dataclass(frozen=True)
class Fix:
    """What PREDICT's ``Calc()`` leaves for one instant, as the listing prints it."""

    elevation_deg: float
    height_km: float
    line_fields: str  #: ``%4d %4d %4d %4d %4d %6ld %6ld %c`` part of the line

    @property
    def rounded_elevation(self) -> int:
        return round(self.elevation_deg)


class Listing:
    """Computes PREDICT's ``-f``/``-p`` lines for one satellite from one observer (see the module docstring)."""

    def __init__(self, elements: ElementSet, observer: Observer, ut1_utc: float = 0.0) -> None:
        self.elements, self.observer, self.ut1_utc = elements, observer, ut1_utc
        self.calculations = 0

    def calc(self, daynum: float) -> Fix:
        """Position at PREDICT day number ``daynum``; PropagationError/ValueError/OverflowError when impossible."""
        self.calculations += 1
        if self.calculations > MAX_CALCULATIONS:
            raise GiveUp(f"more than {MAX_CALCULATIONS} positions")
        when = datetime.fromtimestamp(86400.0 * (daynum + DAYNUM_OFFSET), tz=timezone.utc)
        rep = satellite_report(self.elements, self.observer, when, self.ut1_utc)
        el = rep.elevation_deg
        if not rep.sunlit:
            light = " "
        elif round(el) >= 0:
            dark = rep.visibility == "V" if el >= 0.0 else \
                sun_view(self.observer, when, self.ut1_utc).elevation_deg <= -12.0
            light = "+" if dark else "*"
        else:
            light = "*"
        west = round(360.0 - rep.longitude_deg % 360.0)
        fields = (f"{round(el):4d} {round(rep.azimuth_deg):4d} {rep.phase:4d} {round(rep.latitude_deg):4d} "
                  f"{west:4d} {round(rep.range_km):6d} {rep.rev:6d} {light}")
        return Fix(el, rep.height_km, fields)

    def _line(self, unix_text: str | int, daynum: float, fix: Fix) -> str:
        return f"{unix_text} {daynum_text(daynum)} {fix.line_fields}\n"

    def find(self, now: int, start_text: str, end_text: str) -> Iterator[str]:
        """``predict -f``'s lines (QuickFind)."""
        step = 1
        start = atol(start_text)
        if end_text.endswith("m"):
            step, end_text = 60, end_text[:-1]
        end = start + step * atol(end_text) if end_text.startswith("+") else atol(end_text)
        if start == 0:
            start = now
        if start_text.startswith("+"):
            start = now
            if start_text.endswith("m"):
                step, start_text = 60, start_text[:-1]
            end = start + step * atol(start_text)
            if end - start > MAX_SPAN_S:
                start, end = now, now - 1
        if now - ONE_YEAR_S <= start <= now + ONE_YEAR_S and end == 0:
            instants = [start]
        elif end - start > MAX_SPAN_S:
            instants = []
        else:
            instants = list(range(start, end + 1, step))
        for count in instants:
            daynum = count / 86400.0 - DAYNUM_OFFSET
            if decayed(self.elements, daynum):
                continue
            try:
                fix = self.calc(daynum)
            except GiveUp:
                return
            except (PropagationError, ValueError, OverflowError, OSError):
                continue
            yield self._line(count, daynum, fix)

    def predict(self, now: int, start_text: str) -> Iterator[str]:
        """``predict -p``'s lines (QuickPredict): the pass under way at the start, or the next one."""
        start = atol(start_text) or now
        if not now - ONE_YEAR_S <= start <= now + ONE_YEAR_S:
            return
        daynum = start / 86400.0 - DAYNUM_OFFSET
        if not aos_happens(self.elements, self.observer) or geostationary(self.elements) \
                or decayed(self.elements, daynum):
            return
        try:
            daynum, fix = self._find_aos(daynum)
            last = 0
            while fix.rounded_elevation >= 0:
                yield self._line(math.floor(86400.0 * (DAYNUM_OFFSET + daynum)), daynum, fix)
                last = fix.rounded_elevation
                daynum += math.cos(math.radians(fix.elevation_deg - 1.0)) * math.sqrt(fix.height_km) / 25000.0
                fix = self.calc(daynum)
            if last != 0:
                daynum = self._find_los(daynum)
                fix = self.calc(daynum)
                yield self._line(math.floor(86400.0 * (DAYNUM_OFFSET + daynum)), daynum, fix)
        except (GiveUp, PropagationError, ValueError, OverflowError, OSError):
            return

    def _find_aos(self, daynum: float) -> tuple[float, Fix]:
        """PREDICT's ``FindAOS``: step into range, then home in on elevation 0 (within 0.03 deg)."""
        fix = self.calc(daynum)
        while fix.elevation_deg < -1.0:
            daynum -= 0.00035 * (fix.elevation_deg * ((fix.height_km / 8400.0) + 0.46) - 2.0)
            fix = self.calc(daynum)
        while abs(fix.elevation_deg) >= 0.03:
            daynum -= fix.elevation_deg * math.sqrt(fix.height_km) / 530000.0
            fix = self.calc(daynum)
        return daynum, fix

    def _find_los(self, daynum: float) -> float:
        """PREDICT's ``FindLOS``: home in on elevation 0 (within 0.03 deg) from ``daynum``."""
        fix = self.calc(daynum)
        while True:
            daynum += fix.elevation_deg * math.sqrt(fix.height_km) / 502500.0
            fix = self.calc(daynum)
            if abs(fix.elevation_deg) < 0.03:
                return daynum
