"""``nfwserver passes`` as a newcomer runs it (issue 25 item 4): an 80-column table by default, filters,
local times, favourites.  Every row is checked against the CSV of the same search (CSV itself is checked
against skyfield in test_tracking_cli and the pass oracle tests)."""

from __future__ import annotations

import csv
import io
import os
import subprocess
import sys
from datetime import datetime, timedelta
from pathlib import Path

from nfwserver.cli import main
from tests.conftest import DATA

ROOT = Path(__file__).resolve().parents[2]
COMMON = ["passes", "--elements", str(DATA / "visual.txt"), "--observer", "52.2,0.12", "--start",
          "2026-05-08T00:00Z", "--hours", "12"]


def _csv(argv: list[str], capsys) -> list[dict[str, str]]:
    assert main([*argv, "--format", "csv"]) == 0
    return list(csv.DictReader(io.StringIO(capsys.readouterr().out)))


def _table(argv: list[str], capsys) -> list[list[str]]:
    assert main(argv) == 0
    lines = capsys.readouterr().out.splitlines()
    assert all(len(line) <= 80 for line in lines), max(lines, key=len)
    return [line.split() for line in lines]


def _expected_cells(row: dict[str, str], shift: timedelta = timedelta(0)) -> list[str]:
    def clock(iso: str, with_date: bool) -> list[str]:
        when = datetime.strptime(iso, "%Y-%m-%dT%H:%M:%S.%fZ") + shift
        return [when.strftime("%m-%d"), when.strftime("%H:%M:%S")] if with_date else [when.strftime("%H:%M:%S")]

    return [row["catalog_number"], *clock(row["aos_utc"], True), *clock(row["tca_utc"], False),
            *clock(row["los_utc"], False), f"{float(row['max_elevation_deg']):.1f}",
            f"{float(row['aos_azimuth_deg']):.0f}", f"{float(row['los_azimuth_deg']):.0f}",
            f"{float(row['duration_s']) / 60:.1f}"]


def _without_name(cells: list[str], name_words: int) -> list[str]:
    return [cells[0], *cells[1 + name_words:]]


def test_the_default_table_fits_80_columns_and_holds_the_csv_values(capsys) -> None:
    rows = [r for r in _csv(COMMON, capsys) if r["aos_utc"] and r["los_utc"]]
    table = _table(COMMON, capsys)
    assert table[0] == ["sat", "name", "aos", "(UTC)", "tca", "los", "max", "rise", "set", "min"]
    body = [cells for cells in table[1:] if len(cells) == 10]  # rows with AOS and LOS inside the window
    assert len(body) == len(rows) > 50
    for cells, row in zip(body, rows):
        assert _without_name(cells, 1) == _expected_cells(row)


def test_min_el_keeps_the_passes_that_reach_it(capsys) -> None:
    every = _csv(COMMON, capsys)
    high = _csv([*COMMON, "--min-el", "45"], capsys)
    assert high == [r for r in every if float(r["max_elevation_deg"]) >= 45] and 0 < len(high) < len(every)


def test_group_is_a_name_pattern_and_sat_adds_to_it(capsys) -> None:
    rows = _csv([*COMMON, "--group", "sl-1?*", "--sat", "25544"], capsys)
    names = {r["name"] for r in rows}
    assert "ISS (ZARYA)" in names and len(names) > 2
    assert all(n.startswith("SL-1") and n[4:5].isdigit() or n == "ISS (ZARYA)" for n in names), names
    assert main([*COMMON, "--group", "NO-SUCH-*"]) == 1


def test_local_times_are_shifted_by_the_zone_and_named(capsys) -> None:
    rows = [r for r in _csv(COMMON, capsys) if r["aos_utc"] and r["los_utc"]]
    env = dict(os.environ, TZ="Asia/Kolkata", PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-m", "nfwserver", *COMMON, "--local"], cwd=ROOT, env=env,
                         capture_output=True, text=True, check=True).stdout.splitlines()
    assert out[0].split()[2:4] == ["aos", "(IST)"]
    body = [line.split() for line in out[1:] if len(line.split()) == 10]
    assert [_without_name(c, 1) for c in body] == [_expected_cells(r, timedelta(hours=5, minutes=30))
                                                    for r in rows]


def test_favourites_are_the_default_when_configured(tmp_path, capsys) -> None:
    config = tmp_path / "station.toml"
    config.write_text('[observer]\nlocation = "52.2,0.12"\n[satellites]\nfavourites = [25544, 3597]\n'
                      f'[elements]\nfiles = ["{DATA / "visual.txt"}"]\n')
    argv = ["passes", "--config", str(config), "--start", "2026-05-08T00:00Z", "--hours", "24"]
    rows = _csv(argv, capsys)
    assert {r["catalog_number"] for r in rows} == {"25544", "3597"}
    every = _csv([*argv, "--all"], capsys)
    assert len({r["catalog_number"] for r in every}) > 10
    assert main([*argv, "--favourites", "--format", "csv"]) == 0
    assert "favourite" not in capsys.readouterr().err  # asked for: no reminder


def test_every_option_has_help() -> None:
    out = subprocess.run([sys.executable, "-m", "nfwserver", "passes", "--help"], cwd=ROOT, capture_output=True,
                         text=True, check=True).stdout
    options = [line.split()[0].rstrip(",") for line in out.splitlines() if line.startswith("  -")]
    assert "--hours" in options and "--min-el" in options
    for option in options:
        block = out[out.index("  " + option):].split("\n  -", 1)[0]
        assert len(block.split()) > 2, f"{option} has no help"
