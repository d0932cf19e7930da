"""PassList: compact columns read back as Pass records, sorted, with the window flags (hand-built values)."""

from __future__ import annotations

import math
from datetime import datetime, timedelta, timezone

import numpy as np
import pytest

from nfwserver.tracking.pass_records import Pass, PassList

START = datetime(2026, 5, 8, tzinfo=timezone.utc)
NAN = math.nan


def _columns() -> dict[str, np.ndarray]:
    # Three passes given out of order: one cut at the start (no AOS), one whole, one cut at the end (no LOS).
    return {
        "catalog_number": np.array([25544, 40000, 7530]),
        "aos_s": np.array([3000.0, 600.5, NAN]),
        "tca_s": np.array([3300.0, 900.0, 60.0]),
        "los_s": np.array([NAN, 1200.25, 400.0]),
        "max_elevation_deg": np.array([10.0, 45.5, 3.25]),
        "aos_azimuth_deg": np.array([200.0, 10.0, 99.0]),
        "los_azimuth_deg": np.array([300.0, 170.0, 250.0]),
    }


def test_records_come_back_sorted_with_datetimes_and_window_flags() -> None:
    passes = PassList(START, 3200.0, _columns())
    assert len(passes) == 3
    assert list(passes) == [
        Pass(7530, None, START + timedelta(seconds=60), START + timedelta(seconds=400), 3.25, None, 250.0,
             aos_before_start=True, los_after_end=False),
        Pass(40000, START + timedelta(seconds=600.5), START + timedelta(seconds=900),
             START + timedelta(seconds=1200.25), 45.5, 10.0, 170.0, aos_before_start=False, los_after_end=False),
        Pass(25544, START + timedelta(seconds=3000), START + timedelta(seconds=3300), None, 10.0, 200.0, None,
             aos_before_start=False, los_after_end=True),
    ]
    assert passes[1].duration_s == pytest.approx(599.75)
    assert passes[-1].catalog_number == 25544
    assert [p.catalog_number for p in passes[1:]] == [40000, 25544]
    assert max(passes, key=lambda p: p.max_elevation_deg).catalog_number == 40000
    with pytest.raises(IndexError):
        passes[3]


def test_concat_merges_parts_in_order_and_empty_lists_work() -> None:
    cols = _columns()
    one = {k: v[:1] for k, v in cols.items()}
    two = {k: v[1:] for k, v in cols.items()}
    merged = PassList.concat(START, 3200.0, [one, {}, two])
    assert [p.catalog_number for p in merged] == [7530, 40000, 25544]
    empty = PassList(START, 10.0)
    assert len(empty) == 0 and list(empty) == [] and empty[:] == []


def test_columns_gathered_in_parts_past_their_capacity_sort_like_one_list() -> None:
    """PassColumns (the search's gatherer) grows past its first capacity and sorts what it gathered exactly as
    PassList sorts the same rows given at once: by AOS (TCA when AOS is unknown), then catalog number."""
    from nfwserver.tracking.pass_records import PassColumns

    rng = np.random.default_rng(7)
    parts = []
    for size in (1100, 0, 1500, 3000, 1):  # the first part alone is past the capacity (a forked worker's share)
        tca = rng.uniform(-200.0, 86700.0, size).round(0)  # rounded: equal times, ordered by number
        aos = np.where(rng.random(size) < 0.1, NAN, tca - 300.0)
        parts.append({"catalog_number": rng.integers(1, 60000, size), "aos_s": aos, "tca_s": tca,
                      "los_s": tca + 300.0, "max_elevation_deg": rng.uniform(0, 90, size),
                      "aos_azimuth_deg": rng.uniform(0, 360, size), "los_azimuth_deg": rng.uniform(0, 360, size)})
    gathered = PassColumns(capacity=1024)
    for part in parts:
        gathered.add(part)
    gathered.add({})
    assert len(gathered) == 5601
    result = gathered.pass_list(START, 86400.0)
    expected = PassList(START, 86400.0, {k: np.concatenate([p[k] for p in parts]) for k in parts[0]})
    assert len(result) == 5601
    for name, column in expected.columns.items():
        np.testing.assert_array_equal(result.columns[name], column)
    keys = [(p.aos or p.tca, p.catalog_number) for p in result]
    assert keys == sorted(keys)
    assert len(gathered) == 0 and len(gathered.pass_list(START, 86400.0)) == 0
