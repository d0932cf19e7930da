"""The KCT driver against the KCT and FlipAnts documents' own words (expected values built by hand)."""

from __future__ import annotations

import struct
from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.clock import VirtualClock
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_annunciator import parse_morse_request
from nfwserver.rotor.kct_driver import ADD_OK, KctDriver, TableMode
from nfwserver.rotor.kct_status import KctStatusBit
from nfwserver.rotor.kct_table import NormalEntry, RepetitiveEntry
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


def test_slew_that_carries_the_target_out_of_reach_sends_nothing() -> None:
    # Function 2 "If either value is invalid the entire command will be ignored" -- a slew of -5 is valid,
    # but target el 3 - 5 = -2 is beyond this rotor, so no command goes out; back in reach, it does.
    _, rotor, driver = _rig(RotorGeometry(0.0, 360.0, 0.0, 90.0))
    assert driver.set_target(100, 3)
    assert driver.write_slew(-5, 0)
    assert rotor.commands == [(100.0, 3.0)]
    assert driver.write_slew(-2, 0)
    assert rotor.commands == [(100.0, 3.0), (100.0, 1.0)]
    assert driver.set_target(100, 1) is False  # 1 - 2 = -1: out of reach with this slew


# -- item 10: status bits 20h / 10h -----------------------------------------------------------------

def test_a_reported_stall_sets_the_axis_bit_and_holds_the_axis() -> None:
    # KCT function 0: "20 - =1 if the ELEV rotor is stalled & has been disabled
    #                  10 - =1 if the AZIM rotor is stalled & has been disabled"
    clock, rotor, driver = _rig(RotorGeometry(0.0, 360.0, 0.0, 90.0))
    driver.set_target(90, 20)
    clock.advance(2)
    driver.service()
    rotor.az_stalled = True
    driver.service()
    bits = driver.status().bits
    assert bits & 0x10 and not bits & 0x20
    assert driver.announcements[-1].kind == "alarm" and "azimuth" in driver.announcements[-1].text
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
    driver.enable(True)  # function 9: "The enable function reverses this effect."
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


# -- item 11: function 10h ----------------------------------------------------------------------------

def test_morse_rules_from_function_10h() -> None:
    # "Unrecognised characters will be replaced with a space. Multiple spaces will be replaced with a
    # single space. A 0FFh byte will generate the rising warble used for AOS notification. A 0FEh byte
    # will generate the dropping warble used for LOS notification."  "... with a null (00h) terminator."
    assert parse_morse_request(b"AO-13\x07\x07\x07UP") == [("text", "AO-13 UP")]
    assert parse_morse_request(b"AO 13     UP") == [("text", "AO 13 UP")]
    assert parse_morse_request(b"\xffAO-13\xfe") == [("AOS", ""), ("text", "AO-13"), ("LOS", "")]
    assert parse_morse_request(b"QRT\x00IGNORED") == [("text", "QRT")]
    assert parse_morse_request(b"A#B$C") == [("text", "A B C")]
    assert parse_morse_request("rs0\xff") == [("text", "RS0"), ("AOS", "")]


def test_warbles_are_events_for_listeners() -> None:
    _, _, driver = _rig(RotorGeometry())
    heard = []
    driver.annunciator.listeners.append(heard.append)
    driver.announce(b"\xff")
    driver.announce(b"\xfe")
    assert [(a.kind, a.text) for a in heard] == [("AOS", ""), ("LOS", "")]
    driver.set_morse(False)  # function 11h AL=00: disabled -> nothing is sent
    driver.announce(b"\xff")
    assert len(heard) == 2


# -- item 12: functions 0Dh and 06h ----------------------------------------------------------------

def test_function_0d_counts_the_entries_in_the_table() -> None:
    # "This function returns the number of time-target table entries defined within the driver."
    clock, _, driver = _rig(RotorGeometry(), table_capacity=50)
    assert driver.table_size() == 0
    for k in range(3):
        driver.add_entry(NormalEntry(T0 + timedelta(minutes=1 + k), 10, 10 * k, "RS-10"))
    assert driver.table_size() == 3  # three defined, of 50 places
    clock.advance(61)
    driver.service()  # the first has been executed and left the table
    assert driver.table_size() == 2
    driver.clear_table()
    assert driver.table_size() == 0


def test_function_06_returns_23_byte_images() -> None:
    # "ES:[BX] contains the address of where the data should be placed"; "Table-entry length = 23 bytes";
    # "If the relative table-record number is out of range the returned-entry count in CX will be zero."
    _, _, driver = _rig(RotorGeometry())
    when = datetime(2026, 5, 8, 13, 5, 30, tzinfo=timezone.utc)
    driver.add_entry(NormalEntry(when, 45, 270, "AO-10", 145_810_000, first_of_pass=True))
    driver.add_entry(NormalEntry(when + timedelta(seconds=10), 46, 271, "AO-10"))
    read = driver.get_table(0, 1)
    by_hand = (struct.pack("<H", 2026) + bytes([5, 8, 13 | 0x80, 5, 30]) + struct.pack("<hH", 45, 270)
               + b"AO-10   " + struct.pack("<I", 145_810_000))
    assert read.count == 1 and read.data == by_hand and read.mode is TableMode.NORMAL
    assert read.in_force is None  # DX is defined only "if the driver is in BBSROTOR mode"
    assert driver.get_table(1, 5).count == 1
    assert driver.get_table(2, 5).count == 0 and driver.get_table(2, 5).data == b""


def test_function_06_reports_the_segment_in_force_in_repetitive_mode() -> None:
    # "DX if the driver is in BBSROTOR mode, DX contains the relative table entry# of the Time/Target
    # table currently in force."
    clock, _, driver = _rig(RotorGeometry())
    driver.set_table_mode(TableMode.REPETITIVE, 60)
    for minute, az in ((10, 90), (30, 180), (45, 270)):
        assert driver.add_entry(RepetitiveEntry(minute, az, f"SEG{minute}")) == ADD_OK
    clock.advance(31 * 60)  # minute 31 of the cycle: the segment starting at 30 (record #1)
    read = driver.get_table(0, 10)
    assert read.mode is TableMode.REPETITIVE and read.in_force == 1 and read.count == 3
    assert read.images[2] == b"\xff\xff" + struct.pack("<HH", 45, 270) + b"SEG45     " + bytes(7)
    clock.advance(30 * 60)  # minute 1 of the next cycle: the last segment is still in force
    assert driver.get_table(0, 10).in_force == 2


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
