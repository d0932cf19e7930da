"""Run every ``bench/bench_*.py`` and write their Markdown sections to ``docs/BENCHMARKS.md``.

Usage: ``python -m bench [NAME ...]`` (names without the ``bench_`` prefix select a subset; the
file is then updated only for those sections).  Each benchmark module is run as its own process
(``python -m bench.bench_NAME``) and prints one Markdown section, starting with a ``## `` heading,
on stdout.

Opt-in benchmarks (:data:`OPT_IN`) are not part of the plain ``python -m bench`` run and do not write
docs/BENCHMARKS.md: ``python -m bench reliability [OPTIONS]`` runs the hostile-input and fault campaign
(bench/bench_reliability.py) with its output on the terminal and its options passed on.
"""

from __future__ import annotations

import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "BENCHMARKS.md"
OPT_IN = ("reliability",)  #: run only when named first, with their own options; their figures go elsewhere
HEADER = "# Benchmarks\n\nRegenerate with `python -m bench` (a subset: `python -m bench NAME ...`).\n"


def _machine() -> str:
    import numpy

    cpu = platform.processor() or platform.machine()
    return (
        f"Machine: {os.cpu_count()} cores ({cpu}), Python {platform.python_version()}, "
        f"numpy {numpy.__version__}, {platform.system()} {platform.release()}."
    )


def _sections(text: str) -> dict[str, str]:
    parts = re.split(r"(?m)^(?=## )", text)
    return {p.splitlines()[0]: p.rstrip() + "\n" for p in parts if p.startswith("## ")}


def main(argv: list[str]) -> int:
    if argv and argv[0] in OPT_IN:
        return subprocess.run([sys.executable, "-m", f"bench.bench_{argv[0]}", *argv[1:]], cwd=ROOT).returncode
    names = sorted(p.stem[len("bench_") :] for p in (ROOT / "bench").glob("bench_*.py")
                   if p.stem[len("bench_") :] not in OPT_IN)
    chosen = argv or names
    unknown = [n for n in chosen if n not in names]
    if unknown:
        print(f"unknown benchmark(s): {', '.join(unknown)}; have: {', '.join(names)} "
              f"(and, alone with its options: {', '.join(OPT_IN)})", file=sys.stderr)
        return 2
    old = _sections(OUT.read_text()) if OUT.exists() else {}
    for name in chosen:
        print(f"running bench_{name} ...", file=sys.stderr)
        started = time.monotonic()
        proc = subprocess.run(
            [sys.executable, "-m", f"bench.bench_{name}"], cwd=ROOT, capture_output=True, text=True
        )
        if proc.returncode != 0:
            sys.stderr.write(proc.stderr)
            print(f"bench_{name} failed (exit {proc.returncode})", file=sys.stderr)
            return 1
        for heading, body in _sections(proc.stdout).items():
            old[heading] = body
        print(f"  done in {time.monotonic() - started:.1f} s", file=sys.stderr)
    stamp = time.strftime("%Y-%m-%d", time.gmtime())
    text = HEADER + f"\nLast run {stamp}. {_machine()}\n\n" + "\n".join(old[h] for h in sorted(old))
    OUT.parent.mkdir(exist_ok=True)
    OUT.write_text(text)
    print(f"wrote {OUT.relative_to(ROOT)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
