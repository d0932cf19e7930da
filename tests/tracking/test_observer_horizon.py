"""Observer parsing, Maidenhead locators and horizon tables."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.tracking.horizon import HorizonTable, parse_horizon
from nfwserver.tracking.maidenhead import latlon_to_locator, locator_to_latlon
from nfwserver.tracking.observer import Observer, parse_observer


@pytest.mark.parametrize(
    ("text", "lat", "lon", "alt"),
    [
        ("-33.87,151.21,40", -33.87, 151.21, 40.0),
        ("33.87S,151.21E", -33.87, 151.21, 0.0),
        ("40.0N,110.0W", 40.0, -110.0, 0.0),
        ("40.0N, 110.0W, 1500m", 40.0, -110.0, 1500.0),
        ("52.2 0.12", 52.2, 0.12, 0.0),
    ],
)
def test_coordinates(text: str, lat: float, lon: float, alt: float) -> None:
    assert parse_observer(text) == Observer(lat, lon, alt)


def test_locators() -> None:
    lat, lon = locator_to_latlon("JO01")  # 1 deg x 2 deg square, centre
    assert (lat, lon) == pytest.approx((51.5, 1.0))
    obs = parse_observer("QF56od")
    assert obs.latitude_deg == pytest.approx(-33.8542, abs=1e-3)
    assert obs.longitude_deg == pytest.approx(151.2083, abs=1e-3)
    assert parse_observer("FN31pr21").latitude_deg == pytest.approx(41.7146, abs=1e-3)
    assert latlon_to_locator(-33.87, 151.21, 6) == "QF56od"
    assert latlon_to_locator(41.714775, -72.727260, 8) == "FN31pr21"


@given(st.floats(-89.99, 89.99), st.floats(-179.99, 179.99), st.sampled_from([4, 6, 8]))
def test_locator_round_trip_stays_in_its_box(lat: float, lon: float, precision: int) -> None:
    loc = latlon_to_locator(lat, lon, precision)
    clat, clon = locator_to_latlon(loc)
    size_lat = {4: 1.0, 6: 1 / 24, 8: 1 / 240}[precision]
    assert abs(clat - lat) <= size_lat / 2 + 1e-9
    assert abs(clon - lon) <= size_lat + 1e-9
    assert latlon_to_locator(clat, clon, precision) == loc


@pytest.mark.parametrize(("text", "says"), [
    ("", "neither LAT,LON"), ("abc", "'abc' is neither LAT,LON"), ("91,0", "latitude 91.0 is outside -90..90"),
    ("10,400", "longitude 400.0 is outside"), ("1,2,3,4", "'1,2,3,4' is neither"), ("nan,0", "'nan' is not a finite"),
    ("10X,5E", "latitude '10X' is not a number"), ("ZZ99", "'ZZ99' is neither"), ("10,10,xx", "altitude 'xx'"),
])
def test_bad_observers_say_why(text: str, says: str) -> None:
    # The reason names the value the user typed and what is wrong with it.
    with pytest.raises(ValueError) as info:
        parse_observer(text)
    assert says in str(info.value)


def test_itrs_position_of_a_known_place() -> None:
    x, y, z = Observer(0.0, 0.0, 0.0).itrs_km()
    assert (x, y, z) == pytest.approx((6378.137, 0.0, 0.0))
    x, y, z = Observer(90.0, 0.0, 0.0).itrs_km()
    assert z == pytest.approx(6356.752314, abs=1e-6)


def test_horizon_interpolation_wraps_around_north() -> None:
    table = HorizonTable([(350, 10), (10, 20), (180, 0)])
    assert table.min_elevation(0) == pytest.approx(15.0)
    assert table.min_elevation(355) == pytest.approx(12.5)
    assert table.min_elevation(360) == pytest.approx(15.0)
    assert table.min_elevation(95) == pytest.approx(10.0)
    assert table.minimum == 0.0
    az = np.array([0.0, 355.0, 95.0, -5.0])
    assert table.min_elevation_array(az) == pytest.approx([15.0, 12.5, 10.0, 12.5])
    assert table.slope_array(np.array([0.0]))[0] == pytest.approx(0.5)
    assert not table.is_above(0.0, 14.9) and table.is_above(0.0, 15.1)


def test_empty_and_single_point_tables() -> None:
    assert HorizonTable().min_elevation(123.0) == 0.0
    assert HorizonTable([(40, 7)]).min_elevation(300.0) == 7.0
    assert HorizonTable().is_flat


def test_horizon_file() -> None:
    text = "# my roof\n0 5\n\n90, 10  # trees\n180 2\n270 8\n"
    assert parse_horizon(text).points == [(0.0, 5.0), (90.0, 10.0), (180.0, 2.0), (270.0, 8.0)]
    with pytest.raises(ValueError, match="line 2"):
        parse_horizon("0 5\n90 ninety\n")
    with pytest.raises(ValueError, match="line 1"):
        parse_horizon("0 95\n")
