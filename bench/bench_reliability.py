"""The hostile-input and fault campaign (issue 18, "The standing campaign"), run against a real Station.

``python -m bench reliability [--minutes N] [--quick] [--seed S]`` runs every family with bounded loops
(:class:`bench.campaign.tally.Budget`) and prints, for each, inputs tried, crashes, tracebacks in the log
and data lost -- the goal for the last three is 0 -- then the real-time run's RSS.  The default is the full
campaign with a 10-minute real-time run at 50 Hz; ``--quick`` is a smaller campaign for a developer (about a
minute), ``--minutes`` sets the real-time run alone.  Exit status 1 when any count that should be 0 is not.
It is not part of the plain ``python -m bench`` run and does not write docs/BENCHMARKS.md; its figures are
quoted in docs/RELIABILITY.md.
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from bench.campaign import fault_families, input_families, realtime, stop_attacks, tcp_attacks, write_kills
from bench.campaign.station_rig import StationRig, hamlib_available
from bench.campaign.tally import Budget, Tally, run_family


def run_campaign(budget: Budget, workdir: Path, progress: Callable[[str], None] = lambda _: None) -> list[Tally]:
    """Every family in turn; returns their tallies (the real-time run last)."""
    seed = budget.seed
    tallies: list[Tally] = []

    def family(name: str, body: Callable[[Tally], None]) -> None:
        progress(f"{name} ...")
        tally = run_family(Tally(name), body)
        tallies.append(tally)
        progress(f"  {tally.tried} inputs, {tally.crashes} crashes, {tally.tracebacks} tracebacks, "
                 f"{tally.lost} lost, {tally.seconds:.1f} s")

    family("element files: load_elements", lambda t: input_families.run_element_files(t, budget.elements, seed))
    family("element files: elements update",
           lambda t: input_families.run_element_updates(t, budget.updates, seed, workdir))
    family("configurations: parse_config", lambda t: input_families.run_configs(t, budget.configs, seed, workdir))
    family("Hamlib replies (scripted peer)",
           lambda t: fault_families.run_hostile_hamlib(t, budget.hamlib_replies, seed))
    family("SIGKILL during element-store writes",
           lambda t: write_kills.run_store_kills(t, budget.write_kills, seed, workdir))
    family("SIGKILL during state-file writes",
           lambda t: write_kills.run_state_kills(t, budget.write_kills, seed, workdir))
    family("nfwserver stop: during start-up, forged description, suspended station, full disk",
           lambda t: stop_attacks.run_stop_attacks(t, budget.stop_attacks, seed, workdir))
    station_dir = workdir / "station"
    station_dir.mkdir(exist_ok=True)
    with StationRig(station_dir) as rig:
        family("Nova pokes over DDE", lambda t: input_families.run_dde_pokes(t, rig, budget.pokes, seed))
        family("Nova lines over TCP", lambda t: input_families.run_tcp_lines(t, rig, budget.pokes, seed))
        family("PREDICT datagrams over UDP",
               lambda t: input_families.run_predict_datagrams(t, rig, budget.datagrams, seed))
        family("rotctld/rigctld killed and restarted",
               lambda t: fault_families.run_daemon_kills(t, rig, budget.daemon_kills))
    family("TCP: web pages' requests (cross-protocol), 8 addresses",
           lambda t: tcp_attacks.run_cross_protocol(t, budget.http_requests, seed, workdir))
    family("TCP: the operator's status and watch under crowds",
           lambda t: tcp_attacks.run_lockout(t, budget.lockout_rounds, workdir))
    files = Tally("station files after the run (store, state)", tried=2)
    rig.files_whole(files)
    tallies.append(files)
    family(f"real time at 50 Hz, {budget.realtime_s / 60:g} min",
           lambda t: realtime.run_realtime(t, budget.realtime_s, workdir))
    return tallies


def format_report(tallies: list[Tally], budget: Budget, elapsed_s: float) -> str:
    lines = ["## Reliability campaign\n",
             f"`python -m bench reliability` with seed {budget.seed}: a real Station (fake DDE transport, PREDICT "
             "UDP and the TCP server on 127.0.0.1, " + ("real rotctld/rigctld" if hamlib_available() else
                                                        "no Hamlib daemons installed") +
             f"), {platform.system()} {platform.release()}, Python {platform.python_version()}; "
             f"{elapsed_s / 60:.1f} minutes in all.\n",
             "| family | inputs | crashes | tracebacks | data lost | seconds |", "|---|---:|---:|---:|---:|---:|"]
    for t in tallies:
        lines.append(f"| {t.family} | {t.tried:,} | {t.crashes} | {t.tracebacks} | {t.lost} | {t.seconds:.1f} |")
    total = Tally("total", sum(t.tried for t in tallies), sum(t.crashes for t in tallies),
                  sum(t.tracebacks for t in tallies), sum(t.lost for t in tallies))
    lines.append(f"| **total** | {total.tried:,} | {total.crashes} | {total.tracebacks} | {total.lost} | "
                 f"{sum(t.seconds for t in tallies):.1f} |\n")
    for t in tallies:
        details = [f"{key}: {value}" for key, value in t.extra.items() if key != "rss samples"]
        lines.append(f"- {t.family}: " + ("; ".join(details) or "-"))
        lines += [f"  - {note}" for note in t.notes]
        if "rss samples" in t.extra:
            samples = t.extra["rss samples"]
            step = max(1, len(samples) // 12)
            shown = samples[::step] + ([samples[-1]] if (len(samples) - 1) % step else [])
            lines.append("  - RSS (s: MiB): " + ", ".join(f"{s:.0f}: {rss:.1f}" for s, rss in shown))
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench reliability", description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=None, help="length of the real-time run (default 10)")
    parser.add_argument("--quick", action="store_true", help="a smaller campaign (about a minute)")
    parser.add_argument("--seed", type=int, default=Budget.seed)
    args = parser.parse_args(argv)
    budget = Budget(seed=args.seed)
    if args.quick:
        budget = replace(budget, elements=500, updates=30, configs=500, pokes=500, datagrams=500,
                         hamlib_replies=120, daemon_kills=2, write_kills=2, stop_attacks=2, realtime_s=30.0,
                         http_requests=300, lockout_rounds=6)
    if args.minutes is not None:
        budget = replace(budget, realtime_s=args.minutes * 60.0)
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="nfw-campaign-") as tmp:
        tallies = run_campaign(budget, Path(tmp), lambda text: print(text, file=sys.stderr, flush=True))
    print(format_report(tallies, budget, time.monotonic() - started))
    return 0 if all(t.clean for t in tallies) else 1


if __name__ == "__main__":
    raise SystemExit(main())
