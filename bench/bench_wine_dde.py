"""Real DDEML under Wine: delivered advise rate and ``DdePostAdvise`` cost with 1, 10 and 100 conversations.

``python -m bench wine-dde`` (not in the default ``python -m bench`` run: it needs the Wine prefix of
``tools/wine/setup``; without one it says so and changes nothing).  Set ``NFW_WINE_HOME`` to a prefix
nobody else is using: DDE service names are per Wine server, so a second station in the same prefix
would take part.  Sizes: ``NFW_BENCH_WINE_SIZES`` (default ``1,10,100``), window ``NFW_BENCH_WINE_WINDOW``
seconds (default 20).

For each size N a station (``tools/wine/nfwserver run --headless``, 10 Hz, the Windows suite's
configuration) serves ceil(N/2) client programs (``tests/windows/dde_clients.py`` under
``tools/wine/run``, two conversations each, ``NFW32`` and ``NFW_SERVER``, hot advise loops on
``NFW_SERVER``).  Every program waits for the same wall-clock start and counts the strings each
conversation receives in the same window, then keeps its conversations until the station stops.
The station logs its ``DdePostAdvise`` wall time when it stops (one call per tick and item; the
figures at N advise links are the steady state, see :mod:`nfwserver.dde.post_advise_stats`).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from nfwserver.dde.post_advise_stats import parse_summary
from tests.windows.station_config import write_station_config
from tests.windows.wine_session import kill_session

ROOT = Path(__file__).resolve().parent.parent
WINE = ROOT / "tools" / "wine"
RATE_HZ = 10.0


def winpath(path: Path) -> str:
    return "Z:" + str(path.resolve()).replace("/", "\\")


def wine_home() -> Path:
    return Path(os.environ.get("NFW_WINE_HOME", Path.home() / ".cache" / "nfwserver" / "wine"))


@dataclass
class CaseResult:
    """One size: delivered rates (Hz, one per conversation) and the station's DDEML cost (ms)."""

    conversations: int
    programs: int
    window_s: float
    rates_hz: list[float]
    failures: list[str]
    deliveries: dict[str, int]  #: what the window's deliveries carried: string, empty, no data (all programs)
    cost: dict[str, float]
    connect_s: float
    load_1min: float


def connect_budget_s(programs: int) -> float:
    """Seconds allowed from launch until every program has its conversations (Wine Python starts
    take a few CPU seconds each; 2 cores)."""
    return 20.0 + 1.0 * programs


def run_case(conversations: int, window_s: float, work: Path) -> CaseResult:
    programs = (conversations + 1) // 2
    budget = connect_budget_s(programs)
    linger = 8.0 + 0.2 * programs  # after the window: last request, then the station stops
    case = work / f"n{conversations}"
    config = write_station_config(case, elements=Path(winpath(ROOT / "tests" / "data" / "visual.txt")))
    log = case / "station.log"
    env = {**os.environ, "NFW_WINE_TIMEOUT": str(int(budget + window_s + linger + 120))}
    launched = time.time()
    start_at = launched + budget
    station = subprocess.Popen(
        [str(WINE / "nfwserver"), "run", "--headless", "--config", winpath(config), "--log-file", winpath(log),
         "--duration", f"{budget + window_s + linger:.0f}"],
        cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env,
        start_new_session=True)
    outs = [case / f"clients{i}.json" for i in range(programs)]
    clients = []
    for i, out in enumerate(outs):
        count = min(2, conversations - 2 * i)
        clients.append(subprocess.Popen(
            [str(WINE / "run"), "python", winpath(ROOT / "tests" / "windows" / "dde_clients.py"),
             "--clients", str(count), "--seconds", str(window_s), "--start-at", f"{start_at:.3f}",
             "--connect-timeout", f"{budget:.0f}", "--wait-disconnect", f"{linger + 60:.0f}", "--out", winpath(out)],
            cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
            start_new_session=True))
        time.sleep(0.2)  # a little apart: many Wine processes starting at the same instant crowd wineserver
    load = 0.0
    try:
        time.sleep(max(0.0, start_at + window_s / 2 - time.time()))
        load = os.getloadavg()[0]
        for client in clients:
            client.wait(timeout=budget + window_s + linger + 120)
        _, stderr = station.communicate(timeout=120)
    finally:
        for proc in (*clients, station):  # on failure: the launchers and the Windows programs under them
            kill_session(proc)
    failures, rates = [], []
    deliveries = {"string": 0, "empty": 0, "no data": 0}
    if station.returncode != 0:
        failures.append(f"station exit {station.returncode}: {stderr[-500:]}")
    for out in outs:
        if not out.exists():
            failures.append(f"{out.name}: no result")
            continue
        records = json.loads(out.read_text())
        for key, value in (records[0].get("program_deliveries") or {}).items():
            deliveries[key] += value
        for record in records:
            if record["error"] is not None or record.get("late"):
                failures.append(f"{out.name}: {record['error'] or 'connected after the window began'}")
                continue
            rates.append(record["advise"] / record["window_s"])
    text = log.read_text(encoding="utf-8", errors="replace") if log.exists() else ""
    cost = parse_summary(text) or {}
    return CaseResult(conversations, programs, window_s, rates, failures, deliveries, cost, budget, load)


