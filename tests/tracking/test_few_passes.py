"""The small pass search (few satellites, pure Python) against skyfield's geometry, with the catalog search's goals.

The oracle is tests/tracking/test_pass_accuracy.py's: skyfield's own SGP4 and frames, crossings and maxima
found by nested dense sampling.  Same tolerances: AOS/LOS within 10 ms, maximum elevation within 0.001 deg,
TCA within 1 s for passes under an hour; and no sign change of skyfield's elevation sampled every 20 s without
an event of ours next to it.
"""

from __future__ import annotations

import math
from datetime import timedelta

import numpy as np
import pytest

from nfwserver.tracking.few_passes import FewPasses, Row, find_few_passes
from nfwserver.tracking.passes import Pass, find_passes
from nfwserver.tracking.timescale import julian_date
from tests.tracking.test_pass_accuracy import BY_NUMBER, DUT1, END, OBSERVER, SETS, START, Oracle, _check_pass

WINDOW_S = (END - START).total_seconds()
#: ISS, AO-10 (a multi-hour HEO pass), and a spread of the catalog's first 2,000 orbits
NUMBERS = [25544, 14129] + [s.catalog_number for s in SETS[:2000:67]]


def _few(numbers: list[int]) -> FewPasses:
    jd, fr = julian_date(START)
    return find_few_passes([BY_NUMBER[n].satrec for n in numbers], numbers, OBSERVER, jd, fr, WINDOW_S, 0.0, DUT1)


def _as_pass(row: Row) -> Pass:
    number, aos, tca, los, max_el, aos_az, los_az = row

    def at(s: float | None) -> object:
        return None if s is None else START + timedelta(seconds=s)

    return Pass(number, at(aos), at(tca), at(los), max_el, aos_az, los_az,  # type: ignore[arg-type]
                aos is None or aos < 0.0, los is None or los > WINDOW_S)


@pytest.fixture(scope="module")
def few() -> FewPasses:
    return _few(NUMBERS)


def test_passes_against_skyfield(few: FewPasses) -> None:
    passes = [_as_pass(row) for row in few.rows]
    assert len(passes) > 100
    assert any(p.duration_s and p.duration_s > 5 * 3600.0 for p in passes)  # AO-10's long pass
    assert any(p.aos_before_start for p in passes)  # a pass in progress at the start, with its true AOS
    for p in passes[::3]:
        _check_pass(p)


def test_grazing_and_near_zenith_passes_against_skyfield() -> None:
    catalog = find_passes(SETS[:2000], OBSERVER, START, END, ut1_utc=DUT1)
    chosen = sorted({p.catalog_number for p in catalog if p.max_elevation_deg < 0.05 or p.max_elevation_deg > 88.0})
    assert len(chosen) >= 8
    passes = [_as_pass(row) for row in _few(chosen[:8]).rows]
    extreme = [p for p in passes if p.max_elevation_deg < 0.05 or p.max_elevation_deg > 88.0]
    assert len(extreme) >= 8
    for p in extreme:
        _check_pass(p)


def test_no_pass_found_by_a_dense_scan_is_missed(few: FewPasses) -> None:
    offsets = np.arange(0.0, WINDOW_S, 20.0)
    checked = 0
    for number in NUMBERS[::2]:
        e = Oracle(number).elevation(START, offsets)
        ours = [s for row in few.rows if row[0] == number for s in (row[1], row[3]) if s is not None]
        for i in np.flatnonzero(np.sign(e[1:]) != np.sign(e[:-1])).tolist():
            assert any(-1.0 <= s - offsets[i] <= 21.0 for s in ours), (number, offsets[i])
            checked += 1
    assert checked > 40


class _DecaysAfter:
    """ISS's model, failing (SGP4 error 6: decayed) from ``after_days`` past ``jd + fr`` on."""

    def __init__(self, satrec: object, jd: float, fr: float, after_days: float) -> None:
        self.satrec, self.limit = satrec, jd + fr + after_days
        self.no_kozai, self.ecco = satrec.no_kozai, satrec.ecco  # type: ignore[attr-defined]

    def sgp4(self, jd: float, fr: float) -> tuple[int, tuple[float, ...], tuple[float, ...]]:
        if jd + fr > self.limit:
            return 6, (math.nan,) * 3, (math.nan,) * 3
        return self.satrec.sgp4(jd, fr)  # type: ignore[attr-defined, no-any-return]


def test_a_model_failing_inside_the_window_is_handed_to_the_catalog_search() -> None:
    """The small search stops (NeedsCatalogSearch) rather than guess; ``passes`` then runs the catalog search,
    which handles SGP4 failing inside a window."""
    from nfwserver.tracking.few_passes import NeedsCatalogSearch

    jd, fr = julian_date(START)
    failing = _DecaysAfter(BY_NUMBER[25544].satrec, jd, fr, 0.5)
    with pytest.raises(NeedsCatalogSearch):
        find_few_passes([failing], [25544], OBSERVER, jd, fr, WINDOW_S)
    unusable = _DecaysAfter(BY_NUMBER[25544].satrec, jd, fr, -1.0)  # fails at the start: left out, as screening does
    assert find_few_passes([unusable], [25544], OBSERVER, jd, fr, WINDOW_S).skipped == [25544]
