"""Pass prediction against skyfield's find_events and against a dense brute-force search."""

from __future__ import annotations

import sys
from datetime import datetime, timedelta, timezone

import numpy as np
import pytest

from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.look_angles import LookAngleCalculator, look_angles_array
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
from nfwserver.tracking.timescale import julian_date
from tests.conftest import DATA
from tests.tracking.skyfield_oracle import TS, skyfield_satellite, skyfield_topos

START = datetime(2026, 5, 8, tzinfo=timezone.utc)
END = START + timedelta(hours=24)
VISUAL = load_element_file(DATA / "visual.txt").sets
ACTIVE = {s.catalog_number: s for s in load_element_file(DATA / "active.txt").sets}
OBSERVERS = [Observer(52.2, 0.12, 20.0), Observer(-33.87, 151.21, 40.0), Observer(78.22, 15.63, 10.0)]


def _our_events(passes, catnr):
    events = []
    for p in passes:
        if p.catalog_number != catnr:
            continue
        if p.aos is not None and START <= p.aos <= END:
            events.append((0, p.aos))
        if START <= p.tca <= END:
            events.append((1, p.tca))
        if p.los is not None and START <= p.los <= END:
            events.append((2, p.los))
    return events


@pytest.mark.parametrize("observer", OBSERVERS, ids=["north", "south", "polar"])
def test_same_events_as_skyfield_with_a_flat_horizon(observer: Observer) -> None:
    sats = VISUAL[:25] + [ACTIVE[25544], ACTIVE[27607]]
    passes = find_passes(sats, observer, START, END)
    topos = skyfield_topos(observer)
    total = 0
    for es in sats:
        t, kinds = skyfield_satellite(es).find_events(topos, TS.from_datetime(START), TS.from_datetime(END), 0.0)
        ref = [(int(k), x.utc_datetime()) for k, x in zip(kinds, t)]
        ours = _our_events(passes, es.catalog_number)
        assert [k for k, _ in ours] == [k for k, _ in ref], es.name
        for (_, a), (_, b) in zip(ours, ref):
            assert abs((a - b).total_seconds()) < 0.5, es.name
        total += len(ref)
    assert total > 300


def test_in_progress_pass_gets_its_true_aos_before_the_window() -> None:
    observer = OBSERVERS[0]
    iss = ACTIVE[25544]
    full = find_passes([iss], observer, START, END)
    p = full[3]
    mid = p.aos + (p.los - p.aos) / 2
    cut = find_passes([iss], observer, mid, mid + timedelta(hours=1))
    first = cut[0]
    assert first.aos_before_start and not first.los_after_end
    assert abs((first.aos - p.aos).total_seconds()) < 0.01
    assert abs((first.los - p.los).total_seconds()) < 0.01
    tail = find_passes([iss], observer, mid - timedelta(hours=1), mid)
    assert tail[-1].los_after_end and abs((tail[-1].los - p.los).total_seconds()) < 0.01


def test_geostationary_objects_give_no_bogus_events() -> None:
    geo = [s for s in ACTIVE.values() if abs(s.mean_motion_rev_per_day - 1.0027) < 0.0005 and s.eccentricity < 5e-4]
    observer = OBSERVERS[0]
    calc = LookAngleCalculator(observer)
    passes = find_passes(geo[:40], observer, START, END)
    for p in passes:  # whatever is reported must be a real crossing
        for when in (p.aos, p.los):
            if when is not None:
                before = calc.compute(ACTIVE[p.catalog_number].satrec, when - timedelta(seconds=1)).elevation_deg
                after = calc.compute(ACTIVE[p.catalog_number].satrec, when + timedelta(seconds=1)).elevation_deg
                assert before * after < 0
    # one always above the horizon has one pass, with neither AOS nor LOS (tests/tracking/test_always_up.py)
    up = [s for s in geo[:40] if calc.compute(s.satrec, START).elevation_deg > 1.0]
    assert up and [(p.aos, p.los) for p in passes if p.catalog_number == up[0].catalog_number] == [(None, None)]


def _brute_force(es, observer, horizon, step_s=0.5):
    t = np.arange(0.0, (END - START).total_seconds() + step_s, step_s)
    jd, fr = julian_date(START)
    la = look_angles_array([es.satrec], observer, np.full(t.shape, jd), fr + t / 86400.0)
    f = la.elevation_deg[0] - horizon.min_elevation_array(la.azimuth_deg[0])
    up = f > 0
    idx = np.flatnonzero(up[1:] != up[:-1])
    # Linear interpolation between the dense samples.
    times = t[idx] + f[idx] / (f[idx] - f[idx + 1]) * step_s
    return [(bool(up[i + 1]), START + timedelta(seconds=float(x))) for i, x in zip(idx, times)]


