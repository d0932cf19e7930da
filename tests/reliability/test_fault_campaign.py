"""The fault campaign behind ``python -m bench faults``, run on the faults that take seconds, so that the
campaign's own measuring is tested and a latch coming back fails the suite.

Each fault is injected into a real station (real rotctld/rigctld behind fault proxies, DDE, TCP, EasyComm
on a pty, a watched configuration file) stepped tick by tick in virtual time.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from bench.fault_campaign.rig import FaultRig
from bench.fault_campaign.runner import run_fault
from bench.fault_campaign.scenarios import FAULTS

QUICK = ("selected set past decay", "process stopped")


@pytest.mark.hamlib
def test_quick_faults_heal_within_two_ticks_and_status_tells_the_truth() -> None:
    chosen = [f for f in FAULTS if f.name.startswith(QUICK)]
    assert len(chosen) == len(QUICK)
    with FaultRig() as rig:
        results = [run_fault(rig, fault) for fault in chosen]
    for r in results:
        assert r.healthy_at_start, r.name
        assert r.recovered_ticks is not None and r.recovered_ticks <= 2, r
        assert r.tracebacks == 0 and r.unexplained == 0 and r.false_alarms == 0, r
    decay = results[0]
    assert decay.detected_s == pytest.approx(0.2)  # the first failing tick is in STATUS
    assert decay.silent == decay.ticks - decay.recovered_ticks  # silent exactly while it lasted


@pytest.mark.hamlib
def test_the_campaign_counts_what_goes_wrong() -> None:
    # A fault whose cause never ends must be reported as never recovered, with its ticks unexplained when
    # STATUS stays silent about it: the measuring can fail.
    never = replace(next(f for f in FAULTS if f.name.startswith("selected set past decay")),
                    remove=lambda rig: None, link="no-such-link")
    with FaultRig() as rig:
        result = run_fault(rig, never, recovery_limit_s=2.0)
    assert result.recovered_ticks is None and result.detected_s is None and not result.passed
    assert result.silent == result.ticks


@pytest.mark.hamlib
def test_slow_loris_evicts_idle_connections_and_serves_local_tools(monkeypatch) -> None:
    # 40 idle connections from 127.0.0.1: each of the 8 over the cap closes the quietest before it; then every
    # check from 127.0.0.1 (as `nfwserver status` connects) is served, the first by closing the quietest
    # connection (the checks after it use the room it left: each closes its connection), and 127.0.0.2 too.
    loris = next(f for f in FAULTS if "slow-loris" in f.name)
    with FaultRig() as rig:
        result = run_fault(rig, loris)
        counts = rig.loris
    assert result.passed and result.recovered_ticks is not None and result.recovered_ticks <= 2, result
    assert counts is not None and counts.refused == 0, counts
    assert counts.local_served >= 8 and counts.evicted == 9, counts  # 10 s, a check a second
    # The check can fail: with no connection ever chosen to make room, 127.0.0.1 is locked out, and those
    # ticks are counted as not working while STATUS names no fault.
    monkeypatch.setattr("nfwserver.tcp.admission._quietest", lambda clients, now: None)
    with FaultRig() as rig:
        locked = run_fault(rig, loris)
    assert not locked.passed and locked.unexplained > 0, locked
