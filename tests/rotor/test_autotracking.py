"""Whole passes followed on the virtual clock: the server's ticks drive the KCT driver and the simulated rotor."""

from __future__ import annotations

import math
from datetime import datetime, timedelta, timezone

import numpy as np

from nfwserver.core.publisher import run_virtual
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.tracks import SatelliteTracks
from tests.dde.conftest import ISS, ISS_PASS, state_for
from tests.rotor.conftest import pass_crossing_north, rotor_station

DAY = datetime(2026, 5, 8, tzinfo=timezone.utc)


def test_a_whole_pass_is_followed_within_the_threshold_and_then_parked() -> None:
    geometry = RotorGeometry.preset("overlap-450")
    clock, server, rotor, driver, coupling, errors = rotor_station(ISS_PASS.aos - timedelta(minutes=2), geometry,
                                                             threshold_deg=2.0)
    driver.set_parking(0, 180, 0)
    ticks = run_virtual(server, clock, (ISS_PASS.los - ISS_PASS.aos).total_seconds() + 240)
    settled = np.array(errors[150:])  # after the first 30 s of the pass
    assert np.median(settled) < 3.0 and np.percentile(settled, 90) < 6.0
    assert len(rotor.commands) < ticks / 3  # moves only past the threshold
    assert rotor.target == (180.0, 0.0)  # parked after LOS
    antenna = server.snapshot().state.antenna
    assert antenna.source == "rotor" and antenna.azimuth_deg is not None


def test_a_pass_across_north_is_flipped_on_a_north_stop_rotor_and_never_leaves_its_range() -> None:
    catnr, crossing = pass_crossing_north()
    geometry = RotorGeometry.preset("north-stop+flip")
    clock, server, rotor, driver, coupling, errors = rotor_station(crossing.aos - timedelta(seconds=30), geometry,
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
    clock, server, rotor, driver, coupling, _ = rotor_station(ISS_PASS.los - timedelta(seconds=20), geometry,
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
