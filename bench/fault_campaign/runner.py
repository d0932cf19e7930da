"""Runs one fault through a rig and measures it: detection, recovery, silent ticks, STATUS's truth.

Per fault, in virtual time at the station's publish rate:

1. healthy: ticks until the affected output works and STATUS names no fault (at most 60 s);
2. the cause, for the fault's duration;
3. the cause ended: ticks until the output works again and its link has left STATUS (at most 300 s,
   ``recovery_limit_s``).

Measured: ``detected_s`` (cause to the first tick whose STATUS names the link), ``recovered_ticks`` and
``recovered_s`` (cause ended to the first tick that works with the link gone from STATUS), ``silent``
(ticks after TUNE ON without a string for the DDE client), ``unexplained`` (silent ticks, or ticks
where the output did not work, while STATUS named no fault -- after detection), ``false_alarms``
(ticks after recovery whose STATUS still names the link), ``tracebacks`` (log records with one).
"""

from __future__ import annotations

from dataclasses import dataclass

from bench.fault_campaign.rig import RATE_HZ, FaultRig, TickRecord
from bench.fault_campaign.scenarios import Fault, restore_baseline

HEALTHY_LIMIT_S = 60.0
RECOVERY_LIMIT_S = 300.0
AFTER_S = 4.0  #: ticks watched after recovery for a fault that stays in STATUS


@dataclass
class FaultResult:
    name: str
    link: str | None
    healthy_at_start: bool
    detected_s: float | None
    recovered_ticks: int | None
    recovered_s: float | None
    ticks: int
    silent: int
    unexplained: int
    false_alarms: int
    tracebacks: int

    @property
    def passed(self) -> bool:
        return (self.healthy_at_start and self.recovered_ticks is not None and self.tracebacks == 0
                and self.unexplained == 0 and self.false_alarms == 0
                and (self.link is None or self.detected_s is not None))


def _ok(fault: Fault, rig: FaultRig, record: TickRecord) -> bool:
    try:
        works = fault.works(rig, record)
    except (OSError, ValueError, IndexError):
        works = False
    return works and (fault.link is None or fault.link not in record.faults)


def run_fault(rig: FaultRig, fault: Fault, recovery_limit_s: float = RECOVERY_LIMIT_S) -> FaultResult:
    restore_baseline(rig)
    rig.real_time = fault.real_time
    healthy = False
    for _ in range(round(HEALTHY_LIMIT_S * RATE_HZ)):
        record = rig.tick()
        if _ok(fault, rig, record) and not record.faults:
            healthy = True
            break
    records: list[tuple[TickRecord, bool]] = []  # each tick with whether the output worked then

    def step() -> tuple[TickRecord, bool]:
        record = rig.tick()
        records.append((record, _ok(fault, rig, record)))
        return records[-1]

    fault.inject(rig)
    start = rig.index
    for _ in range(round(fault.duration_s * RATE_HZ)):
        step()
    fault.remove(rig)
    ended = rig.index
    recovered: int | None = None
    for _ in range(round(recovery_limit_s * RATE_HZ)):
        record, ok = step()
        if ok:
            recovered = record.index - ended
            break
    after = rig.run(AFTER_S)
    rig.real_time = False
    detected = next((r.index for r, _ in records if fault.link is not None and fault.link in r.faults), None)
    silent = sum(not r.published for r, _ in records)
    unexplained = 0
    for r, ok in records:
        if detected is not None and r.index < detected:
            continue  # detection takes its time; counted in detected_s
        if (not ok or not r.published) and not r.faults:
            unexplained += 1
    return FaultResult(
        fault.name, fault.link, healthy,
        None if detected is None else (detected - start) / RATE_HZ,
        recovered, None if recovered is None else recovered / RATE_HZ,
        len(records), silent, unexplained,
        sum(fault.link is not None and fault.link in r.faults for r in after),
        sum(r.tracebacks for r, _ in records) + sum(r.tracebacks for r in after))
