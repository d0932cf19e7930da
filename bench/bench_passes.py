"""Pass prediction as a user runs it: the ``nfwserver passes`` command against skyfield writing the same rows.

Each run is a whole process writing every pass to a file: ``python -m nfwserver passes --elements FILE
--observer 52.2,0.12,20 --start 2026-05-08T00:00:00Z --hours 24 --format F`` (run from the checkout, as
the installed console script runs it) against ``python -m bench.skyfield_passes`` (bench/skyfield_passes.py:
``find_events`` for every satellite, the angles at the events, the same columns and formats).  FILE is the
first N objects of tests/data/active.txt (the catalog of /work/shared/data/active.txt).  The two programs
alternate (ours, skyfield, ours, ...) so that load from other processes hits both alike; medians of the
wall time, and each run's peak resident memory from the OS (``wait4``'s rusage of that child).  Also: the
whole catalog with one and two worker processes, start-up of whole processes, and, for context, skyfield
finding only the events (printing their count, as this benchmark did before).

Our modules are byte-compiled first, as ``pip install`` leaves an installed package (skyfield's were
compiled when pip installed it): with ``PYTHONDONTWRITEBYTECODE`` set, as on the project's machines, a
checkout would otherwise be compiled from source again in every process (about 20 ms).
"""

from __future__ import annotations

