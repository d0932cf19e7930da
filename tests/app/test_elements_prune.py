"""``nfwserver elements prune`` (InstantTrack OLD and CRASH), the bundled set and stable DDE names."""

from __future__ import annotations

import dataclasses
from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.app.element_sources import bundled_elements
from nfwserver.app.element_store import ElementStore
from nfwserver.cli import main
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import ElementSet, load_element_file, load_elements
from nfwserver.tracking.tle import parse_tle
from tests.conftest import DATA

NOW = datetime.now(timezone.utc)


def _set(catnr: int, age_days: float, name: str, **changes) -> str:
    """ISS's elements under another number and name, with the epoch ``age_days`` before now."""
    iss = next(s for s in load_element_file(DATA / "visual.txt").sets if s.catalog_number == 25544)
    fields = dataclasses.replace(parse_tle(iss.line1, iss.line2), catalog_number=catnr,
                                 epoch=NOW - timedelta(days=age_days), **changes)
    return ElementSet.from_fields(name, fields).tle_text()


@pytest.fixture
def store(tmp_path):
    path = tmp_path / "stored.txt"
    # 17.5 rev/day puts the semi-major axis at about 6220 km, below the Earth's 6378 km radius.
    path.write_text(_set(90001, 1, "FRESH") + _set(90002, 40, "OLD") + _set(90003, 10, "OLD-ISH")
                    + _set(90004, 1, "FALLEN", mean_motion_rev_per_day=17.5))
    return path


def test_prune_removes_decayed_and_old_sets(store, capsys) -> None:
    assert main(["elements", "prune", "--store", str(store)]) == 0
    out, err = capsys.readouterr()
    assert out == f"removed 1 decayed and 1 older than 30 days; 2 sets remain in {store}\n"
    assert "90004 FALLEN: decayed" in err
    assert sorted(s.catalog_number for s in ElementStore(store).load()) == [90001, 90003]
    # no temporary file left (the lock's sidecar stays: removing it would race another writer)
    assert sorted(p.name for p in store.parent.iterdir()) == [".stored.txt.lock", "stored.txt"]


def test_prune_age_is_configurable_and_the_configured_store_is_used(store, tmp_path, capsys) -> None:
    config = tmp_path / "c.toml"
    config.write_text(f'[elements]\nstore = "{store.name}"\n')
    assert main(["elements", "prune", "--config", str(config), "--days", "5"]) == 1  # 3 of 4: no terminal, no --yes
    assert capsys.readouterr().err == (f"nfwserver: pruning would remove 3 of the 4 sets in {store}; give --yes to "
                                       "confirm (--dry-run lists them)\n")
    assert len(ElementStore(store).load()) == 4
    assert main(["elements", "prune", "--config", str(config), "--days", "5", "--yes"]) == 0
    assert "removed 1 decayed and 2 older than 5 days; 1 sets remain" in capsys.readouterr().out
    assert [s.name for s in ElementStore(store).load()] == ["FRESH"]
    before = store.read_bytes()
    assert main(["elements", "prune", "--config", str(config), "--days", "5"]) == 0
    assert store.read_bytes() == before


@pytest.mark.parametrize("days", ["0", "-3", "abc"])
def test_prune_bad_days_is_a_usage_error(store, days, capsys) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["elements", "prune", "--store", str(store), f"--days={days}"])
    assert exit_info.value.code == 2 and "--days" in capsys.readouterr().err


def test_prune_of_a_missing_store_is_one_sentence(tmp_path, capsys) -> None:
    assert main(["elements", "prune", "--store", str(tmp_path / "none.txt")]) == 1
    assert "does not exist yet" in capsys.readouterr().err


def test_bundled_set_holds_every_satellite_with_a_built_in_channel() -> None:
    from nfwserver.radio.defaults import DEFAULT_CHANNELS

    result = bundled_elements()
    assert not result.rejected and result.bundled == len(result.sets)
    assert set(DEFAULT_CHANNELS) <= {s.catalog_number for s in result.sets}


