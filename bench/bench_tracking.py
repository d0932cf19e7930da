"""Tracking engine speed, side by side with skyfield in the same run.

- look angles of every object in tests/data/active.txt at one instant (numpy path);
- one satellite at one instant (scalar path used on every publish tick);
(pass prediction has its own benchmark, ``bench_passes``).
"""

from __future__ import annotations

import statistics
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
from sgp4.api import SatrecArray

from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.look_angles import LookAngleCalculator, look_angles_array
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.timescale import julian_date

ROOT = Path(__file__).resolve().parent.parent
ACTIVE = ROOT / "tests" / "data" / "active.txt"
WHEN = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)
OBS = Observer(52.2, 0.12, 20.0)


def _median_ms(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times) * 1e3


def main() -> None:
    sets = load_element_file(ACTIVE).sets
    satrecs = [s.satrec for s in sets]
    array = SatrecArray(satrecs)
    jd, fr = julian_date(WHEN)
    jda, fra = np.array([jd]), np.array([fr])
    ours_all = _median_ms(lambda: look_angles_array(array, OBS, jda, fra), 21)
    sgp4_all = _median_ms(lambda: array.sgp4(jda, fra), 21)

    from skyfield.api import EarthSatellite, load, wgs84

    ts = load.timescale(builtin=True)
    t = ts.from_datetime(WHEN)
    topos = wgs84.latlon(52.2, 0.12, elevation_m=20.0)
    sky_sats = [EarthSatellite(s.line1, s.line2, s.name, ts) for s in sets]

    def sky_loop() -> None:
        for sat in sky_sats:
            (sat - topos).at(t).altaz()

    sky_all = _median_ms(sky_loop, 3)

    calc = LookAngleCalculator(OBS)
    iss = next(s for s in sets if s.catalog_number == 25544).satrec
    n = 50_000
    per_call = []
    for _ in range(7):
        t0 = time.perf_counter()
        for _ in range(n):
            calc.compute(iss, WHEN)
        per_call.append((time.perf_counter() - t0) / n * 1e6)
    scalar_us = statistics.median(per_call)
    sky_one = _median_ms(lambda: (sky_sats[0] - topos).at(t).altaz(), 51) * 1e3

    print("## Tracking engine\n")
    print(f"{len(sets):,} objects from tests/data/active.txt; observer 52.2N 0.12E; medians.\n")
    print("| measurement | nfwserver | skyfield | ratio | goal |")
    print("|---|---|---|---|---|")
    print(f"| look angles, all {len(sets):,} objects, one instant | {ours_all:.1f} ms | {sky_all:.0f} ms (loop) "
          f"| {sky_all / ours_all:.0f}x | <= 12 ms |")
    print(f"| of which `SatrecArray.sgp4` alone | {sgp4_all:.1f} ms | | | |")
    print(f"| one satellite, one instant (scalar path) | {scalar_us:.2f} us | {sky_one:.0f} us "
          f"| {sky_one / scalar_us:.0f}x | <= 5 us |")
    print("\nPass prediction: see the section *Pass prediction against skyfield* (`python -m bench passes`).")
    print()


if __name__ == "__main__":
    main()