def test_non_flat_horizon_matches_a_dense_brute_force_search() -> None:
    horizon = HorizonTable([(0, 5), (45, 12), (90, 2), (135, 20), (180, 8), (225, 0), (270, 15), (315, 3)])
    observer = OBSERVERS[0]
    sats = VISUAL[:30] + [ACTIVE[25544]]
    passes = find_passes(sats, observer, START, END, horizon=horizon)
    checked = 0
    for es in sats:
        ref = _brute_force(es, observer, horizon)
        ours = []
        for p in (q for q in passes if q.catalog_number == es.catalog_number):
            if p.aos is not None and START < p.aos < END:
                ours.append((True, p.aos))
            if p.los is not None and START < p.los < END:
                ours.append((False, p.los))
        assert [k for k, _ in ours] == [k for k, _ in ref], es.name
        for (_, a), (_, b) in zip(ours, ref):
            assert abs((a - b).total_seconds()) < 0.1, es.name
        checked += len(ref)
    assert checked > 100
    for p in passes:
        assert p.max_elevation_deg > horizon.minimum


def test_short_pass_between_grid_points_is_found() -> None:
    # Choose the lowest ISS pass of the day and place a flat horizon just under its maximum, so
    # the remaining pass lasts only seconds.
    observer = OBSERVERS[0]
    iss = ACTIVE[25544]
    low = min(find_passes([iss], observer, START, END), key=lambda p: p.max_elevation_deg)
    horizon = HorizonTable([(0, low.max_elevation_deg - 0.01)])
    short = [p for p in find_passes([iss], observer, START, END, horizon=horizon)
             if abs((p.tca - low.tca).total_seconds()) < 60]
    assert len(short) == 1
    assert 0 < short[0].duration_s < 30
    assert short[0].aos < short[0].tca < short[0].los


@pytest.mark.skipif(sys.platform == "win32", reason="fork")
def test_worker_processes_give_the_same_passes() -> None:
    """Run in a fresh single-threaded interpreter: forking is refused in threaded processes."""
    import subprocess

    script = """
import sys
from datetime import datetime, timedelta, timezone
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
sats = load_element_file(sys.argv[1]).sets[:500]
start = datetime(2026, 5, 8, tzinfo=timezone.utc)
obs = Observer(52.2, 0.12, 20.0)
serial = find_passes(sats, obs, start, start + timedelta(hours=6))
parallel = find_passes(sats, obs, start, start + timedelta(hours=6), workers=2)
assert len(serial) > 100 and len(parallel) == len(serial), (len(serial), len(parallel))
import numpy as np
for name, column in serial.columns.items():  # bit for bit: each worker searches whole chunks of one process
    assert np.array_equal(column, parallel.columns[name], equal_nan=True), name
print("same", len(serial))
"""
    done = subprocess.run([sys.executable, "-c", script, str(DATA / "active.txt")], capture_output=True, text=True,
                          timeout=100)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("same ")


@pytest.mark.skipif(sys.platform == "win32", reason="fork")
@pytest.mark.parametrize("where", ["child", "parent"])
def test_a_failure_in_a_worker_process_reaches_the_caller_at_once(where) -> None:
    """A worker whose search fails (here: a satellite whose model cannot be made, in a forked worker or in the
    command's own process) ends the search with that exception: no hang, no silent gap, and the other worker
    stops after the chunk it is on (200 models; 400 if it had taken a second one before the failure was known)
    instead of searching the rest alone (800: the code before did that)."""
    import subprocess

    script = """
import multiprocessing, os, signal, sys
from datetime import datetime, timedelta, timezone
from nfwserver.tracking.elements import load_element_file
# Forked workers that ignore SIGTERM (as after a station ran in the process that started this one): ending them
# does not stop them early, so what "models made" counts is the stop the failing worker asked for.
signal.signal(signal.SIGTERM, signal.SIG_IGN)
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.passes import find_passes
PARENT = os.getpid()
# models made: shared, without a lock (one process writes it; a worker ended mid-update must not leave a lock held)
made = multiprocessing.get_context("fork").RawValue("i", 0)

class Failing:  # a set whose model fails in the chosen process only
    def __init__(self, element_set):
        self._set = element_set
    def __getattr__(self, name):
        return getattr(self._set, name)
    def transient_satrec(self):
        if (os.getpid() == PARENT) == (sys.argv[2] == "parent"):
            raise RuntimeError("this model cannot be made")
        made.value += 1
        return self._set.transient_satrec()

sats = [Failing(s) for s in load_element_file(sys.argv[1]).sets[:1000]]
start = datetime(2026, 5, 8, tzinfo=timezone.utc)
try:
    find_passes(sats, Observer(52.2, 0.12, 20.0), start, start + timedelta(days=2), workers=2)
except RuntimeError as exc:
    print("raised", exc, "with models made:", made.value)
"""
    done = subprocess.run([sys.executable, "-c", script, str(DATA / "active.txt"), where], capture_output=True,
                          text=True, timeout=100)
    assert done.returncode == 0, done.stderr
    said, _, made = done.stdout.strip().rpartition(" ")
    assert said == "raised this model cannot be made with models made:", done.stdout
    assert int(made) <= 400, done.stdout


