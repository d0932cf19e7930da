"""Limits on one element source (size in bytes, count of sets) and refreshes that never hold up a tick
(#23 item 16).  Real files: a sparse 1 GiB file made with truncate, /dev/zero, generated catalogs."""

from __future__ import annotations

import logging
import os
import threading
import time
import tracemalloc
from datetime import datetime, timezone
from pathlib import Path

import pytest

from nfwserver.app.element_sources import SourceError, SourceLimits, fetch_all, read_source
from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.tle import tle_checksum
from tests.app.element_formats import omm_csv, omm_json
from tests.conftest import DATA


@pytest.fixture
def sparse_gib(tmp_path) -> Path:
    path = tmp_path / "huge.txt"
    with open(path, "wb") as f:
        f.truncate(2**30)  # 1 GiB, no block written
    return path


def test_a_sparse_gibibyte_file_is_refused_unread_naming_the_file_and_the_limit(sparse_gib) -> None:
    tracemalloc.start()
    started = time.perf_counter()
    try:
        with pytest.raises(SourceError) as refused:
            read_source(str(sparse_gib))
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert time.perf_counter() - started < 1.0
    assert peak < 2**20  # nothing near the file's size was read
    message = str(refused.value)
    assert message == (f"{sparse_gib} is larger than 64 MiB, the limit for one element source "
                       "([elements] max_source_mib)")


def test_a_source_that_is_not_a_regular_file_is_refused_at_once(tmp_path) -> None:
    """/dev/zero would never end and a FIFO's open would wait for a writer for ever (the refresher thread with
    it): both are refused unread, in one sentence."""
    fifo = tmp_path / "elements.fifo"
    os.mkfifo(fifo)
    for path in ("/dev/zero", str(fifo)):
        outcome: list[BaseException] = []

        def read(path: str = path, outcome: list[BaseException] = outcome) -> None:
            try:
                read_source(path, limits=SourceLimits(max_bytes=2**20))
            except BaseException as exc:
                outcome.append(exc)

        reader = threading.Thread(target=read, daemon=True)  # a blocked open must not hang the suite
        reader.start()
        reader.join(30.0)
        assert not reader.is_alive(), f"reading {path} blocked"
        assert isinstance(outcome[0], SourceError)
        assert str(outcome[0]) == f"cannot read {path}: it is not a regular file"


def test_too_many_sets_in_one_source_are_refused_in_every_format(tmp_path) -> None:
    limits = SourceLimits(max_sets=100)
    with pytest.raises(SourceError) as refused:
        read_source(str(DATA / "visual.txt"), limits=limits)  # 148 TLEs
    assert str(refused.value) == (f"{DATA / 'visual.txt'} holds more than 100 element sets, the limit for one "
                                  "element source ([elements] max_source_sets)")
    (tmp_path / "x.json").write_text(omm_json(DATA / "visual.txt"))
    (tmp_path / "x.csv").write_text(omm_csv(DATA / "visual.txt"))
    for name in ("x.json", "x.csv"):
        with pytest.raises(SourceError, match="holds more than 100 element sets"):
            read_source(str(tmp_path / name), limits=limits)
    assert len(read_source(str(DATA / "visual.txt"), limits=SourceLimits(max_sets=148)).sets) == 148


def test_a_download_over_the_limit_is_refused(http_server) -> None:
    with pytest.raises(SourceError, match=r"active\.txt is larger than 100,000 bytes, the limit for one element"):
        read_source(f"{http_server}/active.txt", limits=SourceLimits(max_bytes=100_000))


def test_the_station_starts_without_the_oversized_file_and_says_why(tmp_path, sparse_gib, caplog) -> None:
    config = parse_config(f'[elements]\nfiles = ["{sparse_gib}", "{DATA / "visual.txt"}"]\nstore = "none"\n'
                          "use_bundled = false\n")
    station = Station(config, VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc)),
                      transport=FakeDdeSystem().server_transport())
    with caplog.at_level(logging.WARNING):
        station.start()
    try:
        assert len(station.catalog) == 148
    finally:
        station.stop()
    warnings = [r.getMessage() for r in caplog.records if "huge.txt" in r.getMessage()]
    assert warnings == [f"element source unavailable: {sparse_gib} is larger than 64 MiB, the limit for one "
                        "element source ([elements] max_source_mib)"]


