"""``nfwserver schedule`` against an independent computation of the autotrack rule over ``passes``' CSV.

The oracle reads the rows ``nfwserver passes --min-el 10 --format csv`` writes for the same satellites and
window, and applies the rule as docs/AUTOTRACK.md states it, in plain Python: satellites in priority order, each
satellite's passes in AOS order; a pass is scheduled when it is at least min_gap_s apart from every pass already
scheduled, else left out naming the earliest scheduled pass it runs into.
"""

from __future__ import annotations

import csv
import io
import json
from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.cli import main
from nfwserver.cli.pass_reports import PASS_COLUMNS
from tests.conftest import ROOT

AMATEUR = ROOT / "nfwserver" / "data" / "amateur.txt"
PLACE = ["--elements", str(AMATEUR), "--observer", "JO02ae", "--start", "2026-05-08T00:00:00Z", "--hours", "24"]
#: Six satellites, highest priority first.
SIX = ["ISS", "SO-50", "AO-91", "AO-7", "RS-44", "FO-29"]


def _run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    assert main(argv) == 0
    return capsys.readouterr().out


def _time(text: str) -> datetime:
    return datetime.strptime(text, "%Y-%m-%dT%H:%M:%S.%fZ").replace(tzinfo=timezone.utc)


def _oracle(rows: list[dict[str, str]], priority: list[int], gap_s: float) -> dict[tuple[str, str], str]:
    """(catalog number, AOS) -> "" when scheduled, else the reason, by the rule's words."""
    order = sorted(rows, key=lambda r: (priority.index(int(r["catalog_number"])), _time(r["aos_utc"])))
    names = {25544: "ISS", 27607: "SO-50", 43017: "AO-91", 7530: "AO-7", 44909: "RS-44", 24278: "FO-29"}
    taken: list[dict[str, str]] = []
    out = {}
    for row in order:
        a, b = _time(row["aos_utc"]), _time(row["los_utc"])
        clashes = []
        for other in taken:
            c, d = _time(other["aos_utc"]), _time(other["los_utc"])
            apart = max((c - b).total_seconds(), (a - d).total_seconds())
            if apart < gap_s:
                clashes.append((c, other, apart))
        key = (row["catalog_number"], row["aos_utc"])
        if not clashes:
            taken.append(row)
            out[key] = ""
            continue
        c, other, apart = min(clashes, key=lambda x: x[0])
        d = _time(other["los_utc"])
        what = f"{names[int(other['catalog_number'])]} {c:%H:%M}-{d:%H:%M}"
        out[key] = f"overlaps {what}" if apart < 0 else \
            f"too close to {what} ({apart:.0f} s apart, min_gap_s {gap_s:g})"
    return out


@pytest.mark.parametrize("gap_s", [60.0, 900.0])
def test_a_day_of_six_satellites_follows_the_rule(capsys: pytest.CaptureFixture[str], gap_s: float) -> None:
    sats = [arg for name in SIX for arg in ("--sat", name)]
    passes = list(csv.DictReader(io.StringIO(_run(capsys, ["passes", *PLACE, *sats, "--min-el", "10",
                                                           "--format", "csv"]))))
    rows = list(csv.DictReader(io.StringIO(_run(capsys, ["schedule", *PLACE, *sats, "--min-gap", str(gap_s),
                                                         "--format", "csv"]))))
    assert list(rows[0]) == [*PASS_COLUMNS, "scheduled", "reason"]
    # every candidate pass listed, in AOS order, with the columns of passes (the durations to the microsecond)
    assert [[r[k] for k in PASS_COLUMNS if k != "duration_s"] for r in rows] == \
        [[r[k] for k in PASS_COLUMNS if k != "duration_s"] for r in passes]
    assert all(abs(float(r["duration_s"]) - float(p["duration_s"])) < 1e-5 for r, p in zip(rows, passes))
    expected = _oracle(passes, [25544, 27607, 43017, 7530, 44909, 24278], gap_s)
    got = {(r["catalog_number"], r["aos_utc"]): r["reason"] for r in rows}
    assert got == expected
    assert all((r["scheduled"] == "Y") == (r["reason"] == "") for r in rows)
    assert {r["scheduled"] for r in rows} == {"Y", "N"}  # the day has both, so the rule is exercised
    if gap_s == 900.0:
        assert any(r["reason"].startswith("too close to") for r in rows)