@pytest.mark.skipif(sys.platform == "win32", reason="fork")
def test_a_worker_killed_before_it_answers_is_one_clear_error() -> None:
    """A forked worker that dies (out of memory, a signal) ends the search with an OSError naming its exit
    status, which the command reports in one line, instead of a bare EOFError traceback."""
    import subprocess

    script = """
import os, sys
from datetime import datetime, timezone, timedelta
from nfwserver.tracking import pass_workers, passes
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
pass_workers.fork_worker = lambda search, satellites, args, results: os._exit(3)  # dies at once, in the child
sats = load_element_file(sys.argv[1]).sets[:500]
start = datetime(2026, 5, 8, tzinfo=timezone.utc)
try:
    passes.find_passes(sats, Observer(52.2, 0.12, 20.0), start, start + timedelta(hours=6), workers=2)
except OSError as exc:
    print("raised", exc)
"""
    done = subprocess.run([sys.executable, "-c", script, str(DATA / "active.txt")], capture_output=True, text=True,
                          timeout=100)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "raised a pass-search worker process ended without its answer (exit status 3)"


def test_element_sets_and_their_models_give_the_same_passes_and_no_model_is_kept() -> None:
    """Element sets are grouped by their own fields and propagated by models made for the search only;
    the passes are exactly those of the same satellites given as sgp4 Satrecs."""
    sets = load_element_file(DATA / "active.txt").sets[:400]  # fresh sets: no model made yet
    observer = OBSERVERS[0]
    from_sets = find_passes(sets, observer, START, START + timedelta(hours=6))
    assert all(s._satrec is None for s in sets)  # a catalog-wide search holds one chunk's models at a time
    from_models = find_passes([s.satrec for s in sets], observer, START, START + timedelta(hours=6))
    assert len(from_sets) > 100 and list(from_sets) == list(from_models)


def test_sgp4s_pure_python_model_finds_the_same_passes(monkeypatch) -> None:
    """The start-up self-check's last resort (sgp4_selfcheck, mode "python") swaps in sgp4's pure-Python
    Satrec and SatrecArray; the search must run on them and agree with the compiled extension."""
    import sgp4.model

    from nfwserver.tracking import look_angles, pass_screen

    # As the self-check does before these modules import it: every module's SatrecArray is the pure one.
    monkeypatch.setattr(pass_screen, "SatrecArray", sgp4.model.SatrecArray)
    monkeypatch.setattr(look_angles, "SatrecArray", sgp4.model.SatrecArray)
    sets = VISUAL[:3]
    pure = find_passes([sgp4.model.Satrec.twoline2rv(s.line1, s.line2) for s in sets], OBSERVERS[0], START,
                       START + timedelta(hours=8))
    compiled = find_passes(sets, OBSERVERS[0], START, START + timedelta(hours=8))
    assert len(pure) == len(compiled) >= 3
    for a, b in zip(pure, compiled):
        assert a.catalog_number == b.catalog_number
        assert abs((a.aos - b.aos).total_seconds()) < 1e-3 and abs((a.los - b.los).total_seconds()) < 1e-3
        assert abs(a.max_elevation_deg - b.max_elevation_deg) < 1e-6


@pytest.mark.parametrize("horizon", [None, HorizonTable([(0, 4.0), (120, 11.0), (250, 1.5)])])
def test_refining_several_chunks_together_changes_no_bit(monkeypatch, horizon) -> None:
    """Chunks refined together, each satellite against its own chunk's reference instant, and rounds taken in
    slices give bit for bit the passes of refining every chunk alone in one slice."""
    import nfwserver.tracking.pass_refine as pass_refine
    import nfwserver.tracking.passes as passes

    sets = list(ACTIVE.values())[::25]  # ~600 objects of every kind: low, eccentric, geosynchronous
    start = datetime(2026, 5, 8, 7, 13, 22, 123456, tzinfo=timezone.utc)
    observer = Observer(47.3, -122.5, 120.0)
    monkeypatch.setattr(passes, "_CHUNK", 40)
    found = []
    for batch, slice_size in ((1, 10**9), (10**9, 10**9), (3000, 257)):  # alone, all together, in slices
        monkeypatch.setattr(passes, "_BATCH_BRACKETS", batch)
        monkeypatch.setattr(pass_refine, "_SLICE", slice_size)
        found.append(find_passes(sets, observer, start, start + timedelta(hours=30), horizon=horizon).columns)
    assert len(found[0]["tca_s"]) > 1000
    for other in found[1:]:
        for name, column in found[0].items():
            assert np.array_equal(column, other[name], equal_nan=True), name
