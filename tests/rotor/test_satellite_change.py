"""SAT= during a pass: nothing planned for the old satellite survives (pass plan, flip decision, azimuth
branch, last target); the new satellite's pass is planned from its own track."""

from __future__ import annotations

from datetime import timedelta

from nfwserver.core.publisher import run_virtual
from nfwserver.rotor.geometry import RotorGeometry
from nfwserver.tracking.look_angles import LookAngleCalculator
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER
from tests.rotor.conftest import rotor_station


def _another_satellite_up(when) -> int:
    calc = LookAngleCalculator(OBSERVER)
    for sat in CATALOG:
        if sat.catalog_number == ISS:
            continue
        try:
            if calc.compute(sat.satrec, when).elevation_deg > 10.0:
                return sat.catalog_number
        except Exception:
            continue
    raise AssertionError("no other satellite up during the ISS pass")


def test_sat_during_a_pass_plans_the_new_satellites_pass() -> None:
    when = ISS_PASS.tca - timedelta(seconds=60)
    other = _another_satellite_up(when)
    clock, server, rotor, driver, coupling, _ = rotor_station(when, RotorGeometry.preset("north-stop"),
                                                              satellite=other)
    planned_for: list[int | None] = []
    track = coupling.pass_track

    def recording(at):
        planned_for.append(server.state.snapshot().catalog_number)
        return track(at)

    coupling.pass_track = recording
    run_virtual(server, clock, 2)
    assert planned_for == [other] and coupling.plan is not None
    server.command(f"SAT={ISS}")
    run_virtual(server, clock, 0.4)
    assert planned_for[-1] == ISS  # re-planned from the ISS's track, not kept from the other satellite's
    sent = rotor.commands[-1]
    sample = server.tracker.last_sample
    assert sample is not None and sample.catalog_number == ISS
    # The target sent after the change points at the ISS (within the lead and threshold), not the other one.
    assert abs(((sent[0] - sample.look_angles.azimuth_deg) + 180.0) % 360.0 - 180.0) < 15.0
