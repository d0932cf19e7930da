"""Look angles against skyfield (independent frames code), scalar and vectorised paths."""

from __future__ import annotations

from datetime import datetime, timedelta, timezone

import numpy as np
import pytest
from sgp4.api import SatrecArray

from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.look_angles import LookAngleCalculator, PropagationError, look_angles_array
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.timescale import julian_date
from tests.conftest import DATA
from tests.tracking.skyfield_oracle import skyfield_look_angles

START = datetime(2026, 5, 8, 0, 0, 0, 250000, tzinfo=timezone.utc)
TIMES = [START + timedelta(minutes=97 * k) for k in range(15)]  # spans 24 h

OBSERVERS = {
    "north": Observer(52.2053, 0.1218, 20.0),
    "south": Observer(-33.8688, 151.2093, 40.0),
    "polar": Observer(78.2232, 15.6267, 10.0),
    "equatorial-high": Observer(-0.1807, -78.4678, 2850.0),
}


def _pick_satellites():
    sets = load_element_file(DATA / "active.txt").sets
    by_num = {s.catalog_number: s for s in sets}
    chosen = [by_num[n] for n in (25544, 27607, 43017, 57166, 40069, 43013)]  # LEO, amateur, SSO
    sso = [s for s in sets if 97.0 < s.inclination_deg < 99.5 and 14.0 < s.mean_motion_rev_per_day < 15.5]
    molniya = [  # Molniya orbits: 12 h, e ~ 0.7, critical inclination
        s for s in sets
        if 1.9 < s.mean_motion_rev_per_day < 2.1 and 0.6 < s.eccentricity < 0.76 and 60 < s.inclination_deg < 66
    ]
    heo = [s for s in sets if s.eccentricity > 0.8]
    geo = [s for s in sets if abs(s.mean_motion_rev_per_day - 1.0027) < 0.001 and s.eccentricity < 0.001]
    meo = [s for s in sets if 1.9 < s.mean_motion_rev_per_day < 2.1 and s.eccentricity < 0.02]
    chosen += sso[:3] + molniya[:3] + heo[:3] + geo[:3] + meo[:2]
    assert len(chosen) >= 20 and len(heo) >= 1 and len(molniya) >= 1
    return chosen


SATS = _pick_satellites()


@pytest.mark.parametrize("place", sorted(OBSERVERS))
def test_scalar_path_matches_skyfield(place: str) -> None:
    observer = OBSERVERS[place]
    for es in SATS:
        az_ref, el_ref, rng_ref, rr_ref, dut1 = skyfield_look_angles(es, observer, TIMES)
        for k, when in enumerate(TIMES):
            la = LookAngleCalculator(observer, float(dut1[k])).compute(es.satrec, when)
            assert la.elevation_deg == pytest.approx(el_ref[k], abs=1e-6), es.name
            if el_ref[k] < 89.9:
                daz = (la.azimuth_deg - az_ref[k] + 180.0) % 360.0 - 180.0
                assert abs(daz) < 1e-6, es.name
            assert la.range_km == pytest.approx(rng_ref[k], abs=1e-3), es.name
            assert la.range_rate_km_s == pytest.approx(rr_ref[k], abs=1e-6), es.name
            assert 0.0 <= la.azimuth_deg < 360.0


def test_vectorised_path_matches_scalar_path() -> None:
    observer = OBSERVERS["north"]
    jd, fr = zip(*(julian_date(t) for t in TIMES))
    arr = look_angles_array(SatrecArray([s.satrec for s in SATS]), observer, np.array(jd), np.array(fr), 0.1)
    calc = LookAngleCalculator(observer, 0.1)
    assert arr.azimuth_deg.shape == (len(SATS), len(TIMES))
    for i, es in enumerate(SATS):
        for k, when in enumerate(TIMES):
            la = calc.compute(es.satrec, when)
            assert arr.elevation_deg[i, k] == pytest.approx(la.elevation_deg, abs=1e-9)
            assert arr.azimuth_deg[i, k] == pytest.approx(la.azimuth_deg, abs=1e-9)
            assert arr.range_km[i, k] == pytest.approx(la.range_km, abs=1e-9)
            assert arr.range_rate_km_s[i, k] == pytest.approx(la.range_rate_km_s, abs=1e-12)
    assert (arr.error == 0).all()


def test_ut1_offset_moves_the_answer_by_the_documented_amount() -> None:
    iss = SATS[0]
    when = TIMES[3]
    a = LookAngleCalculator(OBSERVERS["north"], 0.0).compute(iss.satrec, when)
    b = LookAngleCalculator(OBSERVERS["north"], 0.9).compute(iss.satrec, when)
    moved = max(abs(a.elevation_deg - b.elevation_deg), abs(a.azimuth_deg - b.azimuth_deg))
    assert 1e-5 < moved < 0.01
    assert abs(a.range_rate_km_s - b.range_rate_km_s) < 1e-3
    with pytest.raises(ValueError):
        LookAngleCalculator(OBSERVERS["north"], 2.0)


def test_propagation_failure_is_reported_not_returned_as_numbers() -> None:
    iss = SATS[0]
    far = datetime(2040, 1, 1, tzinfo=timezone.utc)  # long after reentry in SGP4's model
    with pytest.raises(PropagationError) as info:
        LookAngleCalculator(OBSERVERS["north"]).compute(iss.satrec, far)
    assert info.value.code in (1, 2, 3, 4, 5, 6)
    jd, fr = julian_date(far)
    arr = look_angles_array([iss.satrec], OBSERVERS["north"], np.array([jd]), np.array([fr]))
    assert arr.error[0, 0] != 0 and np.isnan(arr.elevation_deg[0, 0])
