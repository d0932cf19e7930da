"""passes, visible and ephemeris on the configured station: observer, horizon, catalog and now by default."""

from __future__ import annotations

import csv
import io
from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.cli import main
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.maidenhead import locator_to_latlon
from nfwserver.tracking.observer import Observer
from tests.conftest import DATA
from tests.tracking.skyfield_oracle import TS, skyfield_look_angles, skyfield_satellite, skyfield_topos

LOCATOR = "JO02ae"
OBSERVER = Observer(*locator_to_latlon(LOCATOR), 0.0)


def _station(tmp_path, extra: str = "", elements: str = "") -> str:
    """A configuration file for a station at JO02ae reading visual.txt only."""
    config = tmp_path / "station.toml"
    files = elements or str(DATA / "visual.txt")
    config.write_text(f'[observer]\nlocation = "{LOCATOR}"\n\n[elements]\nfiles = ["{files}"]\nuse_bundled = false\n'
                      f'store = "none"\n{extra}')
    return str(config)


def _rows(capsys) -> list[dict]:
    return list(csv.DictReader(io.StringIO(capsys.readouterr().out)))


def _iss():
    return next(s for s in load_element_file(DATA / "visual.txt").sets if s.catalog_number == 25544)


def test_visible_uses_the_configured_observer_and_catalog(tmp_path, capsys) -> None:
    at = datetime(2026, 5, 8, 3, 0, tzinfo=timezone.utc)
    assert main(["visible", "--config", _station(tmp_path), "--at", "2026-05-08T03:00Z", "--format", "csv"]) == 0
    rows = _rows(capsys)
    sets = {s.catalog_number: s for s in load_element_file(DATA / "visual.txt").sets}
    expected = set()
    for catnr, es in sets.items():
        _, el, _, _, _ = skyfield_look_angles(es, OBSERVER, [at])
        if el[0] > 0.01:
            expected.add(catnr)
        elif el[0] > -0.01:  # too close to call: leave it out of the comparison
            expected.discard(catnr)
    listed = {int(r["catalog_number"]) for r in rows}
    assert expected and expected <= listed and all(
        abs(skyfield_look_angles(sets[c], OBSERVER, [at])[1][0]) < 0.01 for c in listed - expected)


def test_configured_horizon_applies_to_the_configured_observer_only(tmp_path, capsys) -> None:
    config = _station(tmp_path, '\n[horizon]\npoints = [[0, 40], [180, 40]]\n')
    base = ["passes", "--config", config, "--start", "2026-05-08", "--hours", "24", "--sat", "ISS", "--format", "csv"]
    assert main(base) == 0
    masked = _rows(capsys)
    assert masked and all(float(r["max_elevation_deg"]) > 40 for r in masked)
    assert main([*base, "--observer", LOCATOR]) == 0  # another observer: no horizon table of its own
    flat = _rows(capsys)
    assert len(flat) > len(masked) and any(float(r["max_elevation_deg"]) < 40 for r in flat)


def test_ephemeris_defaults_to_now_and_the_configured_satellite(tmp_path, capsys) -> None:
    dut1 = float(TS.now().dut1)
    config = _station(tmp_path, f"\n[server]\nsatellite = 25544\nut1_utc_s = {dut1:.6f}\n")
    before = datetime.now(timezone.utc)
    assert main(["ephemeris", "--config", config, "--duration", "0", "--format", "csv"]) == 0
    after = datetime.now(timezone.utc)
    out, err = capsys.readouterr()
    (row,) = list(csv.DictReader(io.StringIO(out)))
    when = datetime.fromisoformat(row["time_utc"].replace("Z", "+00:00"))
    assert before - timedelta(milliseconds=1) <= when <= after
    _, el, _, _, _ = skyfield_look_angles(_iss(), OBSERVER, [when])
    assert float(row["elevation_deg"]) == pytest.approx(el[0], abs=0.01)
    assert "(more than [elements] stale_days, 14)" in err  # the test data is from May 2026


@pytest.mark.parametrize(("text", "offset"), [("+2h", timedelta(hours=2)), ("-30m", timedelta(minutes=-30)),
                                              ("+90s", timedelta(seconds=90)), ("+1d", timedelta(days=1)),
                                              ("now", timedelta(0))])
def test_relative_start_times(tmp_path, capsys, text, offset) -> None:
    before = datetime.now(timezone.utc)
    assert main(["ephemeris", "--config", _station(tmp_path), "--sat", "ISS", f"--start={text}", "--duration", "0",
                 "--format", "csv"]) == 0
    after = datetime.now(timezone.utc)
    when = datetime.fromisoformat(_rows(capsys)[0]["time_utc"].replace("Z", "+00:00"))
    assert before + offset - timedelta(milliseconds=1) <= when <= after + offset


