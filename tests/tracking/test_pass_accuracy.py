"""Pass times and maximum elevations against skyfield's geometry sampled densely around each event.

The oracle never uses our propagation: skyfield's own SGP4 and frames give the elevation at any
instant; crossings are located by nested dense sampling of that elevation (to well under a
millisecond), maxima by nested dense sampling of the whole pass.  Goals (issue 17): every AOS/LOS
within 10 ms of the true crossing, every maximum elevation within 0.001 deg of the true maximum,
TCA within 1 s for passes shorter than an hour, grazing, near-zenith and multi-hour passes included.
"""

from __future__ import annotations

from datetime import datetime, timedelta, timezone

import numpy as np
import pytest

from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import Pass, find_passes
from tests.conftest import DATA
from tests.tracking.skyfield_oracle import TS, skyfield_satellite, skyfield_topos

START = datetime(2026, 5, 8, tzinfo=timezone.utc)
END = START + timedelta(hours=24)
OBSERVER = Observer(52.2, 0.12, 20.0)
SETS = load_element_file(DATA / "active.txt").sets
BY_NUMBER = {s.catalog_number: s for s in SETS}
DUT1 = float(TS.from_datetime(START + timedelta(hours=12)).dut1)  # skyfield's UT1-UTC, passed to us too
EVENT_TOL_S = 0.010
MAX_EL_TOL_DEG = 0.001
GEOMETRY_DEG = 2e-6


class Oracle:
    """Skyfield elevation of one satellite, many instants at once."""

    def __init__(self, catalog_number: int) -> None:
        topos = skyfield_topos(OBSERVER)
        self.topos = topos
        self.rel = skyfield_satellite(BY_NUMBER[catalog_number]) - topos

    def elevation(self, base: datetime, offsets_s: np.ndarray) -> np.ndarray:
        t = TS.from_datetime(base)
        t = TS.tt_jd(t.whole, t.tt_fraction + np.asarray(offsets_s) / 86400.0)  # split date: ps resolution
        return self.rel.at(t).frame_latlon(self.topos)[0].degrees

    def crossing(self, lo: datetime, hi: datetime) -> datetime:
        """The sign change of the elevation in [lo, hi] (one expected), to 1 microsecond: eleven
        samples per round, each round keeping the sample interval that holds the change."""
        a, b = 0.0, (hi - lo).total_seconds()
        while b - a > 1e-6:
            x = np.linspace(a, b, 11)
            e = self.elevation(lo, x)
            k = np.flatnonzero(np.sign(e[1:]) != np.sign(e[:-1]))
            assert len(k), f"no crossing in [{lo}, {hi}]"
            a, b = x[k[0]], x[k[0] + 1]
        return lo + timedelta(seconds=0.5 * (a + b))

    def maximum(self, lo: datetime, hi: datetime) -> tuple[datetime, float]:
        """Time and value of the highest elevation in [lo, hi], to 1 ms: eleven samples per round,
        each round keeping the neighbours of the best one."""
        a, b = 0.0, (hi - lo).total_seconds()
        best_x, best_e = a, -90.0
        while b - a > 1e-3:
            x = np.linspace(a, b, 11)
            e = self.elevation(lo, x)
            k = int(np.argmax(e))
            best_x, best_e = float(x[k]), float(e[k])
            a, b = x[max(k - 1, 0)], x[min(k + 1, 10)]
        return lo + timedelta(seconds=best_x), best_e


def _check_pass(p: Pass) -> None:
    oracle = Oracle(p.catalog_number)
    true_tca = p.tca
    if p.aos is not None and p.los is not None:  # otherwise the TCA is the highest point searched
        true_tca, true_max = oracle.maximum(p.aos, p.los)
        assert abs(p.max_elevation_deg - true_max) < MAX_EL_TOL_DEG, (p, true_max)
        if p.duration_s < 3600.0:
            assert abs((p.tca - true_tca).total_seconds()) < 1.0, (p, true_tca)
    for when, lo, hi in ((p.aos, -1.0, None), (p.los, None, 1.0)):
        if when is None:
            continue
        bracket = (when + timedelta(seconds=lo), true_tca) if lo else (true_tca, when + timedelta(seconds=hi))
        true_when = oracle.crossing(*bracket)
        off = abs((when - true_when).total_seconds())
        # Slow satellites cross the horizon at a few 1e-5 deg/s: there the two geometries' 1e-6 deg
        # agreement (test_look_angles) is the limit, so the elevation at our event is checked instead.
        assert off < EVENT_TOL_S or abs(oracle.elevation(when, np.zeros(1))[0]) < GEOMETRY_DEG, (p, true_when)


@pytest.fixture(scope="module")
def catalog_passes() -> list[Pass]:
    return find_passes(SETS[:2000] + [BY_NUMBER[14129]], OBSERVER, START, END, ut1_utc=DUT1)


def test_a_sample_of_ordinary_passes_is_exact(catalog_passes: list[Pass]) -> None:
    sample = catalog_passes[::97]
    assert len(sample) > 100
    for p in sample:
        _check_pass(p)


def test_grazing_passes_are_exact(catalog_passes: list[Pass]) -> None:
    grazing = [p for p in catalog_passes if p.max_elevation_deg < 0.05]
    assert len(grazing) >= 5, "the catalog should hold grazing passes"
    for p in grazing:
        _check_pass(p)


def test_near_zenith_passes_are_exact(catalog_passes: list[Pass]) -> None:
    high = [p for p in catalog_passes if p.max_elevation_deg > 88.0]
    assert len(high) >= 3
    for p in high:
        _check_pass(p)


def test_multi_hour_heo_pass_of_ao10() -> None:
    passes = find_passes([BY_NUMBER[14129]], OBSERVER, START, END, ut1_utc=DUT1)
    longest = max(passes, key=lambda p: p.duration_s or 0.0)
    assert longest.duration_s > 5 * 3600.0
    for p in passes:
        _check_pass(p)


def test_no_pass_found_by_a_dense_scan_is_missed(catalog_passes: list[Pass]) -> None:
    """Skyfield sampled every 20 s for a spread of orbits: each sign change has our event next to it."""
    numbers = [s.catalog_number for s in SETS[:2000:100]] + [14129]
    offsets = np.arange(0.0, 86400.0, 20.0)
    checked = 0
    for number in numbers:
        e = Oracle(number).elevation(START, offsets)
        k = np.flatnonzero(np.sign(e[1:]) != np.sign(e[:-1]))
        ours = [w for p in catalog_passes if p.catalog_number == number for w in (p.aos, p.los) if w is not None]
        for i in k:
            when = START + timedelta(seconds=float(offsets[i]))
            assert any(-1.0 <= (w - when).total_seconds() <= 21.0 for w in ours), (number, when)
            checked += 1
    assert checked > 40
