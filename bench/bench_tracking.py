"""Tracking engine speed, side by side with skyfield in the same run.

- look angles of every object in tests/data/active.txt at one instant (numpy path);
- one satellite at one instant (scalar path used on every publish tick);
- passes of 2,000 satellites over 24 h, as whole processes (import + load + compute).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import textwrap
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


def _process_seconds(code: str, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
        times.append(time.perf_counter() - t)
    return statistics.median(times)


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

    subset = ROOT / "bench" / "results"
    subset.mkdir(exist_ok=True)
    two_k = subset / "active-2000.txt"
    two_k.write_text("\n".join(ACTIVE.read_text().splitlines()[: 3 * 2000]) + "\n")
    ours_code = textwrap.dedent(f"""
        from datetime import datetime, timedelta, timezone
        from nfwserver.tracking.elements import load_element_file
        from nfwserver.tracking.observer import Observer
        from nfwserver.tracking.passes import find_passes
        sets = load_element_file({str(two_k)!r}).sets
        start = datetime(2026, 5, 8, tzinfo=timezone.utc)
        print(len(find_passes(sets, Observer(52.2, 0.12, 20.0), start, start + timedelta(hours=24),
                              workers=WORKERS)))
    """)
    sky_code = textwrap.dedent(f"""
        from skyfield.api import load, wgs84
        from skyfield.iokit import parse_tle_file
        ts = load.timescale(builtin=True)
        with open({str(two_k)!r}, 'rb') as f:
            sats = list(parse_tle_file(f, ts))
        topos = wgs84.latlon(52.2, 0.12, elevation_m=20.0)
        a, b = ts.utc(2026, 5, 8), ts.utc(2026, 5, 9)
        print(sum(len(s.find_events(topos, a, b, altitude_degrees=0.0)[1]) for s in sats))
    """)
    ours_passes = _process_seconds(ours_code.replace("WORKERS", "1"))
    ours_passes_2 = _process_seconds(ours_code.replace("WORKERS", "2"))
    sky_passes = _process_seconds(sky_code)

    print("## Tracking engine\n")
    print(f"{len(sets):,} objects from tests/data/active.txt; observer 52.2N 0.12E; medians.\n")
    print("| measurement | nfwserver | skyfield | ratio | goal |")
    print("|---|---|---|---|---|")
    print(f"| look angles, all {len(sets):,} objects, one instant | {ours_all:.1f} ms | {sky_all:.0f} ms (loop) "
          f"| {sky_all / ours_all:.0f}x | <= 12 ms |")
    print(f"| of which `SatrecArray.sgp4` alone | {sgp4_all:.1f} ms | | | |")
    print(f"| one satellite, one instant (scalar path) | {scalar_us:.2f} us | {sky_one:.0f} us "
          f"| {sky_one / scalar_us:.0f}x | <= 5 us |")
    print(f"| passes, 2,000 satellites x 24 h, whole process, one process | {ours_passes:.2f} s | "
          f"{sky_passes:.2f} s (`find_events`) | {sky_passes / ours_passes:.1f}x | >= 5x |")
    print(f"| same, `workers=2` (both cores; `nfwserver passes --workers 2`) | {ours_passes_2:.2f} s | "
          f"{sky_passes:.2f} s | {sky_passes / ours_passes_2:.1f}x | >= 5x |")
    print()


if __name__ == "__main__":
    main()