def test_relative_start_joined_by_the_negative_value_rule(tmp_path, capsys) -> None:
    before = datetime.now(timezone.utc)
    assert main(["ephemeris", "--config", _station(tmp_path), "--sat", "ISS", "--start", "-30m", "--duration", "0",
                 "--format", "csv"]) == 0
    when = datetime.fromisoformat(_rows(capsys)[0]["time_utc"].replace("Z", "+00:00"))
    assert when - before < timedelta(minutes=-29)


def test_a_pass_in_progress_at_the_start_is_marked(tmp_path, capsys) -> None:
    sat = skyfield_satellite(_iss())
    t, kinds = sat.find_events(skyfield_topos(OBSERVER), TS.utc(2026, 5, 8), TS.utc(2026, 5, 9), 0.0)
    rise_index = list(kinds).index(0)
    rise, culmination = t[rise_index].utc_datetime(), t[rise_index + 1].utc_datetime()
    start = culmination.strftime("%Y-%m-%dT%H:%M:%SZ")
    assert main(["passes", "--config", _station(tmp_path), "--sat", "ISS", "--start", start, "--hours", "6",
                 "--format", "csv"]) == 0
    rows = _rows(capsys)
    assert rows[0]["in_progress"] == "Y" and all(r["in_progress"] == "N" for r in rows[1:])
    aos = datetime.fromisoformat(rows[0]["aos_utc"].replace("Z", "+00:00"))
    assert abs((aos - rise).total_seconds()) < 1.0


def test_passes_with_no_arguments_use_the_stored_catalog(tmp_path, capsys) -> None:
    store = tmp_path / "stored.txt"
    config = tmp_path / "c.toml"
    config.write_text(f'[observer]\nlocation = "{LOCATOR}"\n[elements]\nuse_bundled = false\nstore = "{store.name}"\n')
    assert main(["elements", "update", "--config", str(config), str(DATA / "visual.txt")]) == 0
    capsys.readouterr()
    assert store.exists()
    assert main(["passes", "--config", str(config), "--hours", "2", "--format", "csv"]) == 0
    out, err = capsys.readouterr()
    visual = {s.catalog_number for s in load_element_file(DATA / "visual.txt").sets}
    rows = list(csv.DictReader(io.StringIO(out)))
    assert rows and {int(r["catalog_number"]) for r in rows} <= visual
    assert "no observer configured" not in err


def test_without_an_observer_the_default_is_named_with_the_file_to_edit(tmp_path, capsys) -> None:
    config = tmp_path / "bare.toml"
    config.write_text(f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\nuse_bundled = false\nstore = "none"\n')
    assert main(["visible", "--config", str(config)]) == 0
    assert f"set [observer] location in {config}" in capsys.readouterr().err


def test_after_config_init_and_a_location_the_commands_need_no_arguments(capsys) -> None:
    """The issue's acceptance: `config init`, set `location`, then passes/visible/ephemeris --sat ISS."""
    from nfwserver.config.files import default_config_path

    assert main(["config", "init"]) == 0
    path = default_config_path()
    text = path.read_text()
    assert '# location = "JO02ae"' in text
    path.write_text(text.replace('# location = "JO02ae"', f'location = "{LOCATOR}"'))
    capsys.readouterr()
    for argv in (["passes"], ["visible"], ["ephemeris", "--sat", "ISS", "--duration", "120"]):
        assert main(argv) == 0, argv
        out, err = capsys.readouterr()
        assert out.splitlines()[0].startswith(("catalog_number", "time_utc", "sat ")) and "no observer" not in err
    assert main(["ephemeris", "--sat", "AO-91", "--duration", "0", "--format", "csv"]) == 0
    assert len(_rows(capsys)) == 1


def test_passes_flag_sets_older_than_the_configured_age(tmp_path, capsys) -> None:
    """``[elements] stale_days`` decides which sets `passes` calls stale (#25 item 2)."""
    config = tmp_path / "c.toml"
    elements = f'"{DATA / "visual.txt"}"'
    argv = ["passes", "--observer", "JO02ae", "--start", "2026-05-20", "--hours", "1", "--sat", "25544",
            "--config", str(config)]
    config.write_text(f"[elements]\nfiles = [{elements}]\nuse_bundled = false\nstore = \"none\"\nstale_days = 30\n")
    assert main(argv) == 0
    assert "days old at" not in capsys.readouterr().err
    config.write_text(f"[elements]\nfiles = [{elements}]\nuse_bundled = false\nstore = \"none\"\nstale_days = 5\n")
    assert main(argv) == 0
    # Said as an age (#34 item 10), worked out from the TLE's epoch field: 26127.42525608 is 2026, day 127
    # (7 May) at 0.42525608 d, so 12.57 days before 2026-05-20T00:00Z.
    age = (datetime(2026, 5, 20, tzinfo=timezone.utc) - datetime(2026, 1, 1, tzinfo=timezone.utc)).days - 126.42525608
    assert f"1 element set is {age:.0f} days old at 2026-05-20T00:00:00.000Z (more than [elements] stale_days, 5), " \
           "so its position drifts (ISS)" in capsys.readouterr().err
