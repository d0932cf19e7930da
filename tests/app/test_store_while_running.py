"""``nfwserver elements update`` while the station runs: the station takes the stored catalog within seconds
(#34 item 3).  A set added to the store could not be selected by ``SAT=`` after 10 s, nor after SIGHUP; only a
restart helped.  The real command writes the store; the station runs on a virtual clock."""

from __future__ import annotations

from datetime import datetime, timezone

from nfwserver.app.station import Station
from nfwserver.cli import main
from nfwserver.clock import VirtualClock
from nfwserver.config.loader import parse_config
from nfwserver.fake_dde import FakeDdeSystem
from nfwserver.tracking.elements import load_element_file
from tests.conftest import DATA, advance_until

START = datetime(2026, 5, 8, 12, tzinfo=timezone.utc)


def _split_visual(tmp_path):
    """The visual set in two files: the first 100 sets, and the rest (which the store gets later)."""
    sets = load_element_file(DATA / "visual.txt").sets
    first, later = tmp_path / "first.txt", tmp_path / "later.txt"
    first.write_text("".join(es.tle_text() for es in sets[:100]))
    later.write_text("".join(es.tle_text() for es in sets[100:]))
    return first, later, [es.catalog_number for es in sets[100:]]


def _station(tmp_path, store):
    config = parse_config(f'[observer]\nlocation = "JO02ae"\n[elements]\nuse_bundled = false\nstore = "{store}"\n'
                          '[server]\nstate_file = "none"\n')
    clock = VirtualClock(START)
    return Station(config, clock, transport=FakeDdeSystem().server_transport()), clock


def test_a_set_added_by_elements_update_is_selectable_within_seconds(tmp_path, capsys) -> None:
    first, later, added = _split_visual(tmp_path)
    store = tmp_path / "elements.txt"
    assert main(["elements", "update", str(first), "--store", str(store)]) == 0
    station, clock = _station(tmp_path, store)
    station.start()
    try:
        assert len(station.catalog) == 100
        assert not station.core.command(f"SAT={added[0]}").accepted  # not in the catalog yet
        assert main(["elements", "update", str(later), "--store", str(store)]) == 0
        started = clock.monotonic()
        assert advance_until(clock, lambda: added[-1] in station.catalog, limit_s=10.0)
        assert clock.monotonic() - started <= 5.0  # the watcher's 2 s look and its settling
        assert station.core.command(f"SAT={added[0]}").ok
        assert len(station.catalog) == len(load_element_file(DATA / "visual.txt").sets)
    finally:
        station.stop()


def test_sighup_reads_the_store_at_once(tmp_path, capsys) -> None:
    first, later, added = _split_visual(tmp_path)
    store = tmp_path / "elements.txt"
    assert main(["elements", "update", str(first), "--store", str(store)]) == 0
    station, clock = _station(tmp_path, store)
    station.start()
    try:
        assert main(["elements", "update", str(later), "--store", str(store)]) == 0
        station.reload_config()  # what SIGHUP calls (a station on built-in defaults has no file to read)
        assert advance_until(clock, lambda: added[0] in station.catalog, step_s=0.05, limit_s=0.5)
    finally:
        station.stop()
