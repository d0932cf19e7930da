"""The standing fault campaign: ``python -m bench faults``.

Injects every fault of :mod:`bench.fault_campaign.scenarios` in turn into one real station running
through an ISS pass at virtual speed (real ``rotctld``/``rigctld`` behind fault proxies, DDE, TCP,
EasyComm on a pty, a watched configuration file, a state file), and prints one Markdown table: per
fault, how long STATUS took to show it, how long after its cause ended the output worked again (in
ticks and seconds), ticks without a string, ticks that were silent or broken while STATUS said all was
well, false alarms after recovery, tracebacks.  Exit status 1 when any fault misses the targets
(recovered, explained, no traceback); then what the slow-loris fault counted.  ``--only TEXT`` runs the
faults whose name contains TEXT.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time

from bench.fault_campaign.rig import FaultRig
from bench.fault_campaign.runner import FaultResult, run_fault
from bench.fault_campaign.scenarios import FAULTS


def _cell(value: float | int | None, unit: str = "") -> str:
    if value is None:
        return "**never**"
    return f"{value:g}{unit}" if isinstance(value, float) else f"{value}{unit}"


def table(results: list[FaultResult]) -> str:
    rows = ["| fault | STATUS link | shown after | recovered after cause ended | ticks without a string | "
            "unexplained ticks | false alarms | tracebacks |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in results:
        rows.append(f"| {r.name} | {r.link or '-'} | {_cell(r.detected_s, ' s') if r.link else '-'} | "
                    f"{_cell(r.recovered_ticks, ' ticks')} ({_cell(r.recovered_s, ' s')}) | {r.silent} | "
                    f"{r.unexplained} | {r.false_alarms} | {r.tracebacks} |")
    return "\n".join(rows)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench faults", description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="run only the faults whose name contains this text")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s", stream=sys.stderr)
    chosen = [f for f in FAULTS if args.only.lower() in f.name.lower()]
    started = time.monotonic()
    results = []
    with FaultRig() as rig:
        for fault in chosen:
            print(f"fault: {fault.name} ...", file=sys.stderr, flush=True)
            results.append(run_fault(rig, fault))
        loris = rig.loris
    print(f"## Fault campaign\n\n`python -m bench faults`: {len(results)} faults, one station, 5 Hz ticks in "
          f"virtual time; {time.monotonic() - started:.0f} s of real time.\n")
    print(table(results))
    if loris is not None:
        print(f"\nSlow-loris, from 127.0.0.1: {loris.refused} connections refused with an ERROR line, "
              f"{loris.evicted} quietest one(s) closed to make room, {loris.local_served} checks "
              "from 127.0.0.1 (as `nfwserver status` connects) answered.")
    return 0 if all(r.passed for r in results) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