def test_an_obstructed_horizon_gives_the_passes_of_passes(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    horizon = tmp_path / "horizon.txt"
    horizon.write_text("0 5\n90 25\n180 3\n270 12\n", encoding="utf-8")
    sats = [arg for name in SIX for arg in ("--sat", name)]
    passes = list(csv.DictReader(io.StringIO(_run(capsys, ["passes", *PLACE, "--horizon", str(horizon), *sats,
                                                           "--min-el", "10", "--format", "csv"]))))
    rows = list(csv.DictReader(io.StringIO(_run(capsys, ["schedule", *PLACE, "--horizon", str(horizon), *sats,
                                                         "--format", "csv"]))))
    assert [r["aos_utc"] + r["los_utc"] for r in rows] == [p["aos_utc"] + p["los_utc"] for p in passes]
    expected = _oracle(passes, [25544, 27607, 43017, 7530, 44909, 24278], 60.0)
    assert {(r["catalog_number"], r["aos_utc"]): r["reason"] for r in rows} == expected


def test_the_formats_carry_the_same_rows(capsys: pytest.CaptureFixture[str]) -> None:
    sats = [arg for name in SIX[:3] for arg in ("--sat", name)]
    rows = list(csv.DictReader(io.StringIO(_run(capsys, ["schedule", *PLACE, *sats, "--format", "csv"]))))
    objects = json.loads(_run(capsys, ["schedule", *PLACE, *sats, "--format", "json"]))
    assert [o["aos_utc"] for o in objects] == [r["aos_utc"] for r in rows]
    assert [o["scheduled"] for o in objects] == [r["scheduled"] for r in rows]
    assert [o["reason"] or "" for o in objects] == [r["reason"] for r in rows]
    table = _run(capsys, ["schedule", *PLACE, *sats]).splitlines()
    assert table[0].split() == ["sat", "name", "aos", "(UTC)", "tca", "los", "max", "rise", "set", "min",
                                "scheduled", "reason"]
    assert len(table) == len(rows) + 1
    for line, row in zip(table[1:], rows):
        assert line.split()[0] == row["catalog_number"]
        assert line.split()[3] == row["aos_utc"][11:19]
        assert line.split()[10] == row["scheduled"]  # DDE names hold no blanks
        assert line.endswith(row["reason"] or row["scheduled"])
    wide = _run(capsys, ["schedule", *PLACE, *sats, "--wide"]).splitlines()
    assert wide[0].split() == [*PASS_COLUMNS, "scheduled", "reason"]


def test_local_times_shift_the_reason_too(capsys: pytest.CaptureFixture[str], monkeypatch) -> None:
    import time

    monkeypatch.setenv("TZ", "Asia/Kolkata")  # +05:30, no daylight saving
    time.tzset()
    try:
        sats = [arg for name in SIX for arg in ("--sat", name)]
        utc = _run(capsys, ["schedule", *PLACE, *sats]).splitlines()
        local = _run(capsys, ["schedule", *PLACE, *sats, "--local"]).splitlines()
    finally:
        monkeypatch.delenv("TZ")
        time.tzset()
    left_out = [(u, lo) for u, lo in zip(utc[1:], local[1:]) if "overlaps" in u]
    assert left_out
    for u, lo in left_out:
        when = datetime.strptime(u.split("overlaps ")[1].split()[1].split("-")[0], "%H:%M")
        shown = (when + timedelta(hours=5, minutes=30)).strftime("%H:%M")
        assert lo.split("overlaps ")[1].split()[1].startswith(shown)


def test_satellites_come_from_the_configuration(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    config = tmp_path / "c.toml"
    config.write_text('[satellites]\nfavourites = [27607, 25544]\n', encoding="utf-8")
    favourites = _run(capsys, ["schedule", *PLACE, "--config", str(config), "--format", "csv"])
    by_sat = _run(capsys, ["schedule", *PLACE, "--sat", "SO-50", "--sat", "ISS", "--format", "csv"])
    assert favourites == by_sat
    config.write_text('[satellites]\nfavourites = [27607, 25544]\n[autotrack]\nsatellites = ["ISS", 27607]\n'
                      'min_el_deg = 30\n', encoding="utf-8")
    listed = _run(capsys, ["schedule", *PLACE, "--config", str(config), "--format", "csv"])
    assert listed == _run(capsys, ["schedule", *PLACE, "--sat", "ISS", "--sat", "SO-50", "--min-el", "30",
                                   "--format", "csv"])
    assert listed != by_sat


def test_unknown_satellites_are_named_and_none_usable_is_an_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["schedule", *PLACE, "--sat", "ISS", "--sat", "NOSUCHSAT", "--format", "csv"]) == 0
    assert "NOSUCHSAT is not in the catalog" in capsys.readouterr().err
    assert main(["schedule", *PLACE, "--sat", "NOSUCHSAT"]) == 1
    assert "none of the satellites" in capsys.readouterr().err
    assert main(["schedule", *PLACE]) == 1  # no favourites, no --sat
    assert "no satellites to schedule" in capsys.readouterr().err