def test_well_known_dde_names_survive_an_element_update() -> None:
    catalog = Catalog(bundled_elements().sets)
    before = {s.catalog_number: s.dde_name for s in catalog}
    assert before[43017] == "AO-91" and before[44909] == "RS-44" and before[25544] == "ISS"
    # The same satellites as other sources name them: CelesTrak's active group, a rocket-stage name for
    # RS-44, and a newer ISS module listed before the station itself.
    renamed = load_elements(_set(44909, 0, "BREEZE-KM R/B") + _set(43017, 0, "RADFXSAT (FOX-1B)")
                            + _set(25544, 0, "ISS (NAUKA)") + _set(7530, 0, "OSCAR 7")).sets
    summary = catalog.update([*renamed, *load_element_file(DATA / "active.txt").sets])
    assert {44909, 43017, 25544, 7530} <= set(summary.updated)
    after = {s.catalog_number: s.dde_name for s in catalog if s.catalog_number in before}
    assert after == before
    names = [s.dde_name.upper() for s in catalog]
    assert len(names) == len(set(names))


def test_a_user_override_still_wins_over_a_well_known_name() -> None:
    catalog = Catalog(bundled_elements().sets, dde_names={43017: "FOX1B", 40967: "AO-91"})
    assert catalog.get(43017).dde_name == "FOX1B" and catalog.get(40967).dde_name == "AO-91"
    catalog = Catalog(bundled_elements().sets, dde_names={40967: "RS-44"})
    assert catalog.get(40967).dde_name == "RS-44" and catalog.get(44909).dde_name != "RS-44"


# -- safe pruning (#25 item 3) ----------------------------------------------------------------------------


def test_dry_run_lists_what_would_go_and_changes_nothing(store, capsys) -> None:
    before = store.read_bytes()
    assert main(["elements", "prune", "--store", str(store), "--days", "5", "--dry-run"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in out[:-1]] == ["90004", "90002", "90003"]
    assert out[0].endswith("FALLEN  (decayed)") and out[1].endswith("OLD  (40 days old)")
    assert out[-1] == f"would remove 1 decayed and 2 older than 5 days; 1 of 4 sets would remain in {store}"
    assert store.read_bytes() == before


def test_prune_never_empties_the_store_unless_told(tmp_path, capsys) -> None:
    path = tmp_path / "stored.txt"
    path.write_text(_set(90002, 40, "OLD") + _set(90005, 200, "OLDER"))
    before = path.read_bytes()
    assert main(["elements", "prune", "--store", str(path), "--yes"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"nfwserver: pruning would empty {path} (all 2 sets are decayed or older than 30 days); "
                          "`nfwserver elements update` fetches current ones, --all removes them anyway")
    assert path.read_bytes() == before
    assert main(["elements", "prune", "--store", str(path), "--all", "--yes"]) == 0
    assert ElementStore(path).load() == []


def test_the_selected_satellite_and_favourites_are_never_pruned(tmp_path, store, capsys) -> None:
    from nfwserver.app.session_state import SessionState, StateFile

    state = tmp_path / "state.json"
    StateFile(state).save(SessionState(90002, 25544))
    config = tmp_path / "c.toml"
    config.write_text(f'[elements]\nstore = "{store}"\n[server]\nstate_file = "{state}"\n'
                      "[satellites]\nfavourites = [90004]\n")
    assert main(["elements", "prune", "--config", str(config), "--days", "5", "--yes"]) == 0
    out, err = capsys.readouterr()
    assert "kept 90002 OLD: the selected satellite" in err and "kept 90004 FALLEN: a favourite" in err
    assert sorted(s.catalog_number for s in ElementStore(store).load()) == [90001, 90002, 90004]
    assert "removed 0 decayed and 1 older than 5 days; 3 sets remain" in out


@pytest.mark.parametrize(("answer", "code", "left"), [("y\n", 0, 1), ("n\n", 1, 4)])
def test_more_than_half_asks_on_a_terminal(store, answer, code, left) -> None:
    """A real pty as stdin: the question is asked on stderr and the answer decides."""
    import os
    import pty
    import subprocess
    import sys

    from tests.conftest import ROOT

    leader, follower = pty.openpty()
    try:
        proc = subprocess.Popen([sys.executable, "-m", "nfwserver", "elements", "prune", "--store", str(store),
                                 "--days", "5"], stdin=follower, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})
        os.write(leader, answer.encode())
        out, err = proc.communicate(timeout=60)
    finally:
        os.close(leader)
        os.close(follower)
    assert proc.returncode == code
    assert f"remove 3 of the 4 sets in {store}? [y/N]".encode() in err
    assert len(ElementStore(store).load()) == left
    assert (b"nothing removed" in err) == (code == 1) and (b"1 sets remain" in out) == (code == 0)
