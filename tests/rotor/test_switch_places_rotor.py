"""Every switch of satellite leaves the rotor somewhere sensible (#44 item 3): parked, or pre-positioned at the
new satellite's next AOS, as ``after_los`` says, at once, whoever switched (``SAT=``, another face's selection,
a restart with the satellite below the horizon).

Before: ``TRACK ON``, ``SAT=`` of a satellite that is up, then ``SAT=`` of one below the horizon left the rotor
pointing at the first one (192.9/11.2 in the issue): the switch cleared the pass plan, so the end-of-pass step
never ran.  A simulated rotor on a virtual clock; the AOS oracle is the pass search and look angles of the
tracking engine, computed here independently of the coupling."""

from __future__ import annotations

from datetime import timedelta

from nfwserver.core.publisher import run_virtual
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.tracking.look_angles import LookAngleCalculator
from nfwserver.tracking.passes import find_passes
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER
from tests.rotor.conftest import rotor_station

WHEN = ISS_PASS.tca - timedelta(seconds=60)
PARK = (200, 10)  # azimuth, elevation (deg)


def _a_satellite_below_the_horizon(when) -> int:
    calc = LookAngleCalculator(OBSERVER)
    for sat in CATALOG:
        if sat.catalog_number != ISS and sat.elements.mean_motion_rev_per_day > 11:
            try:
                if calc.compute(sat.satrec, when).elevation_deg < -20.0:
                    return sat.catalog_number
            except Exception:
                continue
    raise AssertionError("no satellite below the horizon")


def _tracking_the_iss(**args):
    station = rotor_station(WHEN, RotorGeometry.preset("overlap-450"), **args)
    clock, server, rotor, driver, coupling, _ = station
    driver.set_parking(0, *PARK)
    run_virtual(server, clock, 3.0)
    assert coupling.plan is not None and rotor.commands and rotor.commands[-1][1] > 10.0  # following the ISS
    return station


def test_sat_of_a_satellite_below_the_horizon_parks_the_rotor_at_once() -> None:
    clock, server, rotor, driver, coupling, _ = _tracking_the_iss()
    assert server.command(f"SAT={_a_satellite_below_the_horizon(clock.now())}").ok
    run_virtual(server, clock, 0.2)
    assert rotor.commands[-1] == (float(PARK[0]), float(PARK[1]))


def test_a_selection_from_another_face_pre_positions_for_the_new_satellites_next_pass() -> None:
    clock, server, rotor, driver, coupling, _ = _tracking_the_iss(after_los="next-aos")
    other = _a_satellite_below_the_horizon(clock.now())
    assert server.select_satellite(other, source="autotrack")  # not a SAT= command: the state changes
    run_virtual(server, clock, 0.2)
    sat = next(s for s in CATALOG if s.catalog_number == other)
    aos = next(p.aos for p in find_passes([sat.satrec], OBSERVER, clock.now(), clock.now() + timedelta(days=1))
               if p.aos is not None)
    az = LookAngleCalculator(OBSERVER).compute(sat.satrec, aos).azimuth_deg
    sent_az, sent_el = rotor.commands[-1]
    assert abs((sent_az - az + 180.0) % 360.0 - 180.0) < 3.0 and abs(sent_el) < 1.0


def test_a_restart_with_the_satellite_below_the_horizon_parks_the_rotor() -> None:
    other = _a_satellite_below_the_horizon(WHEN)
    clock, server, rotor, driver, coupling, _ = rotor_station(WHEN, RotorGeometry.preset("overlap-450"),
                                                              satellite=other)
    driver.set_parking(0, *PARK)
    run_virtual(server, clock, 0.2)  # TRACK ON from the start, the satellite down: the rotor is placed at once
    assert rotor.commands == [(float(PARK[0]), float(PARK[1]))]
