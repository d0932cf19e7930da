"""Rotor geometry, azimuth mapping and the per-pass flip decision."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.rotor.flip import flip, plan_pass
from nfwserver.rotor.geometry import RotorGeometry, fit_track, unwrap

GEOMETRIES = ["north-stop", "north-stop+flip", "south-stop", "south-stop+flip", "overlap-450", "overlap-450+flip"]


def test_flip_formula() -> None:
    assert flip(10.0, 30.0) == (190.0, 150.0)
    assert flip(350.0, 0.0) == (170.0, 180.0)


def test_pass_across_north_on_a_north_stop_rotor_is_flipped() -> None:
    track = [(300.0 + 10 * k, 10.0 + 4 * k) for k in range(12)]  # 300 .. 50 through north
    assert plan_pass(RotorGeometry.preset("north-stop+flip"), track).flipped
    plan = plan_pass(RotorGeometry.preset("north-stop"), track)
    assert not plan.fits and not plan.flipped
    assert not plan_pass(RotorGeometry.preset("overlap-450"), track).flipped
    assert plan_pass(RotorGeometry.preset("south-stop"), track).offset_deg == -360.0


def test_pass_across_south_on_a_south_stop_rotor_is_flipped() -> None:
    track = [(120.0 + 10 * k, 10.0 + 2 * k) for k in range(12)]  # 120 .. 230 through south
    assert plan_pass(RotorGeometry.preset("south-stop+flip"), track).flipped
    assert not plan_pass(RotorGeometry.preset("north-stop+flip"), track).flipped


@st.composite
def passes(draw):
    start = draw(st.floats(0, 359.9))
    steps = draw(st.lists(st.floats(-20, 20), min_size=2, max_size=40))
    az = [start]
    for s in steps:
        az.append((az[-1] + s) % 360.0)
    peak = draw(st.floats(1, 89))
    n = len(az)
    el = [max(0.0, peak * (1 - abs(2 * k / (n - 1) - 1))) for k in range(n)]
    return list(zip(az, el))


@given(passes(), st.sampled_from(GEOMETRIES))
def test_rotor_positions_stay_in_range_and_never_swing(track, name) -> None:
    geometry = RotorGeometry.preset(name)
    plan = plan_pass(geometry, track)
    previous = None
    for az, el in track:
        rotor_az, rotor_el = plan.rotor_position(geometry, az, el, previous)
        assert geometry.az_min - 1e-6 <= rotor_az <= geometry.az_max + 1e-6
        assert geometry.el_min <= rotor_el <= geometry.el_max
        if previous is not None and plan.fits:
            assert abs(rotor_az - previous) <= 20.0 + 1e-6  # the sky step, never a 340-degree swing
        previous = rotor_az


@given(st.floats(-720, 720), st.sampled_from(GEOMETRIES), st.floats(-180, 540))
def test_nearest_rotor_azimuth_points_the_same_way(az, name, current) -> None:
    geometry = RotorGeometry.preset(name)
    rotor = geometry.nearest_rotor_azimuth(az, current)
    assert geometry.az_min - 1e-6 <= rotor <= geometry.az_max + 1e-6
    assert abs(((rotor - az) + 180) % 360 - 180) < 1e-6


def test_one_to_three_fifty_nine_is_a_two_degree_step() -> None:
    geometry = RotorGeometry.preset("overlap-450")
    assert geometry.nearest_rotor_azimuth(359.0, 361.0) == 359.0
    assert geometry.nearest_rotor_azimuth(1.0, 359.0) == 361.0
    assert unwrap([359.0, 1.0, 3.0]) == [359.0, 361.0, 363.0]
    assert fit_track(RotorGeometry.preset("north-stop"), [359.0, 1.0]) is None


def test_bad_geometries() -> None:
    with pytest.raises(ValueError):
        RotorGeometry(0, 90)
    with pytest.raises(ValueError):
        RotorGeometry.preset("sideways")


def test_forced_flip_modes() -> None:
    track = [(100.0 + 5 * k, 10.0 + 3 * k) for k in range(10)]  # fits any rotor normally
    assert not plan_pass(RotorGeometry.preset("north-stop+flip"), track, mode="auto").flipped
    forced = plan_pass(RotorGeometry.preset("north-stop+flip"), track, mode="on")
    assert forced.flipped and forced.fits
    no_tilt = plan_pass(RotorGeometry.preset("north-stop"), track, mode="on")
    assert no_tilt.flipped and not no_tilt.fits  # inverted targets beyond 90 deg: the driver will ignore them
    across_north = [(300.0 + 10 * k, 10.0 + 4 * k) for k in range(12)]
    assert not plan_pass(RotorGeometry.preset("north-stop+flip"), across_north, mode="off").flipped
    with pytest.raises(ValueError):
        plan_pass(RotorGeometry.preset("north-stop"), track, mode="maybe")
