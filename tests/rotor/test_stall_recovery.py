"""A stalled rotor is reported while the stall lasts, held, tried again by itself after a bounded back-off
and at once on an operator's action, and the fault clears as soon as the rotor accepts and moves.

Faults are injected into a simulated rotor on the virtual clock (a jammed or stall-reporting axis) and
into a real rotctld through a loopback proxy that refuses moves (``RPRT -1``), as a controller does.
"""

from __future__ import annotations

import logging
from datetime import timedelta

from nfwserver.app.status_fields import device_status
from nfwserver.core.publisher import run_virtual
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.kct_status import KctStatusBit
from nfwserver.rotor.rotctld_backend import RotctldBackend
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER
from tests.hamlib_daemons import HamlibDaemon
from tests.hamlib_fault_proxy import FaultProxy
from tests.rotor.conftest import rotor_station
from tests.waiting import wait_for

GEOMETRY = RotorGeometry.preset("overlap-450")
STALLED = KctStatusBit.AZ_STALLED | KctStatusBit.EL_STALLED


def _jam(rotor, jammed: bool) -> None:
    rotor.az_speed = rotor.el_speed = 0.0 if jammed else 6.0


def _run_until(server, clock, predicate, limit_s: float) -> float:
    """Tick at 5 Hz until ``predicate()``; returns the virtual seconds it took (inf when it never held)."""
    start = clock.monotonic()
    while clock.monotonic() - start < limit_s:
        if predicate():
            return clock.monotonic() - start
        run_virtual(server, clock, 0.2)
    return float("inf")


def test_a_jammed_rotor_is_held_reported_and_tried_again_by_itself() -> None:
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.aos + timedelta(seconds=60), GEOMETRY)
    status = device_status(coupling, None, None)
    run_virtual(server, clock, 5)
    assert driver.health.ok and status()["rotor"] == "ok"
    _jam(rotor, True)  # iced: commands accepted, nothing turns, nothing reported
    assert _run_until(server, clock, lambda: driver.stalled, 30) <= 16
    assert driver.status().bits & STALLED and not driver.health.ok
    assert status()["rotor"] == "stalled" and "no movement toward the target" in driver.health.describe()
    _jam(rotor, False)  # the ice melts: the cause has ended
    commands = len(rotor.commands)
    run_virtual(server, clock, 4.0)  # inside the 5 s back-off the motor is left alone
    assert driver.stalled and len(rotor.commands) == commands
    took = _run_until(server, clock, lambda: driver.health.ok, 10)
    assert took <= 1.6  # the retry at 5 s, then the first read-back that shows movement
    assert not driver.status().bits & STALLED and status()["rotor"] == "ok"
    assert len(rotor.commands) > commands  # following the satellite again
    assert driver.health.recoveries == 1


def test_a_rotor_jammed_for_good_is_driven_one_stall_timeout_per_back_off_at_most(caplog) -> None:
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.aos + timedelta(seconds=30), GEOMETRY)
    run_virtual(server, clock, 2)
    _jam(rotor, True)
    caplog.set_level(logging.INFO, logger="nfwserver.rotor")
    stalled_ticks = 0
    for _ in range(5 * 600):  # ten minutes jammed (the pass ends on the way: parking is tried too)
        run_virtual(server, clock, 0.2)
        stalled_ticks += not driver.health.ok
    tries = [r for r in caplog.records if "trying the stalled rotor again" in r.getMessage()]
    # Back-off 5, 10, 20, 40, 60, 60 ... s after each stall, each try lasting up to the 15 s stall timeout:
    # about ten tries in ten minutes, not one a tick; the fault is in STATUS nearly all the time.
    assert 6 <= len(tries) <= 12, len(tries)
    assert driver.health.recoveries == 0  # one axis arriving is no recovery while the other is jammed
    assert stalled_ticks >= 0.9 * 5 * (600 - 15)


def test_an_operator_action_tries_a_stalled_rotor_at_once() -> None:
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.aos + timedelta(seconds=60), GEOMETRY)
    run_virtual(server, clock, 3)
    rotor.az_stalled = True  # the controller senses and reports a stall
    assert _run_until(server, clock, lambda: driver.stalled, 2) < 2
    rotor.az_stalled = False
    server.command("TRACK OFF")
    run_virtual(server, clock, 0.4)
    assert driver.stalled  # TRACK OFF is no reason to drive the rotor
    server.command("TRACK ON")  # what the operator does when the rotor seems stuck
    assert _run_until(server, clock, lambda: driver.health.ok, 1.2) <= 1.0  # not the 5 s back-off


def test_a_new_satellite_tries_a_stalled_rotor_at_once() -> None:
    other = next(s.catalog_number for s in CATALOG if s.catalog_number != ISS)
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.aos + timedelta(seconds=60), GEOMETRY)
    run_virtual(server, clock, 3)
    rotor.az_stalled = True
    assert _run_until(server, clock, lambda: driver.stalled, 2) < 2
    rotor.az_stalled = False
    server.command(f"SAT={other}")
    run_virtual(server, clock, 0.2)
    assert not driver.stalled  # re-armed for the new satellite without waiting for the back-off


def test_refusals_from_a_real_rotctld_stall_the_rotor_until_it_accepts_and_moves() -> None:
    from nfwserver.clock import VirtualClock

    with HamlibDaemon("rotctld", extra=["--set-conf=min_az=0,max_az=450,min_el=0,max_el=90"]) as daemon:
        proxy = FaultProxy((daemon.host, daemon.port))
        try:
            clock = VirtualClock(ISS_PASS.aos)
            driver = KctDriver(clock, RotctldBackend(clock, GEOMETRY, port=proxy.port), GEOMETRY)
            assert driver.set_target(40.0, 10.0)
            driver.service()
            proxy.set_mode("refuse")
            for k in range(3):  # three targets in a row, as autotracking sends them, each refused
                assert driver.set_target(80.0 + k, 20.0 + k)
                driver.service()
                clock.advance(0.2)
            assert driver.stalled and "refused" in driver.health.describe()
            proxy.set_mode("pass")  # the controller accepts moves again
            relayed = proxy.set_commands_relayed
            for _ in range(20):  # 4 s: still inside the back-off, nothing is sent
                driver.service()
                clock.advance(0.2)
            assert driver.stalled and proxy.set_commands_relayed == relayed
            clock.advance(1.0)
            # the real rotor turns at 6 deg/s of real time
            wait_for(lambda: driver.service() or driver.health.ok, 5.0, "the rotor link to be well", interval_s=0.05)
            assert not driver.stalled
            assert proxy.set_commands_relayed > relayed
        finally:
            proxy.close()


def test_device_status_names_an_unreachable_rotor(rotctld) -> None:
    # OBSERVER is imported for the station helpers; this checks the daemon-down case of STATUS's rotor field.
    assert OBSERVER is not None
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.aos + timedelta(seconds=60), GEOMETRY)
    status = device_status(coupling, None, None)
    run_virtual(server, clock, 1)
    driver._card_absent = True  # what a RotorUnavailable read sets (function 0's bit 80h)
    assert status()["rotor"] == "unreachable"
