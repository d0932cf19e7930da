"""The KCT driver model's service calls, on a virtual clock with the simulated rotor."""

from __future__ import annotations

from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import ADD_FULL, ADD_INVALID, ADD_OK, KctDriver, TableMode
from nfwserver.rotor.kct_status import KctStatusBit
from nfwserver.rotor.kct_table import NormalEntry, RepetitiveEntry
from nfwserver.rotor.sim_backend import SimulatedRotor

T0 = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)


@pytest.fixture
def rig():
    clock = VirtualClock(T0)
    rotor = SimulatedRotor(clock, RotorGeometry.preset("overlap-450+flip"), az_speed_deg_s=6.0, el_speed_deg_s=3.0)
    driver = KctDriver(clock, rotor, rotor.geometry, table_capacity=5)
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


def test_slew_offsets(rig) -> None:
    _, rotor, driver = rig
    driver.set_target(100, 30)
    assert not driver.write_slew(26, 0) and driver.read_slew() == (0, 0)
    assert driver.write_slew(-5, 10)
    assert rotor.target == (110.0, 25.0)


def test_status_bits_follow_the_rotor(rig) -> None:
    clock, rotor, driver = rig
    driver.set_target(60, 30)
    driver.service()
    status = driver.status()
    assert status.bits & KctStatusBit.AZ_MOVING and status.bits & KctStatusBit.AZ_INCREASING
    assert status.bits & KctStatusBit.EL_MOVING and status.elevation_installed
    clock.advance(20)
    driver.service()
    assert not driver.status().bits & (KctStatusBit.AZ_MOVING | KctStatusBit.EL_MOVING)
    assert driver.status().azimuth_binary == round(60 / 450 * 255)
    driver.enable(False)
    assert driver.status().bits & KctStatusBit.DISABLED
    rotor.card_absent = True
    driver.service()
    assert driver.status().bits & KctStatusBit.CARD_ABSENT
    rotor.card_absent = False
    driver.enable(True)
    driver.service()
    assert not driver.status().bits & KctStatusBit.CARD_ABSENT


def test_table_runs_on_the_clock_and_drops_expired_entries(rig) -> None:
    clock, rotor, driver = rig
    entries = [
        NormalEntry(T0 - timedelta(minutes=5), 5, 10, "OLD"),  # expired long ago
        NormalEntry(T0 + timedelta(seconds=10), 0, 200, "ISS", first_of_pass=True),
        NormalEntry(T0 + timedelta(seconds=20), 20, 210, "ISS"),
        NormalEntry(T0 + timedelta(seconds=30), 0, 220, "ISS", last_of_pass=True),
    ]
    assert [driver.add_entry(e) for e in entries] == [ADD_OK] * 4
    assert driver.add_entry(entries[0].encode()) == ADD_OK
    assert driver.add_entry(entries[1]) == ADD_FULL  # capacity 5
    assert driver.add_entry(RepetitiveEntry(0, 10)) == ADD_INVALID  # wrong mode
    assert driver.add_entry(b"\x00" * 23) == ADD_INVALID
    driver.service()
    assert driver.positions()[2:] == (None, None)  # stale entries dropped, nothing executed
    assert driver.get_table(0, 10).entries() == entries[1:]
    clock.advance(10)
    driver.service()
    assert driver.positions()[2:] == (0.0, 200.0)
    assert [a.kind for a in driver.announcements] == ["AOS"] and driver.table_info() == (TableMode.NORMAL, "ISS")
    clock.advance(20)
    driver.service()
    assert driver.positions()[2:] == (0.0, 220.0)  # the 20 s entry was passed over by the 30 s one
    assert [a.kind for a in driver.announcements] == ["AOS", "LOS"]
    read = driver.get_table(0, 10)
    assert (read.mode, read.count, read.in_force) == (TableMode.NORMAL, 0, None)


def test_processing_off_freezes_the_table(rig) -> None:
    clock, _, driver = rig
    driver.add_entry(NormalEntry(T0 + timedelta(seconds=1), 10, 10, "X"))
    assert driver.set_table_processing(False) is True
    clock.advance(2)
    driver.service()
    assert driver.get_table(0, 5).count == 1
    assert driver.set_table_processing(True) is False


def test_delete_rest_of_pass(rig) -> None:
    _, _, driver = rig
    t = T0 + timedelta(minutes=1)
    pass_a = [NormalEntry(t, 0, 10, "A", first_of_pass=True), NormalEntry(t + timedelta(seconds=5), 5, 20, "A"),
              NormalEntry(t + timedelta(seconds=9), 0, 30, "A", last_of_pass=True)]
    pass_b = [NormalEntry(t + timedelta(minutes=10), 0, 40, "B", first_of_pass=True)]
    for e in pass_a + pass_b:
        driver.add_entry(e)
    driver.delete_rest_of_pass()
    assert driver.get_table(0, 10).entries() == pass_b


def test_repetitive_mode_and_cycle(rig) -> None:
    clock, rotor, driver = rig
    assert not driver.set_table_mode(TableMode.REPETITIVE, 10_081)
    assert driver.set_table_mode(TableMode.REPETITIVE, 60)
    assert driver.add_entry(RepetitiveEntry(0, 90, "east")) == ADD_OK
    assert driver.add_entry(RepetitiveEntry(30, 270, "west")) == ADD_OK
    assert driver.add_entry(NormalEntry(T0, 0, 0, "X")) == ADD_INVALID
    driver.service()
    assert driver.positions()[3] == 90.0
    clock.advance(31 * 60)
    driver.service()
    assert driver.positions()[3] == 270.0 and driver.table_info() == (TableMode.REPETITIVE, (60, 31))
    clock.advance(30 * 60)
    driver.service()
    assert driver.positions()[3] == 90.0


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


def test_announcements_time_and_identifier(rig) -> None:
    clock, _, driver = rig
    heard = []
    driver.annunciator.listeners.append(heard.append)
    driver.announce("hello   world")
    assert heard[0].text == "HELLO WORLD" and heard[0].time == T0
    assert driver.driver_time() == T0
    driver.set_satellite_id("SAUDISAT-1C")
    assert driver.table_info() == (TableMode.NORMAL, "SAUDISAT")


def test_annunciator_popups_and_status_in_morse(rig) -> None:
    _, _, driver = rig
    assert driver.register_popup(0x0001) == (False, 0x0100)
    assert driver.register_popup(0x0001)[0] is True
    assert driver.morse_enabled() and driver.set_morse(False) is True
    driver.announce("not sent")
    assert driver.announcements == []
    driver.set_target(20, 10)
    driver.service()
    text = driver.announce_status()  # sent even with the annunciator disabled
    assert text.startswith("ST ") and "TGT 20 10" in text and driver.announcements[-1].text == text
    assert driver.set_morse(True) is False
