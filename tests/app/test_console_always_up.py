"""The console's next-pass line for a satellite above the horizon all day (issue 34, item 7): it said
"Next pass: none in the next 24 h" while METEOSAT-10 stood 35 deg up."""

from __future__ import annotations

from datetime import timedelta

from skyfield.api import EarthSatellite, load, wgs84

from nfwserver.console.pass_view import next_pass_text, search_passes
from nfwserver.console.time_display import TimeDisplay
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.horizon import HorizonTable
from tests.conftest import DATA
from tests.dde.conftest import DAY, OBSERVER

METEOSAT_10 = 38552


def test_next_pass_says_up_for_the_whole_window() -> None:
    meteosat = next(s for s in load_element_file(DATA / "active.txt").sets if s.catalog_number == METEOSAT_10)
    catalog = Catalog([*load_element_file(DATA / "visual.txt").sets, meteosat])
    now = DAY + timedelta(hours=3)
    # skyfield: above the horizon at every 10 minutes of the next day, 20-60 deg up
    ts = load.timescale(builtin=True)
    times = ts.from_datetimes([now + timedelta(minutes=10 * k) for k in range(145)])
    topos = wgs84.latlon(OBSERVER.latitude_deg, OBSERVER.longitude_deg, elevation_m=OBSERVER.altitude_m)
    elevations = (EarthSatellite(meteosat.line1, meteosat.line2, ts=ts) - topos).at(times).altaz()[0].degrees
    assert (elevations > 20.0).all() and (elevations < 60.0).all()
    search = search_passes(catalog, OBSERVER, HorizonTable(), 0.0, [25544], METEOSAT_10, now)
    p = search.next_pass
    assert p is not None and p.aos is None and p.los is None
    assert abs(p.max_elevation_deg - elevations[:73].max()) < 0.5  # the highest of the 12 h searched
    text = next_pass_text(search, TimeDisplay(), now)
    assert text == f"Up for the whole window: max {p.max_elevation_deg:.0f} deg at {p.tca:%H:%M:%S} UTC"
