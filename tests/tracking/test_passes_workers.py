"""``passes --workers``: ``auto`` by default; any number of worker processes writes the same bytes."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from nfwserver.cli import bulk_output, main, pass_rows, search_workers
from nfwserver.cli.forked_rows import write_in_order
from nfwserver.tracking import pass_workers
from tests.conftest import DATA, ROOT


@pytest.mark.skipif(sys.platform == "win32", reason="fork")
def test_one_two_and_three_workers_write_the_same_bytes(tmp_path) -> None:
    """Before, each worker searched every n-th satellite, in chunks of other satellites than one process
    makes: its times differed in the microseconds (CSV's sixth decimal of a duration, a TCA's millisecond).
    The rows' text is made by as many processes, a slab each in turn (cli/forked_rows.py)."""
    elements = tmp_path / "some.txt"
    elements.write_text("\n".join((DATA / "active.txt").read_text().splitlines()[: 3 * 1500]) + "\n")
    outputs = {}
    for fmt, workers in (("csv", "1"), ("csv", "2"), ("csv", "3"), ("json", "1"), ("json", "2")):
        done = subprocess.run(
            [sys.executable, "-m", "nfwserver", "passes", "--elements", str(elements), "--all", "--observer",
             "52.2,0.12,20", "--start", "2026-05-08T00:00:00Z", "--hours", "24", "--format", fmt,
             "--workers", workers], cwd=ROOT, capture_output=True, text=True, timeout=300, check=True)
        outputs[fmt, workers] = done.stdout
    # more rows than 3 slabs of pass_rows.SLAB_ROWS (2,048): each process makes some slabs' text
    assert outputs["csv", "1"].count("\n") > 3 * 2048
    assert outputs["csv", "2"] == outputs["csv", "1"] and outputs["csv", "3"] == outputs["csv", "1"]
    assert outputs["json", "2"] == outputs["json", "1"]


@pytest.mark.parametrize("fmt", [("csv",), ("json",), ("table", "--wide"), ("table",)])
def test_the_rows_are_made_by_as_many_processes_as_the_search(monkeypatch, capsys, tmp_path, fmt) -> None:
    """The writers are asked for the search's processes (they fork only where that is safe: forked_children)."""
    asked: list[int] = []

    def recorded(count, make, put, processes) -> None:  # the real writer, with the processes it was asked for
        asked.append(processes)
        write_in_order(count, make, put, processes)

    monkeypatch.setattr(pass_rows, "write_in_order", recorded)
    monkeypatch.setattr(bulk_output, "write_in_order", recorded)
    elements = tmp_path / "some.txt"
    elements.write_text("\n".join((DATA / "active.txt").read_text().splitlines()[: 3 * 300]) + "\n")
    assert main(["passes", "--elements", str(elements), "--all", "--observer", "52.2,0.12,20", "--start",
                 "2026-05-08T00:00:00Z", "--hours", "24", "--format", *fmt, "--workers", "3"]) == 0
    assert capsys.readouterr().out.count("\n") > 1000
    assert asked == [3]


def test_auto_forks_only_for_large_searches_and_idle_cores(monkeypatch) -> None:
    assert search_workers.auto_workers(search_workers.AUTO_WORKERS_FROM - 1) == 1
    if sys.platform == "win32":
        assert search_workers.auto_workers(20_000) == 1
        return
    cores = len(os.sched_getaffinity(0)) if sys.platform == "linux" else os.cpu_count()
    monkeypatch.setattr(search_workers, "busy_cores", lambda: 0)
    assert search_workers.auto_workers(20_000) == min(cores, search_workers.AUTO_WORKERS_MAX)
    monkeypatch.setattr(search_workers, "busy_cores", lambda: cores)  # every core busy already
    assert search_workers.auto_workers(20_000) == 1


def test_busy_cores_counts_what_runs_now_not_what_ran_a_minute_ago(monkeypatch) -> None:
    """The load average lags: right after another search it still counts that search's core, and just after a
    heavy job started it does not count it yet.  What runs now counts, the most of three readings."""
    monkeypatch.setattr(os, "getloadavg", lambda: (1.9, 1.2, 0.8))
    assert search_workers.busy_cores(["1.90 1.20 0.80 1/80 4242\n"] * 3) == 0  # only this process runs now
    assert search_workers.busy_cores(["1.90 1.20 0.80 2/80 4242\n", "1.90 1.20 0.80 1/80 4242\n"]) == 1
    monkeypatch.setattr(os, "getloadavg", lambda: (0.1, 0.0, 0.0))
    readings = ["0.10 0.00 0.00 1/80 1\n", "0.10 0.00 0.00 3/80 1\n", "0.10 0.00 0.00 2/80 1\n"]
    assert search_workers.busy_cores(readings) == 2
    monkeypatch.setattr(os, "getloadavg", lambda: (2.4, 1.2, 0.8))
    assert search_workers.busy_cores(["not a loadavg line"]) == 2  # unreadable: the average
    assert search_workers.busy_cores([]) == 2
    if sys.platform == "linux":  # the live file is read, not the average (which would raise here)
        def no_average() -> tuple[float, float, float]:
            raise AssertionError("the load average was read instead of /proc/loadavg")

        monkeypatch.setattr(os, "getloadavg", no_average)
        assert search_workers.busy_cores() >= 0


def test_workers_option_takes_auto_or_a_whole_number(capsys) -> None:
    from nfwserver.cli import build_parser

    parser = build_parser(["passes"])
    assert parser.parse_args(["passes"]).workers == "auto"
    assert parser.parse_args(["passes", "--workers", "AUTO"]).workers == "auto"
    assert parser.parse_args(["passes", "--workers", "3"]).workers == 3
    for bad in ("0", "1.5", "65", "many"):
        with pytest.raises(SystemExit):
            parser.parse_args(["passes", "--workers", bad])
        assert "--workers" in capsys.readouterr().err


def test_workers_take_every_chunk_once_the_largest_first() -> None:
    """Workers sharing one counter take the chunks in pull order, each chunk once, whoever asks next (here two
    takers in one process, alternating unevenly as workers of unequal speed would)."""
    import multiprocessing

    from nfwserver.tracking.elements import load_element_file
    from nfwserver.tracking.passes import _plan

    window_s = 86400.0
    plan = _plan(load_element_file(DATA / "active.txt").sets[:2000], window_s)
    order = pass_workers.pull_order(plan, window_s)
    assert sorted(order) == list(range(len(plan)))
    low = [i for i, c in enumerate(plan) if c.step_s == 1200.0 and len(c.members) == 200]
    assert set(order[: len(low)]) == set(low)  # the full chunks of low orbits (the most passes) go first
    taken = multiprocessing.get_context("fork").Value("q", 0)
    fast, slow = iter(pass_workers._Pulled(plan, order, taken)), iter(pass_workers._Pulled(plan, order, taken))
    got = []
    for _ in range(len(plan)):
        got.append(next(slow if len(got) % 3 == 2 else fast))
    assert [id(c) for c in got] == [id(plan[i]) for i in order]
    assert next(fast, None) is None and next(slow, None) is None
