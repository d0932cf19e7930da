"""The rule on hand-made passes: gaps, touching passes, unknown AOS or LOS, ties, fixed decisions."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.autotrack.rule import NO_BLOCKER, decide

NAN = math.nan


def _decide(passes: list[tuple[float, float, int]], gap: float, fixed: list[int] | None = None):
    aos, los, priority = (np.array(c, dtype=float) for c in zip(*passes))
    return decide(aos, los, priority.astype(np.int64), gap, None if fixed is None else np.array(fixed))


def test_the_gap_decides_and_touching_passes_are_apart_with_no_gap() -> None:
    passes = [(0, 600, 0), (660, 1200, 1), (1230, 1800, 1), (1800, 2400, 2)]
    d = _decide(passes, 60.0)
    # 660 is 60 s after 600 (apart enough); 1230 is 30 s after 1200 (not); 1800 is 570 s after 1200
    assert d.scheduled.tolist() == [True, True, False, True]
    assert d.blocker[2] == 1 and d.separation_s[2] == 30.0
    assert _decide(passes, 0.0).scheduled.tolist() == [True, True, True, True]  # 1800 touches 1800


def test_lower_priority_is_left_out_whole_naming_the_earliest_conflict() -> None:
    passes = [(1000, 1600, 2), (0, 1100, 0), (1500, 2000, 1), (3000, 3600, 2)]
    d = _decide(passes, 60.0)
    assert d.scheduled.tolist() == [False, True, True, True]
    assert d.blocker[0] == 1 and d.separation_s[0] == -100.0  # runs into both; the earliest is named
    assert d.blocker[1] == d.blocker[2] == NO_BLOCKER


def test_priority_beats_time_order() -> None:
    d = _decide([(0, 600, 1), (500, 1000, 0), (900, 1500, 1)], 60.0)
    assert d.scheduled.tolist() == [False, True, False]


def test_unknown_aos_or_los_reach_to_infinity() -> None:
    # an always-up satellite (neither known) of top priority leaves out everything else
    d = _decide([(NAN, NAN, 0), (100, 700, 1)], 60.0)
    assert d.scheduled.tolist() == [True, False] and d.blocker[1] == 0
    d = _decide([(NAN, 500, 1), (540, 900, 0), (5000, NAN, 1), (2000, 4960, 0)], 60.0)
    assert d.scheduled.tolist() == [False, True, False, True]


def test_fixed_decisions_are_kept_and_taken_first() -> None:
    passes = [(0, 600, 1), (500, 1000, 0), (1500, 2000, 2)]
    d = _decide(passes, 60.0, fixed=[1, -1, 0])
    assert d.scheduled.tolist() == [True, False, False]
    assert d.blocker[1] == 0 and d.blocker[2] == NO_BLOCKER  # kept out, with no pass of this plan named


def _plain_rule(passes: list[tuple[float, float, int]], gap: float) -> list[tuple[bool, int]]:
    """The rule as docs/AUTOTRACK.md words it, by brute force: (scheduled, blocker index or -1) per pass."""
    order = sorted(range(len(passes)), key=lambda i: (passes[i][2], passes[i][0], i))
    taken: list[int] = []
    out = [(False, -1)] * len(passes)
    for i in order:
        a, b, _ = passes[i]
        clashes = [k for k in taken if max(passes[k][0] - b, a - passes[k][1]) < gap]
        if clashes:
            out[i] = (False, min(clashes, key=lambda k: passes[k][0]))
        else:
            taken.append(i)
            out[i] = (True, -1)
    return out


@given(st.lists(st.tuples(st.integers(0, 20_000), st.integers(60, 3_000), st.integers(0, 5)), max_size=60),
       st.sampled_from([0.0, 30.0, 60.0, 600.0]))
def test_the_rule_matches_a_brute_force_reading_of_its_words(raw, gap) -> None:
    passes = [(float(a), float(a + d), p) for a, d, p in raw]
    if not passes:
        return
    d = _decide(passes, gap)
    assert list(zip(d.scheduled.tolist(), d.blocker.tolist())) == _plain_rule(passes, gap)
    chosen = [passes[i] for i in np.flatnonzero(d.scheduled)]
    assert all(max(q[0] - p[1], p[0] - q[1]) >= gap for p in chosen for q in chosen if p is not q)


def test_a_pass_overlapping_a_kept_pass_is_left_out_even_when_kept_passes_overlap_each_other() -> None:
    """Begun passes keep their decision on a re-plan; an element update can move one kept pass into another
    ([0, 1000] holding [100, 200]).  The bisection over the scheduled passes' ends then missed [500, 600], which
    overlaps the first: it was scheduled beside it."""
    aos, los = np.array([0.0, 100.0, 500.0]), np.array([1000.0, 200.0, 600.0])
    decisions = decide(aos, los, np.array([0, 1, 2]), 60.0, np.array([1, 1, -1]))
    assert decisions.scheduled.tolist() == [True, True, False]
    assert decisions.blocker[2] == 0 and decisions.separation_s[2] < 0  # overlaps the first