import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ACTIVE = ROOT / "tests" / "data" / "active.txt"
FORMATS = ("table", "csv", "json")
REPEAT = int(os.environ.get("NFW_BENCH_REPEAT", "3"))
WHERE, START, HOURS = "52.2,0.12,20", "2026-05-08T00:00:00Z", "24"
EVENTS_ONLY = """
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


def _run(cmd: list[str]) -> tuple[float, float, int]:
    """Wall seconds, peak RSS (MiB) and lines written of one process (stdout to a file), run from the root."""
    with tempfile.TemporaryFile() as out:
        started = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=out, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - started
        proc.returncode = os.waitstatus_to_exitcode(status)
        error = proc.stderr.read().decode() if proc.stderr else ""
        if proc.returncode:
            raise RuntimeError(f"{cmd} failed ({proc.returncode}): {error}")
        out.seek(0)
        lines = sum(chunk.count(b"\n") for chunk in iter(lambda: out.read(1 << 20), b""))
    return wall, usage.ru_maxrss / 1024.0, lines


def _ours(path: Path, fmt: str, workers: int = 1) -> list[str]:
    return [sys.executable, "-m", "nfwserver", "passes", "--elements", str(path), "--observer", WHERE, "--start",
            START, "--hours", HOURS, "--format", fmt, "--workers", str(workers),
            *(["--wide"] if fmt == "table" else [])]  # the table with every column, as skyfield's rows have


def _skyfield(path: Path, fmt: str) -> list[str]:
    return [sys.executable, "-m", "bench.skyfield_passes", str(path), WHERE, START, HOURS, fmt]


def _subset(n: int, folder: Path) -> Path:
    path = folder / f"active-{n}.txt"
    path.write_text("\n".join(ACTIVE.read_text().splitlines()[: 3 * n]) + "\n")
    return path


def _median(runs: list[tuple[float, float, int]], fmt: str = "csv") -> tuple[float, float, int]:
    """Median wall time, largest peak RSS, and the passes written in the first run (lines less the header, or
    less the opening and closing lines of JSON)."""
    return (statistics.median(r[0] for r in runs), max(r[1] for r in runs),
            runs[0][2] - (2 if fmt == "json" else 1))


def _startup() -> list[tuple[str, float]]:
    """Median wall time of short whole processes: the interpreter's floor, numpy's, and commands that must start
    at once.  (No peak RSS here: a child's ``wait4`` maximum includes the pages it shared with this process
    before its ``exec``, about 22 MiB, more than these processes use.)"""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        closed = str(s.getsockname()[1])
    rows = []
    for label, cmd in (("bare interpreter (`python -c pass`)", ["-c", "pass"]),
                       ("interpreter and numpy (`python -c 'import numpy'`)", ["-c", "import numpy"]),
                       ("`nfwserver --version`", ["-m", "nfwserver", "--version"]),
                       ("`nfwserver status` (no station: refused at once)",
                        ["-m", "nfwserver", "status", "--port", closed]),
                       ("`nfwserver passes --help`", ["-m", "nfwserver", "passes", "--help"]),
                       ("`nfwserver config path`", ["-m", "nfwserver", "config", "path"])):
        times = []
        for _ in range(7):
            started = time.perf_counter()
            subprocess.run([sys.executable, *cmd], cwd=ROOT, capture_output=True)
            times.append(time.perf_counter() - started)
        rows.append((label, statistics.median(times)))
    return rows


def main() -> None:
    folder = ROOT / "bench" / "results"
    folder.mkdir(exist_ok=True)
    subprocess.run([sys.executable, "-m", "compileall", "-q", "nfwserver", "bench"], cwd=ROOT, check=True)
    load_before = os.getloadavg()[0]
    two_k = _subset(2000, folder)
    vs: dict[str, tuple] = {}
    for fmt in FORMATS:
        ours, sky = [], []
        for _ in range(REPEAT):
            ours.append(_run(_ours(two_k, fmt)))
            sky.append(_run(_skyfield(two_k, fmt)))
        vs[fmt] = (_median(ours, fmt), _median(sky, fmt))
        print(f"  2,000 {fmt}: ours {vs[fmt][0][0]:.2f} s, skyfield {vs[fmt][1][0]:.2f} s", file=sys.stderr)
    events = _median([_run([sys.executable, "-c", EVENTS_ONLY, str(two_k)]) for _ in range(REPEAT)])
    whole: dict[str, tuple] = {}
    for fmt in FORMATS:
        whole[fmt] = _median([_run(_ours(ACTIVE, fmt)) for _ in range(REPEAT)], fmt)
        print(f"  whole catalog {fmt}: {whole[fmt][0]:.2f} s, {whole[fmt][1]:.0f} MiB", file=sys.stderr)
    two_workers = _median([_run(_ours(ACTIVE, "csv", workers=2)) for _ in range(REPEAT)])
    startup = _startup()
    load_after = os.getloadavg()[0]
    n_all = len(ACTIVE.read_text().splitlines()) // 3

    print("## Pass prediction against skyfield\n")
    print("The command a user runs, as whole processes writing every pass to a file: `nfwserver passes "
          f"--elements FILE --observer {WHERE} --start {START} --hours {HOURS} --format F` (`python -m nfwserver` "
          "from the checkout, byte-compiled as `pip install` leaves it) against bench/skyfield_passes.py, which "
          "finds the same passes with skyfield's `find_events` (0 deg) and writes the same rows (for the table, "
          "`--wide`: the default 80-column table leaves columns out, so it would be less work). Both print the "
          "header and one row per pass with the columns catalog_number, name, aos_utc, tca_utc, los_utc, "
          "max_elevation_deg, aos_azimuth_deg, los_azimuth_deg, duration_s, in_progress: times ISO-8601 UTC "
          "with milliseconds and Z, numbers with 1 decimal in the table (duration 0) and 6 in CSV and JSON, "
          "JSON as an array of objects (null for an unknown time or angle). Skyfield needs a second "
          "propagation (`(sat - topos).at(t).altaz()`, one call per satellite) for the elevations and azimuths "
          "at its events. What each finds differs at the window's edges only: nfwserver reports the true AOS "
          "and LOS of passes cut by the window (outside it), skyfield leaves them empty. FILE is the first "
          "2,000 objects of tests/data/active.txt (or all of them); the two programs alternate in one run; "
          f"median of {REPEAT} wall times, peak RSS the largest of each run's `wait4` maximum resident set. "
          f"Load average (1 min) {load_before:.1f} at the start, {load_after:.1f} at the end, "
          f"{os.cpu_count()} cores.\n")
    print("| 2,000 satellites x 24 h | nfwserver | skyfield | ratio | peak RSS nfwserver / skyfield | rows "
          "nfwserver / skyfield |")
    print("|---|---|---|---|---|---|")
    for fmt in FORMATS:
        (o, o_rss, o_rows), (s, s_rss, s_rows) = vs[fmt]
        print(f"| `--format {fmt}` | {o:.2f} s | {s:.2f} s | **{s / o:.1f}x** | {o_rss:.0f} / {s_rss:.0f} MiB | "
              f"{o_rows:,} / {s_rows:,} |")
    csv_ours = vs["csv"][0][0]
    print(f"| skyfield finding the events only (their count printed, no angles, no rows) | {csv_ours:.2f} s "
          f"(CSV) | {events[0]:.2f} s | {events[0] / csv_ours:.1f}x | {vs['csv'][0][1]:.0f} / {events[1]:.0f} MiB "
          "| |")
    print(f"\n| whole catalog ({n_all:,} objects) x 24 h | wall | peak RSS | rows |")
    print("|---|---|---|---|")
    for fmt in FORMATS:
        w, rss, rows = whole[fmt]
        print(f"| `--format {fmt}` | **{w:.2f} s** | {rss:.0f} MiB | {rows:,} |")
    w, rss, rows = two_workers
    print(f"| `--format csv --workers 2` | {w:.2f} s ({whole['csv'][0] / w:.2f}x one process) | {rss:.0f} MiB "
          f"(the largest of the three processes) | {rows:,} |")
    print("\nGoals (issue 27): the whole command at least 12x faster than skyfield at 2,000 satellites with peak "
          "memory no higher than skyfield's, in every format; the whole catalog in at most 2 s and 64 MiB in one "
          "process; a clear speed-up with `--workers 2` on 2 cores. Accuracy is a test, not a benchmark: "
          "tests/tracking/test_pass_accuracy.py checks AOS/LOS to 10 ms and maximum elevations to 0.001 deg "
          "against skyfield's geometry sampled densely.\n")
    print("| start-up (whole process) | median of 7 |")
    print("|---|---|")
    for label, seconds in startup:
        print(f"| {label} | {seconds * 1e3:.0f} ms |")
    print()


if __name__ == "__main__":
    main()
