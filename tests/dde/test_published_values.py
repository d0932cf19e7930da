"""Every published value checked against skyfield at the string's timestamp, AH against the horizon."""

from __future__ import annotations

from datetime import timedelta

import numpy as np

from nfwserver.core.sample import TickSample
from nfwserver.tracking.horizon import HorizonTable
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, NOVA, OBSERVER, make_station
from tests.tracking.skyfield_oracle import skyfield_look_angles

HORIZON = HorizonTable([(0, 10), (90, 25), (180, 5), (270, 15)])


def test_a_whole_pass_matches_skyfield_rounded_as_printed() -> None:
    start = ISS_PASS.aos - timedelta(seconds=30)
    dut1 = float(skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, [start])[4][0])
    station = make_station(start=start, horizon=HORIZON, ut1_utc=dut1)
    conv = station.system.connect("NFW32", "NFW_DATA")
    conv.start_advise("NFW_SERVER")
    conv.poke("NFW_SERVER", "TUNE ON")
    stamped: list[tuple[object, str]] = []
    samples: list[TickSample] = []
    station.core.subscribe(samples.append)
    conv.on_receive = lambda r: stamped.append((station.clock.now(), r.text))
    duration = (ISS_PASS.los - start).total_seconds() + 30
    station.run(duration)
    assert len(stamped) == int(duration * 5) + 1
    times = [t for t, _ in stamped]
    az, el, _, rr, dut1_all = skyfield_look_angles(CATALOG.get(ISS).elements, OBSERVER, times)
    assert np.ptp(dut1_all) < 1e-4  # UT1-UTC barely moves during one pass
    up_seen = {"Y": 0, "N": 0}
    for k, (_, text) in enumerate(stamped):
        m = NOVA.match(text)
        assert m and m.group(1) == "ISS"
        daz = (float(m.group(2)) - az[k] + 180.0) % 360.0 - 180.0
        assert abs(daz) <= 0.05 + 1e-3
        assert abs(float(m.group(3)) - el[k]) <= 0.05 + 1e-3
        assert abs(float(m.group(4)) - rr[k]) <= 5e-11 + 1e-6  # printed to 1e-10 km/s; oracle within 1 mm/s
        limit = HORIZON.min_elevation(az[k])
        if abs(el[k] - limit) > 1e-3:
            assert m.group(5) == ("Y" if el[k] > limit else "N"), (text, el[k], limit)
        up_seen[m.group(5)] += 1
    assert up_seen["Y"] > 100 and up_seen["N"] > 100
    assert [s.above_horizon for s in samples] == [t.endswith("AH:Y") for _, t in stamped]
