"""Run every ``bench/bench_*.py`` and write their Markdown sections to ``docs/BENCHMARKS.md``.

Usage: ``python -m bench [NAME ...]`` (``python -m bench --help`` lists them; names without the ``bench_``
prefix select a subset; the file is then updated only for those sections; ``-`` and ``_`` are the same in
names).  Each benchmark module is run as its own process (``python -m bench.bench_NAME``) and prints one
Markdown section, starting with a ``## `` heading, on stdout; a benchmark that prints nothing leaves its section
as it was.
Benchmarks in ``OPT_IN`` run only when named: ``wine-dde`` needs a Wine prefix (tools/wine/setup); ``soak`` runs
for as long as it is asked (``python -m bench soak --minutes N [--accelerated]``: options after the names go to
every benchmark named).
``python -m bench reliability [OPTIONS]`` (``STANDALONE``) runs the hostile-input and fault campaign
(bench/bench_reliability.py) with its output on the terminal and its options passed on; its figures go to
docs/RELIABILITY.md by hand, not to docs/BENCHMARKS.md.

A section may end in analysis written by hand: everything from a line :data:`KEPT` on is kept when the
benchmark writes its section again (the figures above it are the benchmark's, the reading of them is not).
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
OPT_IN = ("wine_dde", "soak")  #: run only when named
STANDALONE = ("reliability", "faults")  #: run alone, named first, with their own options; they write no section
#: Opens the hand-written end of a section, which a new run of its benchmark keeps.
KEPT = "<!-- written by hand: kept when the benchmark rewrites this section -->"
HEADER = ("# Benchmarks\n\nRegenerate with `python -m bench` (a subset: `python -m bench NAME ...`; the Wine "
          "section: `NFW_WINE_HOME=... python -m bench wine-dde`).\n")


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


def _summary(name: str) -> str:
    """The first line of ``bench/bench_NAME.py``'s docstring, without its quotes."""
    for line in (ROOT / "bench" / f"bench_{name}.py").read_text().splitlines():
        if line.strip():
            return line.strip().strip('"').strip()
    return ""


def _help() -> str:
    names = sorted(p.stem[len("bench_") :] for p in (ROOT / "bench").glob("bench_*.py"))
    width = max(len(n) for n in names) + 2
    lines = ["usage: python -m bench [NAME ...]   (or: python -m bench reliability|faults [OPTIONS])", "",
             "Runs the benchmarks named (every one but the opt-in ones without a name) and writes their sections "
             "to docs/BENCHMARKS.md.", "", "benchmarks:"]
    for name in names:
        note = " (opt-in: run only when named)" if name in OPT_IN else (
            " (alone, with its own options; writes no section)" if name in STANDALONE else "")
        lines.append(f"  {name.replace('_', '-'):{width}}{_summary(name)}{note}")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    if argv and argv[0] in ("-h", "--help", "help"):
        print(_help())
        return 0
    if argv and argv[0] in STANDALONE:
        return subprocess.run([sys.executable, "-m", f"bench.bench_{argv[0]}", *argv[1:]], cwd=ROOT).returncode
    names = sorted(p.stem[len("bench_") :] for p in (ROOT / "bench").glob("bench_*.py")
                   if p.stem[len("bench_") :] not in STANDALONE)
    first_option = next((i for i, a in enumerate(argv) if a.startswith("-")), len(argv))
    argv, options = argv[:first_option], argv[first_option:]
    chosen = [name.replace("-", "_") for name in argv] or [n for n in names if n not in OPT_IN]
    unknown = [n for n in chosen if n not in names]
    if unknown:
        print(f"unknown benchmark(s): {', '.join(unknown)}; have: {', '.join(names)} "
              f"(and, alone with its options: {', '.join(STANDALONE)})", file=sys.stderr)
        return 2
    if "-h" in options or "--help" in options:  # each benchmark's own help (none runs); docs/BENCHMARKS.md untouched
        for name in chosen:
            if "argparse" in (ROOT / "bench" / f"bench_{name}.py").read_text():
                subprocess.run([sys.executable, "-m", f"bench.bench_{name}", "--help"], cwd=ROOT, check=False)
            else:
                print(f"{name.replace('_', '-')}: {_summary(name)} (takes no options)")
        return 0
    old = _sections(OUT.read_text()) if OUT.exists() else {}
    written = 0
    for name in chosen:
        print(f"running bench_{name} ...", file=sys.stderr)
        started = time.monotonic()
        proc = subprocess.run(  # its stderr (progress, failures) goes straight to ours
            [sys.executable, "-m", f"bench.bench_{name}", *options], cwd=ROOT, stdout=subprocess.PIPE, text=True
        )
        if proc.returncode != 0:
            print(f"bench_{name} failed (exit {proc.returncode})", file=sys.stderr)
            return 1
        sections = _sections(proc.stdout)
        if not sections:
            print(f"  bench_{name} printed no section: its section is kept as it was", file=sys.stderr)
        written += len(sections)
        for heading, section in sections.items():
            before = old.get(heading, "")
            if KEPT in before and KEPT not in section:
                section = section.rstrip() + "\n\n" + before[before.index(KEPT):].rstrip() + "\n"
            old[heading] = section
        print(f"  done in {time.monotonic() - started:.1f} s", file=sys.stderr)
    if not written:
        print(f"no section: {OUT.relative_to(ROOT)} left as it was", file=sys.stderr)
        return 0
    stamp = time.strftime("%Y-%m-%d", time.gmtime())
    ran = ", ".join(n.replace("_", "-") for n in chosen)
    text = HEADER + f"\nLast run {stamp}: {ran} (other sections are from earlier runs). {_machine()}\n\n" + \
        "\n".join(old[h] for h in sorted(old))
    OUT.parent.mkdir(exist_ok=True)
    OUT.write_text(text)
    print(f"wrote {OUT.relative_to(ROOT)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
