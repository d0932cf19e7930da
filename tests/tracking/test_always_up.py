"""Satellites above the horizon for the whole window (issue 34, item 7): one pass each, with neither AOS nor LOS.

Checked against skyfield's geometry (tests/tracking/test_pass_accuracy.py's oracle): the satellite is above
the horizon at every 20 s sample of the window, and the pass's maximum elevation is skyfield's highest
elevation in the window (nested dense sampling) within 0.001 deg.  Both searches (the catalog's, numpy; the
small one, pure Python) give the same pass.
"""

from __future__ import annotations

import re
from datetime import timedelta

import numpy as np
import pytest

from nfwserver.tracking.few_passes import find_few_passes
from nfwserver.tracking.passes import find_passes
from nfwserver.tracking.timescale import julian_date
from tests.tracking.test_pass_accuracy import BY_NUMBER, DUT1, END, MAX_EL_TOL_DEG, OBSERVER, SETS, START, Oracle

METEOSAT_10 = 38552
WINDOW_S = (END - START).total_seconds()


def _geostationary_in_view() -> list[int]:
    """Near-geostationary sets (about one revolution a day, near-circular) above the horizon all day, by skyfield."""
    numbers = [METEOSAT_10] + [s.catalog_number for s in SETS if abs(s.mean_motion_rev_per_day - 1.0027) < 0.002
                               and s.eccentricity < 0.001][:40]
    offsets = np.arange(-86400.0, WINDOW_S + 86400.0, 600.0)
    return [n for n in numbers if (Oracle(n).elevation(START, offsets) > 0.5).all()][:6]


@pytest.fixture(scope="module")
def geostationary() -> list[int]:
    numbers = _geostationary_in_view()
    assert METEOSAT_10 in numbers and len(numbers) >= 4
    return numbers


def test_the_catalog_search_gives_each_one_pass_without_aos_or_los(geostationary: list[int]) -> None:
    passes = find_passes([BY_NUMBER[n] for n in geostationary] + [BY_NUMBER[25544]], OBSERVER, START, END,
                         ut1_utc=DUT1)
    up = [p for p in passes if p.catalog_number in geostationary]
    assert sorted(p.catalog_number for p in up) == sorted(geostationary)
    assert len([p for p in passes if p.catalog_number == 25544]) >= 4  # other satellites' passes as before
    offsets = np.arange(0.0, WINDOW_S + 1.0, 20.0)
    for p in up:
        assert p.aos is None and p.los is None and p.aos_before_start and p.los_after_end
        assert p.aos_azimuth_deg is None and p.los_azimuth_deg is None and p.duration_s is None
        oracle = Oracle(p.catalog_number)
        assert (oracle.elevation(START, offsets) > 0.0).all()
        true_tca, true_max = oracle.maximum(START, END)
        assert abs(p.max_elevation_deg - true_max) < MAX_EL_TOL_DEG, (p, true_max, true_tca)
        assert START <= p.tca <= END
        assert abs(oracle.elevation(p.tca, np.zeros(1))[0] - p.max_elevation_deg) < 1e-5


def test_the_small_search_gives_the_same_pass(geostationary: list[int]) -> None:
    jd, fr = julian_date(START)
    rows = find_few_passes([BY_NUMBER[n].satrec for n in geostationary], geostationary, OBSERVER, jd, fr, WINDOW_S,
                           0.0, DUT1).rows
    catalog = {p.catalog_number: p for p in find_passes([BY_NUMBER[n] for n in geostationary], OBSERVER, START, END,
                                                        ut1_utc=DUT1)}
    assert sorted(row[0] for row in rows) == sorted(geostationary)
    for number, aos, tca, los, max_el, aos_az, los_az in rows:
        assert aos is None and los is None and aos_az is None and los_az is None
        assert abs(max_el - catalog[number].max_elevation_deg) < 1e-6
        assert abs(START + timedelta(seconds=tca) - catalog[number].tca) < timedelta(seconds=1)


@pytest.mark.parametrize("options", [[], ["--wide"], ["--format", "csv"], ["--format", "json"], ["--all"]])
def test_passes_lists_it_and_says_it_is_up_for_the_whole_window(capsys, tmp_path, options) -> None:
    """`passes --sat` of METEOSAT-10 said "no passes" while it stood 35 deg up all day (40.4N 3.7W)."""
    from nfwserver.cli import main

    path = tmp_path / "two.txt"
    path.write_text(BY_NUMBER[METEOSAT_10].tle_text() + BY_NUMBER[25544].tle_text())
    chosen = [] if "--all" in options else ["--sat", str(METEOSAT_10)]
    assert main(["passes", "--elements", str(path), *chosen, "--observer", "40.4N,3.7W", "--start",
                 "2026-05-08T00:00Z", *options]) == 0
    out, err = capsys.readouterr()
    assert "up for the whole window" in err and ("METEOSAT-10 (MSG-3)" in err or "MSG-3" in err)
    assert "no passes" not in err
    row = next(line for line in out.splitlines() if str(METEOSAT_10) in line)
    if "--format" in options and "json" in options:
        assert '"aos_utc": null' in row and '"los_utc": null' in row and '"in_progress": true' in row
    elif "--format" in options:
        assert row.split(",")[2] == row.split(",")[4] == "" and row.endswith(",Y")
    elif "--wide" in options:  # the TCA is the row's one time; max elevation, in progress
        assert len(re.findall(r"2026-05-0\dT", row)) == 1 and re.search(r" \d\d\.\d +Y$", row)
    else:  # no AOS (no date), the TCA's time, no LOS, the maximum, no azimuths or length
        assert re.fullmatch(r"38552 +MSG-3 +\d\d:\d\d:\d\d +\d\d\.\d", row), row
