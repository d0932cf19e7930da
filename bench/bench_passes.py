"""Pass prediction as a user runs it: the ``nfwserver passes`` command against skyfield writing the same rows.

Each run is a whole process writing every pass to a file: ``python -m nfwserver passes --elements FILE
--observer 52.2,0.12,20 --start 2026-05-08T00:00:00Z --hours 24 --format F`` (run from the checkout, as
the installed console script runs it) against ``python -m bench.skyfield_passes`` (bench/skyfield_passes.py:
``find_events`` for every satellite, the angles at the events, the same columns and formats).  FILE is the
first N objects of tests/data/active.txt (the catalog of /work/shared/data/active.txt).  The two programs
alternate (ours, skyfield, ours, ...) so that load from other processes hits both alike; medians of the
wall time, and each run's peak resident memory from the OS (``wait4``'s rusage of that child).  Also: one
satellite (``--sat ISS``, the command users run most), the whole catalog over 24 h and 168 h with ``--workers
auto`` (the default) and one process, once against skyfield, each goal of issue 37 with its verdict, start-up
of whole processes, and, for context, skyfield finding only the events (printing their count).

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


def _ours(path: Path, fmt: str, workers: str = "auto", hours: str = HOURS, extra: tuple[str, ...] = ()) -> list[str]:
    return [sys.executable, "-m", "nfwserver", "passes", "--elements", str(path), "--observer", WHERE, "--start",
            START, "--hours", hours, "--format", fmt, "--workers", workers, *extra,
            *(["--wide"] if fmt == "table" and not extra else [])]  # every column, as skyfield's rows have


def _skyfield(path: Path, fmt: str) -> list[str]:
    return [sys.executable, "-m", "bench.skyfield_passes", str(path), WHERE, START, HOURS, fmt]


def _alternate(commands: dict[str, list[str]], repeat: int) -> dict[str, tuple[float, float, int]]:
    """Each command run ``repeat`` times, in turn (a, b, c, a, b, c, ...): median wall, largest RSS, lines."""
    runs: dict[str, list[tuple[float, float, int]]] = {key: [] for key in commands}
    for _ in range(repeat):
        for key, cmd in commands.items():
            runs[key].append(_run(cmd))
    return {key: (statistics.median(r[0] for r in rs), max(r[1] for r in rs), rs[0][2]) for key, rs in runs.items()}


def _around(ours: list[str], peer: list[str]) -> dict[str, tuple[float, float, int]]:
    """One run of ``peer`` (the whole catalog takes skyfield about two minutes) between two runs of ``ours`` before
    it and two after: our median wall of four, the largest RSS, the lines; the peer's one run.  One run of each
    made the ratio swing by a third between two runs of this bench (38.8x and 54.2x)."""
    before = [_run(ours) for _ in range(2)]
    theirs = _run(peer)
    mine = before + [_run(ours) for _ in range(2)]
    return {"ours": (statistics.median(r[0] for r in mine), max(r[1] for r in mine), mine[0][2]), "skyfield": theirs}


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


def _one_satellite(folder: Path) -> dict[str, tuple[float, float, int]]:
    """``passes --sat ISS`` (the 80-column table a user sees, and CSV) against skyfield's script, one set in the
    file, alternating."""
    lines = ACTIVE.read_text().splitlines()
    k = next(i for i in range(0, len(lines), 3) if lines[i + 1].startswith("1 25544U"))
    iss = folder / "iss.txt"
    iss.write_text("\n".join(lines[k : k + 3]) + "\n")
    sat = ("--sat", "ISS")
    config = folder / "station.toml"  # a station's configuration (what a user who runs the station has)
    config.write_text('[observer]\nlocation = "JO02ae"\n\n[elements]\nstale_days = 14\n')
    result = _alternate({"ours table": _ours(iss, "table", extra=sat), "skyfield table": _skyfield(iss, "table"),
                         "ours csv": _ours(iss, "csv", extra=sat), "skyfield csv": _skyfield(iss, "csv"),
                         "ours csv config": _ours(iss, "csv", extra=(*sat, "--config", str(config)))},
                        max(REPEAT, 9))
    return result


def _goal(met: bool) -> str:
    return "**met**" if met else "**not met**"


def main() -> None:
    folder = ROOT / "bench" / "results"
    folder.mkdir(exist_ok=True)
    subprocess.run([sys.executable, "-m", "compileall", "-q", "nfwserver", "bench"], cwd=ROOT, check=True)
    no_config = folder / "no-config"  # no user configuration file: the built-in defaults (one row gives --config)
    no_config.mkdir(exist_ok=True)
    os.environ["XDG_CONFIG_HOME"] = str(no_config)
    load_before = os.getloadavg()[0]
    one = _one_satellite(folder)
    print(f"  one satellite: {one}", file=sys.stderr)
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
    week = _alternate({"24 h": _ours(ACTIVE, "csv"), "168 h": _ours(ACTIVE, "csv", hours="168"),
                       "24 h, 1 process": _ours(ACTIVE, "csv", workers="1"),
                       "168 h, 1 process": _ours(ACTIVE, "csv", workers="1", hours="168"),
                       "24 h, 2 workers": _ours(ACTIVE, "csv", workers="2")}, REPEAT)
    print(f"  week: {week}", file=sys.stderr)
    sky_whole = _around(_ours(ACTIVE, "csv"), _skyfield(ACTIVE, "csv"))
    print(f"  whole catalog against skyfield: {sky_whole}", file=sys.stderr)
    startup = _startup()
    load_after = os.getloadavg()[0]
    n_all = len(ACTIVE.read_text().splitlines()) // 3
    from nfwserver.cli.search_workers import auto_workers

    auto_now = auto_workers(n_all)  # what `--workers auto` would choose at the end
    _report(one, vs, events, whole, week, sky_whole, startup, n_all, auto_now, load_before, load_after)


def _report(one: dict, vs: dict, events: tuple, whole: dict, week: dict, sky_whole: dict, startup: list,
            n_all: int, auto_now: int, load_before: float, load_after: float) -> None:
    print("## Pass prediction against skyfield\n")
    print("The command a user runs, as whole processes writing every pass to a file: `nfwserver passes "
          f"--elements FILE --observer {WHERE} --start {START} --hours {HOURS} --format F` (`python -m nfwserver` "
          "from the checkout, byte-compiled as `pip install` leaves it; `--workers auto`, the default, unless "
          "said) against bench/skyfield_passes.py, which "
          "finds the same passes with skyfield's `find_events` (0 deg) and writes the same rows (for the table, "
          "`--wide`: the default 80-column table leaves columns out, so it would be less work). Both print the "
          "header and one row per pass with the columns catalog_number, name, aos_utc, tca_utc, los_utc, "
          "max_elevation_deg, aos_azimuth_deg, los_azimuth_deg, duration_s, in_progress: times ISO-8601 UTC "
          "with milliseconds and Z, numbers with 1 decimal in the table (duration 0) and 6 in CSV and JSON, "
          "JSON as an array of objects (null for an unknown time or angle). Skyfield needs a second "
          "propagation (`(sat - topos).at(t).altaz()`, one call per satellite) for the elevations and azimuths "
          "at its events. What each finds differs at the window's edges only: nfwserver reports the true AOS "
          "and LOS of passes cut by the window (outside it), skyfield leaves them empty. FILE is the first "
          "2,000 objects of tests/data/active.txt (or all of them); the programs alternate in one run; "
          f"median of {REPEAT} wall times (9 for one satellite), peak RSS the largest of each run's `wait4` "
          f"maximum resident set. No user configuration file (`XDG_CONFIG_HOME` an empty folder), except in "
          f"the row that gives `--config`. Load average (1 min) {load_before:.1f} at the start, "
          f"{load_after:.1f} at the end, {os.cpu_count()} cores (`--workers auto` would choose {auto_now} "
          "worker(s) for the whole catalog at the end).\n")
    print("| one satellite x 24 h (`--sat ISS`, a file holding ISS) | nfwserver | skyfield | ratio | peak RSS "
          "nfwserver / skyfield |")
    print("|---|---|---|---|---|")
    for fmt in ("table", "csv"):
        (o, o_rss, _), (k, k_rss, _) = one[f"ours {fmt}"], one[f"skyfield {fmt}"]
        label = "the 80-column table (skyfield: its table)" if fmt == "table" else "`--format csv`"
        print(f"| {label} | {o * 1e3:.0f} ms | {k * 1e3:.0f} ms | **{k / o:.2f}x** | {o_rss:.0f} / {k_rss:.0f} MiB |")
    (o, o_rss, _), (k, k_rss, _) = one["ours csv config"], one["skyfield csv"]
    print(f"| `--format csv` with a configuration file (`--config`: the configuration is read and built) | "
          f"{o * 1e3:.0f} ms | {k * 1e3:.0f} ms | {k / o:.2f}x | {o_rss:.0f} / {k_rss:.0f} MiB |")
    print("\n| 2,000 satellites x 24 h | nfwserver | skyfield | ratio | peak RSS nfwserver / skyfield | rows "
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
    print(f"\n| whole catalog ({n_all:,} objects) | wall | peak RSS (the largest process) | rows |")
    print("|---|---|---|---|")
    for fmt in FORMATS:
        w, rss, rows = whole[fmt]
        print(f"| 24 h, `--format {fmt}` | **{w:.2f} s** | {rss:.0f} MiB | {rows - (2 if fmt == 'json' else 1):,} |")
    for key in ("24 h", "168 h", "24 h, 1 process", "168 h, 1 process", "24 h, 2 workers"):
        w, rss, rows = week[key]
        print(f"| {key}, `--format csv` (alternating) | {w:.2f} s | {rss:.0f} MiB | {rows - 1:,} |")
    (so, so_rss, so_rows), (sk, sk_rss, sk_rows) = sky_whole["ours"], sky_whole["skyfield"]
    print(f"| 24 h, `--format csv` against skyfield (ours: median of 4 around skyfield's one run) | {so:.2f} s "
          f"against skyfield's {sk:.1f} s: "
          f"**{sk / so:.1f}x** | {so_rss:.0f} / {sk_rss:.0f} MiB | {so_rows - 1:,} / {sk_rows - 1:,} |")
    one_ratio = min(one["skyfield table"][0] / one["ours table"][0], one["skyfield csv"][0] / one["ours csv"][0])
    one_rss = max(one["ours table"][1], one["ours csv"][1]) <= min(one["skyfield table"][1], one["skyfield csv"][1])
    two_k = min(vs[f][1][0] / vs[f][0][0] for f in FORMATS)
    week_ratio = week["168 h"][0] / week["24 h"][0]
    print("\n| goal (issue 37) | measured | |")
    print("|---|---|---|")
    print(f"| one satellite x 24 h: at least 1.5x skyfield, peak RSS no higher | {one_ratio:.2f}x (the lower "
          f"format), RSS {'no higher' if one_rss else 'higher'} | {_goal(one_ratio >= 1.5 and one_rss)} |")
    print(f"| 2,000 x 24 h: at least 25x skyfield | {two_k:.1f}x (the lowest format) | {_goal(two_k >= 25.0)} |")
    print(f"| whole catalog x 24 h: at least 50x skyfield | {sk / so:.1f}x | {_goal(sk / so >= 50.0)} |")
    print(f"| whole catalog x 168 h: at most 3x the 24 h time | {week_ratio:.2f}x | {_goal(week_ratio <= 3.0)} |")
    print(f"| whole catalog x 168 h: at most 80 MiB | {week['168 h'][1]:.0f} MiB | "
          f"{_goal(week['168 h'][1] <= 80.0)} |")
    print("\nAccuracy is a test, not a benchmark: tests/tracking/test_pass_accuracy.py (and test_few_passes.py "
          "for the search of a few satellites) check AOS/LOS to 10 ms and maximum elevations to 0.001 deg "
          "against skyfield's geometry sampled densely.\n")
    print("| start-up (whole process) | median of 7 |")
    print("|---|---|")
    for label, seconds in startup:
        print(f"| {label} | {seconds * 1e3:.0f} ms |")
    print()


if __name__ == "__main__":
    main()
