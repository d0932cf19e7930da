"""The autotrack rule: which candidate passes are scheduled, by priority, and which are left out and why.

Taking the satellites in priority order (and each satellite's passes in AOS order), a pass is scheduled
when it is at least ``min_gap_s`` apart from every pass already scheduled; otherwise it is left out whole.
Two passes ``[a1, b1]`` and ``[a2, b2]`` (AOS, LOS; s) are ``max(a2 - b1, a1 - b2)`` apart: negative when
they overlap.  A pass with an unknown AOS (before the search reached) counts from minus infinity, one with
an unknown LOS to plus infinity.

Scheduled passes never come closer than ``min_gap_s`` to each other, so in AOS order they are also in LOS
order: the conflicts of a pass are one run of them, found by two bisections.  Passes kept from an earlier
plan (begun before a re-plan) are the exception, as new elements may have moved them, so they are compared
one by one (a few at most).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np

__all__ = ["Decisions", "decide"]

#: ``Decisions.blocker`` of a scheduled pass (or one left out for a reason carried from an earlier plan).
NO_BLOCKER = -1


@dataclass(frozen=True)
class Decisions:
    """The rule's outcome for passes ``0..n-1`` (the caller's order)."""

    scheduled: np.ndarray  #: bool per pass
    blocker: np.ndarray  #: int per pass: the earliest scheduled pass it conflicts with, or NO_BLOCKER
    separation_s: np.ndarray  #: float per pass: how far apart it is from its blocker (s; negative: overlap)


def decide(aos_s: np.ndarray, los_s: np.ndarray, priority: np.ndarray, min_gap_s: float,
           fixed: np.ndarray | None = None) -> Decisions:
    """Apply the rule to passes with AOS ``aos_s`` and LOS ``los_s`` (s on one time axis; NaN: unknown) of
    priority ``priority`` (0 highest).  ``fixed`` (int per pass, optional): 1 for a pass scheduled already
    (kept, and taken before any other), 0 for one left out already (kept out, with no blocker named), -1 for
    a pass the rule decides.  Ties of priority and AOS keep the caller's order."""
    n = len(aos_s)
    start = np.where(np.isnan(aos_s), -np.inf, aos_s)
    end = np.where(np.isnan(los_s), np.inf, los_s)
    fixed = np.full(n, -1, dtype=np.int64) if fixed is None else np.asarray(fixed, dtype=np.int64)
    # Fixed passes first (scheduled ones take their place, left-out ones stay out), then by priority and AOS.
    order = np.lexsort((np.arange(n), start, priority, fixed != 1))
    scheduled = np.zeros(n, dtype=bool)
    blocker = np.full(n, NO_BLOCKER, dtype=np.int64)
    separation = np.full(n, np.nan)
    # The passes the rule scheduled, ascending (they are min_gap_s apart, so their ends are too); the fixed
    # ones apart (an element update may have moved them closer, even one into another), looked at one by one.
    starts: list[float] = []
    ends: list[float] = []
    which: list[int] = []
    kept: list[int] = []
    fixed_list, start_list, end_list = fixed.tolist(), start.tolist(), end.tolist()
    for i in order.tolist():
        if fixed_list[i] == 0:
            continue
        a, b = start_list[i], end_list[i]
        if fixed_list[i] == 1:
            kept.append(i)
            scheduled[i] = True
            continue
        # conflicts: scheduled [c, d] with c - b < gap and a - d < gap
        hi = bisect.bisect_left(starts, b + min_gap_s)
        lo = bisect.bisect_right(ends, a - min_gap_s)
        conflicts = [which[lo]] if lo < hi else []
        conflicts += [k for k in kept if start_list[k] - b < min_gap_s and a - end_list[k] < min_gap_s]
        if conflicts:
            k = min(conflicts, key=lambda c: (start_list[c], c))
            blocker[i] = k
            separation[i] = max(start_list[k] - b, a - end_list[k])
            continue
        at = bisect.bisect_left(starts, a)
        starts.insert(at, a)
        ends.insert(at, b)
        which.insert(at, i)
        scheduled[i] = True
    return Decisions(scheduled, blocker, separation)
