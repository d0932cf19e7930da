"""``python -m bench --help`` lists the benchmarks (it was read as a benchmark's name, and refused)."""

from __future__ import annotations

import subprocess
import sys

from tests.conftest import ROOT


def test_bench_help_lists_every_benchmark_and_runs_none() -> None:
    done = subprocess.run([sys.executable, "-m", "bench", "--help"], cwd=ROOT, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    names = sorted(p.stem[len("bench_"):].replace("_", "-") for p in (ROOT / "bench").glob("bench_*.py"))
    listed = [line.split()[0] for line in done.stdout.splitlines() if line.startswith("  ")]
    assert listed == names and "station" in names
    assert "running" not in done.stderr  # nothing was run