def environment() -> str:
    """Wine's version and the Windows Python's, as the prefix reports them."""
    wine = subprocess.run(["wine", "--version"], capture_output=True, text=True, timeout=30).stdout.strip()
    probe = subprocess.run(
        [str(WINE / "run"), "python", "-c",
         "import sys, numpy, sgp4; print('CPython', sys.version.split()[0], '/ numpy', numpy.__version__, "
         "'/ sgp4', sgp4.__version__)"],
        cwd=ROOT, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=120)
    return f"{wine}, Windows embeddable {probe.stdout.strip()}"


def _ms(value: float | None) -> str:
    return "—" if value is None else f"{value:.2f} ms"


def report(results: list[CaseResult], env: str, window_s: float) -> str:
    lines = [
        "## Real DDEML under Wine (tools/wine)\n",
        f"Measured {time.strftime('%Y-%m-%d', time.gmtime())} with `python -m bench wine-dde` under **{env}** "
        "(64-bit prefix, null graphics driver) on the 2-core Linux machine above. **These are Wine figures, not "
        "Windows figures.** Station: "
        f"`tools/wine/nfwserver run --headless` at {RATE_HZ:g} Hz; clients: `tests/windows/dde_clients.py` under "
        "`tools/wine/run`, two conversations per program (`NFW32` and `NFW_SERVER`; Wine allows one per "
        "service per program), hot advise loops on `NFW_SERVER`, all counting over the same "
        f"{window_s:g} s window. Rate = strings a conversation received in the window / window. "
        "`DdePostAdvise` = its wall time in the station (the transport's log line at stop), which includes "
        "our `XTYP_ADVREQ` callback for every link and DDEML posting the data; the station posts both "
        "items (`NFW_SERVER`, `NFW_DATA`) each tick, so a tick's DDE cost is the two columns added. Load: the "
        "1-minute load average in mid-window (the machine may be shared). A delivery without data is a "
        "notification whose data was lost (docs/PLATFORMS.md, open problem).\n",
        "| conversations (programs) | delivered per conversation: min / median / max | deliveries carrying a "
        "Nova string | `DdePostAdvise` at N links: mean / max | per link | post on the unlinked item | load (1 min) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in results:
        if r.rates_hz:
            rates = (f"{min(r.rates_hz):.2f} / {statistics.median(r.rates_hz):.2f} / {max(r.rates_hz):.2f} Hz "
                     f"({len(r.rates_hz)} of {r.conversations})")
        else:
            rates = f"none of {r.conversations}"
        at_n = r.cost.get("links") == r.conversations
        mean = r.cost.get("steady_mean_ms") if at_n else None
        per_link = f"{mean / r.conversations * 1e3:.0f} us" if mean is not None else "—"
        steady = f"{_ms(mean)} / {_ms(r.cost.get('steady_max_ms') if at_n else None)}"
        if not at_n and r.cost.get("links") is not None:
            steady += f" (most calls at {r.cost['links']:.0f} links)"
        total = sum(r.deliveries.values())
        carried = f"{r.deliveries['string']:,} of {total:,}"
        if r.deliveries["no data"]:
            carried += f" ({r.deliveries['no data']:,} without data)"
        lines.append(f"| {r.conversations} ({r.programs}) | {rates} | {carried} | {steady} | {per_link} | "
                     f"{_ms(r.cost.get('idle_mean_ms'))} | {r.load_1min:.1f} |")
    lines.append("")
    for r in results:
        for failure in r.failures[:5]:
            lines.append(f"- {r.conversations} conversations: {failure}")
    lines.append("")
    return "\n".join(lines)


def main() -> int:
    home = wine_home()
    if not (home / "stamps" / "ready").exists() or subprocess.run(
            ["sh", "-c", "command -v wine"], capture_output=True).returncode != 0:
        print(f"bench wine-dde: no Wine prefix at {home} (run tools/wine/setup, with NFW_WINE_HOME set to a "
              "prefix of your own); skipped, nothing changed", file=sys.stderr)
        return 0
    sizes = [int(s) for s in os.environ.get("NFW_BENCH_WINE_SIZES", "1,10,100").split(",")]
    window_s = float(os.environ.get("NFW_BENCH_WINE_WINDOW", "20"))
    env = environment()
    results = []
    work = Path(tempfile.mkdtemp(prefix="nfw-bench-wine-"))
    print(f"bench wine-dde: logs and client results in {work}", file=sys.stderr)
    for n in sizes:
        started = time.monotonic()
        results.append(run_case(n, window_s, work))
        print(f"  {n} conversations: {time.monotonic() - started:.0f} s, {len(results[-1].rates_hz)} measured, "
              f"{len(results[-1].failures)} failures, {results[-1].cost}", file=sys.stderr)
    print(report(results, env, window_s))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
