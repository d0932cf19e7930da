"""Autotracking against the FlipAnts document: flip forced on/off or auto."""

from __future__ import annotations

from datetime import timedelta

import pytest

from nfwserver.core.publisher import run_virtual
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.rotor.geometry import RotorGeometry
from tests.dde.conftest import ISS_PASS
from tests.rotor.conftest import pass_crossing_north, rotor_station


def _with_events(start, geometry, **kwargs):
    events: list[str] = []
    clock, server, rotor, driver, coupling, _ = rotor_station(start, geometry, on_event=events.append, **kwargs)
    return clock, server, rotor, driver, coupling, events


# -- item 8: flip forced on / off / auto (FlipAnts functions 7F, 7E) ------------------------------------

def test_flip_on_inverts_every_target_even_when_the_pass_fits_normally() -> None:
    # FlipAnts 7F "AL = ... 01 for inverted antenna tracking"; DESIGN: inverted (az, el) -> (az+180 mod 360, 180-el).
    geometry = RotorGeometry.preset("overlap-450+flip")
    clock, server, rotor, driver, coupling, _ = _with_events(ISS_PASS.aos + timedelta(seconds=30), geometry,
                                                             flip_mode="on", after_los="stay")
    sky = []
    server.subscribe(lambda s: sky.append((s.look_angles.azimuth_deg, s.look_angles.elevation_deg)))
    run_virtual(server, clock, 120)
    assert coupling.flip_state and rotor.commands
    assert all(el >= 90.0 for _, el in rotor.commands)
    az, el = rotor.commands[-1]
    sat_az, sat_el = sky[-1]
    # the last command points within the threshold (2 deg) plus lead at the satellite, seen inverted
    assert abs(((az % 360) - (sat_az + 180) % 360 + 180) % 360 - 180) < 8.0 and abs((180 - el) - sat_el) < 8.0


def test_flip_off_never_inverts_even_where_auto_would() -> None:
    catnr, crossing = pass_crossing_north()
    geometry = RotorGeometry.preset("north-stop+flip")
    clock, server, rotor, driver, coupling, _ = _with_events(crossing.aos - timedelta(seconds=30), geometry,
                                                             satellite=catnr, flip_mode="off", after_los="stay")
    run_virtual(server, clock, (crossing.los - crossing.aos).total_seconds() + 30)
    assert not coupling.flip_state
    assert rotor.commands and all(0 <= el <= 90 and 0 <= az <= 360 for az, el in rotor.commands)


def test_flip_on_for_a_rotor_that_cannot_tilt_over_sends_nothing_and_says_why() -> None:
    # FlipAnts caution 1: "Your antennas must be capable of moving 180 degrees in elevation." and 2: the
    # driver "must ignore any angles that your antennas are not physically capable of".
    geometry = RotorGeometry.preset("overlap-450")
    clock, server, rotor, driver, coupling, events = _with_events(ISS_PASS.aos + timedelta(seconds=30), geometry,
                                                                  flip_mode="on", after_los="stay")
    run_virtual(server, clock, 60)
    assert rotor.commands == []
    assert any("ignored, not clamped" in e for e in events)


def test_functions_7f_and_7e_at_run_time() -> None:
    geometry = RotorGeometry.preset("overlap-450+flip")
    clock, server, rotor, driver, coupling, events = _with_events(ISS_PASS.aos + timedelta(seconds=60), geometry,
                                                                  after_los="stay")
    run_virtual(server, clock, 10)
    assert not coupling.flip_state and rotor.commands[-1][1] <= 90  # auto: this pass fits normally
    coupling.set_flip_mode("on")  # FLIP ON
    run_virtual(server, clock, 10)
    assert coupling.flip_state and rotor.commands[-1][1] > 90  # re-planned mid-pass, as asked
    assert coupling.flip_mode == "on"
    coupling.set_flip_mode("off")  # FLIP OFF
    run_virtual(server, clock, 10)
    assert not coupling.flip_state and rotor.commands[-1][1] <= 90
    coupling.set_flip_mode("auto")
    assert "flip mode auto" in events
    with pytest.raises(ValueError):
        coupling.set_flip_mode("sideways")
    with pytest.raises(ValueError):
        RotorCoupling(driver, lambda t: None, lambda t: None, flip_mode="inverted")


def test_driver_alarms_reach_the_console_events() -> None:
    geometry = RotorGeometry.preset("overlap-450")
    clock, server, rotor, driver, coupling, events = _with_events(ISS_PASS.aos + timedelta(seconds=60), geometry)
    rotor.az_stalled = True
    run_virtual(server, clock, 1)
    assert any(e.startswith("ALARM: azimuth rotor stalled") for e in events)
