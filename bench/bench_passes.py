"""Pass prediction against skyfield, side by side in one run, as whole processes.

For 500, 2,000 and 8,000 satellites (the first N of tests/data/active.txt) over 24 h from one
observer, each program runs as its own process (interpreter start, imports, element loading and
the search): ``nfwserver.tracking.passes.find_passes`` against skyfield's
``EarthSatellite.find_events`` for every satellite.  The two alternate (ours, skyfield, ours, ...)
so that load from other processes on the machine hits both alike; medians of wall time, and
peak resident memory from ``/usr/bin/time -v`` (``resource`` of the children when it is absent).
Also: command-line start-up (``python -m nfwserver CMD --help`` against a bare interpreter) and
loading the whole catalog in process.

Our modules are byte-compiled first, as ``pip install`` leaves an installed package (skyfield's were
compiled when pip installed it): with ``PYTHONDONTWRITEBYTECODE`` set, as on the project's machines,
a checkout would otherwise be compiled from source again in every process (about 20 ms).
"""

from __future__ import annotations

import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ACTIVE = ROOT / "tests" / "data" / "active.txt"
SIZES = ((500, 3), (2000, 3), (8000, 1))

OURS = """
import sys
from datetime import datetime, timedelta, timezone
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
sets = load_element_file(sys.argv[1]).sets
start = datetime(2026, 5, 8, tzinfo=timezone.utc)
print(len(find_passes(sets, Observer(52.2, 0.12, 20.0), start, start + timedelta(hours=24),
                      workers=int(sys.argv[2]))))
"""
SKYFIELD = """
import sys
from skyfield.api import load, wgs84
from skyfield.iokit import parse_tle_file
ts = load.timescale(builtin=True)
with open(sys.argv[1], 'rb') as f:
    sats = list(parse_tle_file(f, ts))
topos = wgs84.latlon(52.2, 0.12, elevation_m=20.0)
a, b = ts.utc(2026, 5, 8), ts.utc(2026, 5, 9)
print(sum(len(s.find_events(topos, a, b, altitude_degrees=0.0)[1]) for s in sats))
"""


def _run(code: str, *args: str) -> tuple[float, float, str]:
    """Wall seconds, peak RSS (MiB) and stdout of ``python -c code args`` run from the repository root."""
    gnu_time = shutil.which("time") if Path("/usr/bin/time").exists() else None
    with tempfile.NamedTemporaryFile("r", suffix=".txt") as report:
        cmd = [sys.executable, "-c", textwrap.dedent(code), *args]
        if gnu_time:
            cmd = ["/usr/bin/time", "-v", "-o", report.name, *cmd]
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        started = time.perf_counter()
        done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=True)
        wall = time.perf_counter() - started
        peak_kib = float(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
        if gnu_time:
            for line in Path(report.name).read_text().splitlines():
                if "Maximum resident set size" in line:
                    peak_kib = float(line.rsplit(":", 1)[1])
        elif peak_kib <= before:
            peak_kib = float("nan")  # an earlier, larger child hides this one
    return wall, peak_kib / 1024.0, done.stdout.strip()


def _subset(n: int, folder: Path) -> Path:
    path = folder / f"active-{n}.txt"
    path.write_text("\n".join(ACTIVE.read_text().splitlines()[: 3 * n]) + "\n")
    return path


def _startup() -> list[tuple[str, float]]:
    rows = []
    for label, cmd in (("bare interpreter (`python -c pass`)", ["-c", "pass"]),
                       ("`python -m nfwserver --help`", ["-m", "nfwserver", "--help"]),
                       ("`python -m nfwserver passes --help`", ["-m", "nfwserver", "passes", "--help"]),
                       ("`python -m nfwserver config path`", ["-m", "nfwserver", "config", "path"])):
        times = []
        for _ in range(7):
            started = time.perf_counter()
            subprocess.run([sys.executable, *cmd], cwd=ROOT, capture_output=True, check=True)
            times.append(time.perf_counter() - started)
        rows.append((label, statistics.median(times)))
    return rows


def _catalog_load_s() -> float:
    from nfwserver.tracking.elements import load_element_file

    times = []
    for _ in range(5):
        started = time.perf_counter()
        load_element_file(ACTIVE)
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def main() -> None:
    folder = ROOT / "bench" / "results"
    folder.mkdir(exist_ok=True)
    subprocess.run([sys.executable, "-m", "compileall", "-q", "nfwserver"], cwd=ROOT, check=True)
    rows = []
    for n, repeat in SIZES:
        path = _subset(n, folder)
        ours, sky = [], []
        for _ in range(repeat):
            ours.append(_run(OURS, str(path), "1"))
            sky.append(_run(SKYFIELD, str(path)))
        two = [_run(OURS, str(path), "2") for _ in range(repeat)] if n == 2000 else []
        rows.append((n, ours, sky, two))
        print(f"  {n}: ours {statistics.median(r[0] for r in ours):.2f} s, "
              f"skyfield {statistics.median(r[0] for r in sky):.2f} s", file=sys.stderr)
    startup = _startup()
    load_s = _catalog_load_s()
    load_avg = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")

    print("## Pass prediction against skyfield\n")
    print("Whole processes (interpreter, imports, loading the elements, the search), the first N objects of "
          "tests/data/active.txt, 24 h from 52.2N 0.12E, flat horizon; nfwserver and skyfield `find_events` "
          f"alternate in one run; median wall time, peak RSS from `/usr/bin/time -v`; both run from bytecode "
          f"(ours compiled first, as `pip install` leaves it). Both print only the number "
          f"of events found: `find_passes` returns a `PassList` (columns; a `Pass` record is built when one is "
          f"read), skyfield arrays per satellite. Load average at the end: {load_avg:.1f} on {os.cpu_count()} "
          f"cores.\n")
    print("| satellites | nfwserver, one process | skyfield | ratio | peak RSS nfwserver / skyfield | "
          "passes / skyfield events |")
    print("|---|---|---|---|---|---|")
    for n, ours, sky, two in rows:
        o = statistics.median(r[0] for r in ours)
        s = statistics.median(r[0] for r in sky)
        print(f"| {n:,} | {o:.2f} s | {s:.2f} s | **{s / o:.1f}x** | {max(r[1] for r in ours):.0f} / "
              f"{max(r[1] for r in sky):.0f} MiB | {ours[0][2]} / {sky[0][2]} |")
        if two:
            t = statistics.median(r[0] for r in two)
            print(f"| {n:,}, `--workers 2` | {t:.2f} s | {s:.2f} s | {s / t:.1f}x | "
                  f"{max(r[1] for r in two):.0f} MiB (parent) | |")
    print("\nGoals (issue 17): >= 10x at 2,000 and 8,000 in one process; peak memory no higher than skyfield's. "
          "Accuracy is a test, not a benchmark: tests/tracking/test_pass_accuracy.py checks AOS/LOS to 10 ms and "
          "maximum elevations to 0.001 deg against skyfield's geometry sampled densely.\n")
    print("| start-up | median of 7 |")
    print("|---|---|")
    for label, seconds in startup:
        print(f"| {label} | {seconds * 1e3:.0f} ms |")
    print(f"| loading all {len(ACTIVE.read_text().splitlines()) // 3:,} element sets in process | "
          f"{load_s * 1e3:.0f} ms |")
    print()


if __name__ == "__main__":
    main()
