"""The autotrack schedule as a user runs it: ``nfwserver schedule`` over whole satellite lists, beside ``passes``.

Each run is a whole process writing every row to a file: ``python -m nfwserver schedule --config C --elements
FILE --start 2026-05-08T00:00:00Z --hours 24 --format F``, where C names the observer (52.2,0.12,20) and puts
every satellite of FILE in ``[autotrack] satellites`` in the file's order (the first has the highest priority);
beside it ``nfwserver passes`` over the same satellites, file and window (``--min-el 10``, the schedule's
default), which searches the same passes and writes the same columns less the two of the schedule.  FILE is
nfwserver/data/amateur.txt (the bundled amateur list) and tests/data/visual.txt (/work/shared/data's
visual.txt).  Commands alternate; median wall and CPU (user + system) time of :data:`REPEAT`, peak RSS from
``wait4``; our modules byte-compiled first, as ``pip install`` leaves them (bench/bench_passes.py).  In process:
the plan (search and rule) and the rule alone, and one runtime tick; medians.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LISTS = {"amateur list (bundled amateur.txt)": ROOT / "nfwserver" / "data" / "amateur.txt",
         "visual list (tests/data/visual.txt)": ROOT / "tests" / "data" / "visual.txt"}
REPEAT = int(os.environ.get("NFW_BENCH_REPEAT", "5"))
START = "2026-05-08T00:00:00Z"


def _numbers(path: Path) -> list[int]:
    from nfwserver.tracking.elements import load_element_file

    return list(dict.fromkeys(s.catalog_number for s in load_element_file(path).sets))


def _run(cmd: list[str]) -> tuple[float, float, int, float]:
    """Wall seconds, peak RSS (MiB), lines written and CPU seconds of one process (stdout to a file), run from
    the root."""
    with tempfile.TemporaryFile() as out:
        started = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=out, stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - started
        if os.waitstatus_to_exitcode(status):
            raise RuntimeError(f"{cmd} failed")
        out.seek(0)
        return wall, usage.ru_maxrss / 1024.0, out.read().count(b"\n"), usage.ru_utime + usage.ru_stime


def _commands(path: Path, config: Path) -> dict[str, list[str]]:
    common = ["--config", str(config), "--elements", str(path), "--start", START, "--hours", "24"]
    sats = [arg for n in _numbers(path) for arg in ("--sat", str(n))]
    out = {f"schedule --format {fmt}": [sys.executable, "-m", "nfwserver", "schedule", *common, "--format", fmt]
           for fmt in ("table", "csv", "json")}
    out["passes --format csv (beside it)"] = [sys.executable, "-m", "nfwserver", "passes", *common, *sats,
                                               "--min-el", "10", "--format", "csv"]
    return out


def _in_process(path: Path) -> tuple[float, float, float, int, int]:
    """Median seconds of a plan, of the rule alone and of a runtime tick; passes and scheduled passes."""
    import numpy as np

    from nfwserver.autotrack import AutotrackRuntime, AutotrackSettings, plan_schedule
    from nfwserver.autotrack.rule import decide
    from nfwserver.tracking.catalog import Catalog
    from nfwserver.tracking.elements import load_element_file
    from nfwserver.tracking.observer import parse_observer

    catalog = Catalog(load_element_file(path).sets)
    settings = AutotrackSettings(tuple(_numbers(path)))
    observer, start = parse_observer("52.2,0.12,20"), datetime(2026, 5, 8, tzinfo=timezone.utc)
    plans, rules = [], []
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        schedule = plan_schedule(catalog, observer, None, 0.0, settings, start, start + timedelta(hours=24))
        plans.append(time.perf_counter() - t0)
        cols = schedule.columns
        rank = {n: i for i, n in enumerate(schedule.priorities)}
        priority = np.array([rank[n] for n in cols["catalog_number"].tolist()], dtype=np.int64)
        t0 = time.perf_counter()
        decide(cols["aos_s"], cols["los_s"], priority, settings.min_gap_s)
        rules.append(time.perf_counter() - t0)
    runtime = AutotrackRuntime(lambda now, previous: schedule, lambda n: None, on=True)
    runtime.tick(start)
    ticks = 86400
    t0 = time.perf_counter()
    for k in range(ticks):
        runtime.tick(start + timedelta(seconds=k))
    tick = (time.perf_counter() - t0) / ticks
    return (statistics.median(plans), statistics.median(rules), tick, len(schedule),
            int(schedule.decisions.scheduled.sum()))


def main() -> None:
    subprocess.run([sys.executable, "-m", "compileall", "-q", "nfwserver", "bench"], cwd=ROOT, check=True)
    load = os.getloadavg()[0]
    rows, inside = [], []
    with tempfile.TemporaryDirectory() as folder:
        for label, path in LISTS.items():
            numbers = _numbers(path)
            config = Path(folder) / "c.toml"
            config.write_text('[observer]\nlocation = "52.2,0.12,20"\n[autotrack]\nsatellites = ['
                              + ", ".join(str(n) for n in numbers) + "]\n", encoding="utf-8")
            commands = _commands(path, config)
            runs: dict[str, list[tuple[float, float, int, float]]] = {key: [] for key in commands}
            for _ in range(REPEAT):
                for key, cmd in commands.items():
                    runs[key].append(_run(cmd))
            for key, rs in runs.items():
                rows.append(f"| {label}, {len(numbers)} satellites | `{key}` | "
                            f"**{statistics.median(r[0] for r in rs):.3f} s** | "
                            f"{statistics.median(r[3] for r in rs):.3f} s | {max(r[1] for r in rs):.0f} MiB | "
                            f"{rs[0][2] - (2 if 'json' in key else 1)} |")
            plan, rule, tick, passes, scheduled = _in_process(path)
            inside.append(f"| {label} | {plan * 1000:.1f} ms | {rule * 1000:.2f} ms | {tick * 1e6:.1f} us | "
                          f"{passes} / {scheduled} |")
    print("## Autotrack schedule\n")
    print("Whole processes writing every row to a file: `nfwserver schedule --config C --elements FILE --start "
          f"{START} --hours 24 --format F`, C naming the observer (52.2,0.12,20) and every satellite of FILE in "
          "`[autotrack] satellites` in the file's order (the first the highest priority); beside it `nfwserver "
          "passes` over the same satellites, file and window with `--min-el 10` (the schedule's default): the same "
          "search and the same columns less `scheduled` and `reason`.  FILE: the bundled nfwserver/data/amateur.txt "
          "and tests/data/visual.txt (a copy of /work/shared/data/visual.txt).  Byte-compiled first, as `pip "
          f"install` leaves the package; commands alternating, median of {REPEAT}; CPU = user + system time of the "
          "process (`wait4`), which other processes' load does not inflate; peak RSS from `wait4`.  In process: "
          "one plan (the pass search and the rule), the rule alone on its passes, one runtime tick (a day of 1 s "
          f"ticks, divided).  Load average (1 min) {load:.1f} at the start, {os.getloadavg()[0]:.1f} at the end, "
          f"{os.cpu_count()} cores.\n")
    print("| list x 24 h | command | wall | CPU | peak RSS | rows |\n|---|---|---|---|---|---|")
    print("\n".join(rows))
    print("\n| in process | plan (search and rule) | rule alone | runtime tick | candidate / scheduled passes |\n"
          "|---|---|---|---|---|")
    print("\n".join(inside))


if __name__ == "__main__":
    main()
