"""The KCT driver against the KCT and FlipAnts documents' own words (expected values built by hand)."""

from __future__ import annotations

from datetime import datetime, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_annunciator import Announcement
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.kct_status import KctStatusBit
from nfwserver.rotor.rotctld_backend import RotctldBackend
from nfwserver.rotor.sim_backend import SimulatedRotor
from tests.hamlib_daemons import HamlibDaemon

T0 = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)


def _rig(geometry: RotorGeometry, **driver_args):
    clock = VirtualClock(T0)
    rotor = SimulatedRotor(clock, geometry, az_speed_deg_s=6.0, el_speed_deg_s=6.0)
    return clock, rotor, KctDriver(clock, rotor, geometry, **driver_args)


# -- item 9: unreachable targets are ignored, never clamped ------------------------------------------

def test_an_unreachable_elevation_is_ignored_not_clamped() -> None:
    # KCT function 4: "If either value is invalid the entire command will be ignored."
    # FlipAnts caution 2: "Your rotor driver program must ignore any angles that your antennas are not
    # physically capable of. ... Your driver must know not to try to comply."
    _, rotor, driver = _rig(RotorGeometry(0.0, 360.0, 0.0, 90.0))
    assert driver.set_target(100, 30)
    assert rotor.commands == [(100.0, 30.0)]
    assert driver.set_target(280, 150) is False  # over the top: this rotor stops at 90
    assert rotor.commands == [(100.0, 30.0)]  # never (280, 90)
    assert driver.positions()[2:] == (30.0, 100.0)  # the previous target stays in force
    assert driver.set_target(100, -1) is False  # below this rotor's 0 degrees
    assert rotor.commands == [(100.0, 30.0)]


def test_an_azimuth_in_the_rotors_gap_is_ignored() -> None:
    # A rotor turning 0..350: azimuth 355 cannot be reached, so "the entire command will be ignored".
    _, rotor, driver = _rig(RotorGeometry(0.0, 350.0, 0.0, 90.0))
    assert driver.set_target(340, 10)
    assert driver.set_target(355, 10) is False
    assert rotor.commands == [(340.0, 10.0)]


# -- item 10: status bits 20h / 10h -----------------------------------------------------------------

def test_a_reported_stall_sets_the_axis_bit_and_holds_the_axis() -> None:
    # KCT function 0: "20 - =1 if the ELEV rotor is stalled & has been disabled
    #                  10 - =1 if the AZIM rotor is stalled & has been disabled"
    clock, rotor, driver = _rig(RotorGeometry(0.0, 360.0, 0.0, 90.0))
    heard: list[Announcement] = []
    driver.annunciator.listeners.append(heard.append)
    driver.set_target(90, 20)
    clock.advance(2)
    driver.service()
    rotor.az_stalled = True
    driver.service()
    bits = driver.status().bits
    assert bits & 0x10 and not bits & 0x20
    assert heard[-1].kind == "alarm" and "azimuth" in heard[-1].text
    held_az = driver.rotor_position()[0]
    assert held_az == pytest.approx(12.0)  # 2 s at 6 deg/s, then stalled
    driver.set_target(120, 40)  # elevation still moves; the stalled azimuth is held where it is
    assert rotor.commands[-1] == (pytest.approx(held_az), 40.0)
    rotor.el_stalled = True
    driver.service()
    assert driver.status().bits & 0x30 == 0x30
    count = len(rotor.commands)
    driver.set_target(130, 45)
    assert len(rotor.commands) == count  # both axes disabled: nothing is sent
    rotor.az_stalled = rotor.el_stalled = False
    driver.retry_now()  # an operator's action re-arms the stalled axes at once
    assert not driver.status().bits & 0x30
    assert rotor.commands[-1] == (130.0, 45.0)


def test_no_movement_toward_the_target_is_a_stall() -> None:
    # An azimuth motor that turns at 0 deg/s and says nothing: after the stall timeout, bit 10h.
    clock = VirtualClock(T0)
    rotor = SimulatedRotor(clock, RotorGeometry(), az_speed_deg_s=0.0, el_speed_deg_s=6.0)
    driver = KctDriver(clock, rotor, rotor.geometry, stall_timeout_s=10.0)
    driver.set_target(90, 30)
    for _ in range(9):
        clock.advance(1)
        driver.service()
    assert not driver.status().bits & KctStatusBit.AZ_STALLED
    for _ in range(3):
        clock.advance(1)
        driver.service()
    assert driver.status().bits & KctStatusBit.AZ_STALLED
    assert not driver.status().bits & KctStatusBit.EL_STALLED  # elevation reached 30 at 6 deg/s


def test_a_rotor_that_lags_but_keeps_turning_is_not_stalled() -> None:
    clock = VirtualClock(T0)
    rotor = SimulatedRotor(clock, RotorGeometry(0.0, 450.0, 0.0, 90.0), az_speed_deg_s=1.0)
    driver = KctDriver(clock, rotor, rotor.geometry, stall_timeout_s=10.0)
    for k in range(60):  # the target runs away at 2 deg/s, the rotor follows at 1 deg/s
        driver.set_target((20 + 2 * k) % 360, 10)
        clock.advance(1)
        driver.service()
    assert not driver.status().bits & (KctStatusBit.AZ_STALLED | KctStatusBit.EL_STALLED)


@pytest.mark.hamlib
def test_repeated_rotctld_refusals_are_a_stall() -> None:
    # The daemon's limits end at 360 while the configured geometry says 450: every command beyond 360
    # gets RPRT -1 from the real daemon; three in a row mark both axes stalled and disabled.
    geometry = RotorGeometry(0.0, 450.0, 0.0, 90.0)
    with HamlibDaemon("rotctld", extra=["--set-conf=min_az=0,max_az=360,min_el=0,max_el=90"]) as daemon:
        clock = VirtualClock(T0)
        driver = KctDriver(clock, RotctldBackend(clock, geometry, port=daemon.port, timeout_s=1.0), geometry,
                           stall_timeout_s=None)
        driver.set_reference_azimuth(400.0)
        for az in (40, 41):
            assert driver.set_target(az, 10)  # accepted by the driver; refused by the daemon (as 400, 401)
        assert not driver.status().bits & 0x30
        driver.set_target(42, 10)
        assert driver.status().bits & 0x30 == 0x30
        assert not driver.status().bits & KctStatusBit.CARD_ABSENT  # the daemon answers; it refuses


def test_a_rotor_resting_just_short_of_its_target_is_not_stalled() -> None:
    # Real controllers stop a degree or two short; that is arrival, not "stalled & disabled".
    clock = VirtualClock(T0)
    rotor = SimulatedRotor(clock, RotorGeometry(), start=(98.0, 30.0))
    driver = KctDriver(clock, rotor, rotor.geometry, stall_timeout_s=10.0)
    driver.set_target(100, 30)
    rotor.az_speed = 0.0  # it will not move the last 2 degrees
    for _ in range(30):
        clock.advance(1)
        driver.service()
    assert not driver.status().bits & KctStatusBit.AZ_STALLED