def test_limits_come_from_the_configuration(tmp_path, capsys) -> None:
    config = tmp_path / "c.toml"
    config.write_text(f'[elements]\nmax_source_sets = 10\nstore = "{tmp_path / "store.txt"}"\n')
    assert main(["elements", "update", str(DATA / "visual.txt"), "--config", str(config)]) == 1
    err = capsys.readouterr().err
    assert err == (f"nfwserver: {DATA / 'visual.txt'} holds more than 10 element sets, the limit for one element "
                   "source ([elements] max_source_sets)\n")
    assert not (tmp_path / "store.txt").exists()
    result = fetch_all(files=(str(DATA / "visual.txt"),), use_bundled=False, limits=SourceLimits(max_sets=10))
    assert result.sets == [] and len(result.failed) == 1


# -- a refresh never holds up the publish thread ---------------------------------------------------------


def _catalog_text(copies: int, shift_days: float) -> str:
    """active.txt ``copies`` times over with catalog numbers 1..N and epochs moved by ``shift_days``."""
    lines = (DATA / "active.txt").read_text().splitlines()
    out, number = [], 0
    for _ in range(copies):
        for k in range(0, len(lines) - 2, 3):
            number += 1
            cat = f"{number:05d}"
            day = float(lines[k + 1][20:32]) + shift_days
            one = lines[k + 1][:2] + cat + lines[k + 1][7:20] + f"{day:012.8f}" + lines[k + 1][32:68]
            two = lines[k + 2][:2] + cat + lines[k + 2][7:68]
            out += [f"SAT {number}", one + str(tle_checksum(one)), two + str(tle_checksum(two))]
    return "\n".join(out) + "\n"


def test_a_tick_after_a_refresh_of_a_large_catalog_costs_what_any_tick_costs(tmp_path) -> None:
    """On the unfixed code the refresh swapped in bare element sets, and the first tick after it (the publish
    thread) named all 46,041 satellites: 0.3 s and more.  Now the refreshing thread names them before the swap."""
    keps = tmp_path / "keps.txt"
    keps.write_text(_catalog_text(3, 0.0))
    config = parse_config(f'[elements]\nfiles = ["{keps}"]\nstore = "none"\nuse_bundled = false\n'
                          "[server]\nsatellite = 1\ntune = true\n")
    station = Station(config, VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc)),
                      transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        assert len(station.catalog) == 46041
        station.core.tick()  # the live catalog has been read: its names exist
        keps.write_text(_catalog_text(3, 0.5))
        done = []
        refresher = threading.Thread(target=lambda: done.append(station.refresh_elements()))
        refresher.start()
        refresher.join()
        assert len(done[0].updated) == 46041
        started = time.perf_counter()
        sample = station.core.tick()  # as the publish thread would, right after the swap
        took = time.perf_counter() - started
    finally:
        station.stop()
    assert sample.text.startswith("SAT-1 AZ:")
    assert took < 0.05, f"the first tick after the refresh took {took * 1000:.0f} ms"


def test_an_unchanged_refresh_swaps_nothing(tmp_path) -> None:
    keps = tmp_path / "keps.txt"
    keps.write_text((DATA / "visual.txt").read_text())
    config = parse_config(f'[elements]\nfiles = ["{keps}"]\nstore = "none"\nuse_bundled = false\n')
    station = Station(config, VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc)),
                      transport=FakeDdeSystem().server_transport())
    station.start()
    try:
        before = station.core.state.generation
        station.refresh_elements()
        assert station.core.state.generation == before
    finally:
        station.stop()
