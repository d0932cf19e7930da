"""Whole passes followed on the virtual clock: the server's ticks drive the KCT driver and the simulated rotor."""

from __future__ import annotations

import math
from datetime import datetime, timedelta, timezone

import numpy as np

from nfwserver.clock import VirtualClock
from nfwserver.core.publisher import run_virtual
from nfwserver.core.station_core import StationCore
from nfwserver.rotor.coupling import RotorCoupling, angular_distance, sky_from_rotor
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.sim_backend import SimulatedRotor
from nfwserver.rotor.tracks import SatelliteTracks
from nfwserver.tracking.passes import find_passes
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER, state_for

DAY = datetime(2026, 5, 8, tzinfo=timezone.utc)


def _station(start: datetime, geometry: RotorGeometry, satellite: int = ISS, **coupling_args):
    clock = VirtualClock(start)
    server = StationCore(CATALOG, OBSERVER, clock, satellite=satellite, rate_hz=5)
    rotor = SimulatedRotor(clock, geometry, az_speed_deg_s=6.0, el_speed_deg_s=6.0, start=(180.0, 0.0))
    driver = KctDriver(clock, rotor, geometry)
    tracks = SatelliteTracks(server.state)
    coupling = RotorCoupling(driver, tracks.predict, tracks.pass_track,
                             on_position=lambda az, el: server.report_antenna_position(az, el, "rotor"),
                             **coupling_args)
    errors = []

    def follow(sample) -> None:
        coupling.process(sample)
        pos = driver.rotor_position()
        if sample.above_horizon and pos is not None:
            la = sample.look_angles
            errors.append(angular_distance(la.azimuth_deg, la.elevation_deg, *sky_from_rotor(*pos)))

    server.subscribe(follow)
    server.command("TRACK ON")
    return clock, server, rotor, driver, coupling, errors


def test_a_whole_pass_is_followed_within_the_threshold_and_then_parked() -> None:
    geometry = RotorGeometry.preset("overlap-450")
    clock, server, rotor, driver, coupling, errors = _station(ISS_PASS.aos - timedelta(minutes=2), geometry,
                                                             threshold_deg=2.0)
    driver.set_parking(0, 180, 0)
    ticks = run_virtual(server, clock, (ISS_PASS.los - ISS_PASS.aos).total_seconds() + 240)
    settled = np.array(errors[150:])  # after the first 30 s of the pass
    assert np.median(settled) < 3.0 and np.percentile(settled, 90) < 6.0
    assert len(rotor.commands) < ticks / 3  # moves only past the threshold
    assert rotor.target == (180.0, 0.0)  # parked after LOS
    antenna = server.snapshot().state.antenna
    assert antenna.source == "rotor" and antenna.azimuth_deg is not None


def _pass_crossing_north():
    """A pass of a polar satellite whose track crosses north, with some height to it."""
    polar = [s for s in CATALOG if s.elements.inclination_deg > 80 and s.elements.mean_motion_rev_per_day > 13]
    for sat in polar[:10]:
        for p in find_passes([sat], OBSERVER, DAY, DAY + timedelta(days=1)):
            if p.aos is None or p.los is None or p.max_elevation_deg < 20:
                continue
            track = SatelliteTracks(state_for(sat.catalog_number)).pass_track(p.aos)
            azs = [az for _, az, _ in track]
            if any(abs(a - b) > 180 for a, b in zip(azs, azs[1:])):
                return sat.catalog_number, p
    raise AssertionError("no pass crossing north")


def test_a_pass_across_north_is_flipped_on_a_north_stop_rotor_and_never_leaves_its_range() -> None:
    catnr, crossing = _pass_crossing_north()
    geometry = RotorGeometry.preset("north-stop+flip")
    clock, server, rotor, driver, coupling, errors = _station(crossing.aos - timedelta(seconds=30), geometry,
                                                             satellite=catnr, threshold_deg=1.0, after_los="stay")
    flips = []
    server.subscribe(lambda s: flips.append(coupling.flip_state) if coupling.plan else None)
    run_virtual(server, clock, (crossing.los - crossing.aos).total_seconds() + 30)
    assert flips and all(flips)  # flipped from AOS to LOS, never switched mid-pass
    assert all(0 <= az <= 360 and 0 <= el <= 180 for az, el in rotor.commands)
    steps = [abs(b[0] - a[0]) for a, b in zip(rotor.commands, rotor.commands[1:])]
    assert max(steps) < 60  # no swing round the stop
    assert np.median(errors[100:]) < 3.0


def test_next_aos_pre_positioning_and_track_off() -> None:
    geometry = RotorGeometry.preset("overlap-450")
    clock, server, rotor, driver, coupling, _ = _station(ISS_PASS.los - timedelta(seconds=20), geometry,
                                                        after_los="next-aos")
    run_virtual(server, clock, 60)
    nxt = SatelliteTracks(state_for(ISS)).pass_track(ISS_PASS.los + timedelta(minutes=1))
    aos_az = nxt[0][1]
    assert abs(((rotor.target[0] - aos_az) + 180) % 360 - 180) < 1.0 and abs(rotor.target[1]) < 0.01
    before = list(rotor.commands)
    server.command("TRACK OFF")
    run_virtual(server, clock, 10)
    assert rotor.commands == before
    assert math.isfinite(driver.rotor_position()[0])
