"""Shared rotor-test helpers: a station core with a simulated rotor, and a pass that crosses north."""

from __future__ import annotations

from datetime import datetime, timedelta, timezone

from nfwserver.clock import VirtualClock
from nfwserver.core.station_core import StationCore
from nfwserver.rotor.coupling import RotorCoupling, angular_distance, sky_from_rotor
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.rotor.kct_driver import KctDriver
from nfwserver.rotor.sim_backend import SimulatedRotor
from nfwserver.rotor.tracks import SatelliteTracks
from nfwserver.tracking.passes import find_passes
from tests.dde.conftest import CATALOG, ISS, OBSERVER, state_for

DAY = datetime(2026, 5, 8, tzinfo=timezone.utc)


def rotor_station(start: datetime, geometry: RotorGeometry, satellite: int = ISS, **coupling_args):
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


def pass_crossing_north():
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
