"""The KCT driver model's service calls, on a virtual clock with the simulated rotor."""

from __future__ import annotations

from datetime import datetime, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.kct_status import KctStatusBit
from nfwserver.rotor.sim_backend import SimulatedRotor

T0 = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)


@pytest.fixture
def rig():
    clock = VirtualClock(T0)
    rotor = SimulatedRotor(clock, RotorGeometry.preset("overlap-450+flip"), az_speed_deg_s=6.0, el_speed_deg_s=3.0)
    driver = KctDriver(clock, rotor, rotor.geometry)
    return clock, rotor, driver


def test_set_target_validates_the_whole_command(rig) -> None:
    clock, rotor, driver = rig
    assert driver.set_target(90, 45)
    assert not driver.set_target(10, 270)  # elevation out of -90..269: ignored
    assert not driver.set_target(360, 10)
    assert driver.positions()[2:] == (45.0, 90.0)
    assert rotor.target == (90.0, 45.0)
    assert driver.set_target(10, 150)  # over the top: allowed by KCT, within this rotor's 0..180
    assert rotor.target == (10.0, 150.0)


def test_status_bits_follow_the_rotor(rig) -> None:
    clock, rotor, driver = rig
    driver.set_target(60, 30)
    driver.service()
    status = driver.status()
    assert status.bits & KctStatusBit.AZ_MOVING and status.bits & KctStatusBit.AZ_INCREASING
    assert status.bits & KctStatusBit.EL_MOVING
    clock.advance(20)
    driver.service()
    assert not driver.status().bits & (KctStatusBit.AZ_MOVING | KctStatusBit.EL_MOVING)
    rotor.card_absent = True
    driver.service()
    assert driver.status().bits & KctStatusBit.CARD_ABSENT
    rotor.card_absent = False
    driver.service()
    assert not driver.status().bits & KctStatusBit.CARD_ABSENT


def test_parking_after_the_delay(rig) -> None:
    clock, rotor, driver = rig
    assert not driver.set_parking(61, 0, 0) and not driver.set_parking(5, 360, 0)
    assert driver.set_parking(2, 180, 10)
    driver.set_target(100, 40)
    driver.start_parking_timer()
    clock.advance(119)
    driver.service()
    assert driver.positions()[2:] == (40.0, 100.0)
    clock.advance(2)
    driver.service()
    assert driver.positions()[2:] == (10.0, 180.0)
    driver.set_target(100, 40)
    driver.start_parking_timer()
    driver.stop_parking_timer()
    clock.advance(300)
    driver.service()
    assert driver.positions()[2:] == (40.0, 100.0)


