"""The ephemeris, passes and visible commands: columns, formats, usage errors (exit 2), runtime errors (exit 1)."""

from __future__ import annotations

import csv
import io
import json
import re
from datetime import datetime, timedelta, timezone

import pytest

from nfwserver.cli import main
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer, parse_observer
from tests.conftest import DATA
from tests.tracking.skyfield_oracle import skyfield_look_angles

ELEMENTS = ["--elements", str(DATA / "visual.txt")]
TIME = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$")


def _csv(capsys) -> list[dict]:
    return list(csv.DictReader(io.StringIO(capsys.readouterr().out)))


def _visual(catnr: int):
    return next(s for s in load_element_file(DATA / "visual.txt").sets if s.catalog_number == catnr)


def test_ephemeris_csv_matches_skyfield(capsys) -> None:
    observer = Observer(-33.87, 151.21, 40)
    when = datetime(2026, 5, 8, 0, 5, tzinfo=timezone.utc)
    az, el, rng, rr, dut1 = skyfield_look_angles(_visual(25544), observer, [when])
    assert main(["ephemeris", *ELEMENTS, "--observer", "-33.87,151.21,40", "--sat", "25544", "--ut1-utc",
                 f"{dut1[0]:.9f}", "--start", "2026-05-08T00:00:00", "--duration", "600", "--step", "60",
                 "--format", "csv"]) == 0
    rows = _csv(capsys)
    assert list(rows[0])[:6] == ["time_utc", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s",
                                 "above_horizon"]
    assert len(rows) == 11 and all(TIME.match(r["time_utc"]) for r in rows)
    assert rows[5]["time_utc"] == "2026-05-08T00:05:00.000Z"
    assert float(rows[5]["elevation_deg"]) == pytest.approx(el[0], abs=1e-5)
    assert float(rows[5]["azimuth_deg"]) == pytest.approx(az[0], abs=1e-5)
    assert float(rows[5]["range_km"]) == pytest.approx(rng[0], abs=1e-3)
    assert float(rows[5]["range_rate_km_s"]) == pytest.approx(rr[0], abs=1e-5)
    assert len(rows[5]["azimuth_deg"].split(".")[1]) >= 6


def test_sat_by_name_is_the_same_satellite(capsys) -> None:
    common = ["ephemeris", *ELEMENTS, "--observer", "JO02ae", "--start", "2026-05-08", "--duration", "60",
              "--format", "csv"]
    assert main([*common, "--sat", "25544"]) == 0
    by_number = capsys.readouterr().out
    for name in ("ISS", "iss", "ISS (ZARYA)"):
        assert main([*common, "--sat", name]) == 0
        assert capsys.readouterr().out == by_number


def test_passes_csv_and_horizon(capsys, tmp_path) -> None:
    horizon = tmp_path / "h.txt"
    horizon.write_text("0 30\n180 30\n")
    args = ["passes", *ELEMENTS, "--observer", "JO02ae", "--start", "2026-05-08", "--hours", "24",
            "--sat", "ISS", "--format", "csv"]
    assert main(args) == 0
    flat = _csv(capsys)
    assert main([*args, "--horizon", str(horizon)]) == 0
    masked = _csv(capsys)
    assert list(flat[0]) == ["catalog_number", "name", "aos_utc", "tca_utc", "los_utc", "max_elevation_deg",
                             "aos_azimuth_deg", "los_azimuth_deg", "duration_s", "in_progress"]
    assert 1 <= len(masked) < len(flat)
    assert all(float(r["max_elevation_deg"]) > 30 for r in masked)
    assert all(r["aos_utc"] < r["tca_utc"] < r["los_utc"] for r in flat[1:-1])


def test_passes_of_all_satellites_and_visible(capsys) -> None:
    assert main(["passes", *ELEMENTS, "--observer", "52.2,0.12", "--start", "2026-05-08T00:00Z", "--hours", "1",
                 "--wide"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[0].startswith("catalog_number") and len(table) > 10
    at = ["--at", "2026-05-08T03:00:00", "--format", "csv"]
    assert main(["visible", *ELEMENTS, "--observer", "52.2,0.12", *at]) == 0
    rows = _csv(capsys)
    assert rows and all(float(r["elevation_deg"]) > 0 for r in rows)
    assert [float(r["elevation_deg"]) for r in rows] == sorted((float(r["elevation_deg"]) for r in rows), reverse=True)


BAD_VALUES = [
    (["passes", "--start", "tomorrow"], "--start"),
    (["passes", "--start", "+2x"], "--start"),
    (["visible", "--at", "2026-13-01"], "--at"),
    (["ephemeris", "--observer", "ZZ99zz"], "--observer"),
    (["ephemeris", "--observer", "100,2"], "--observer"),
    (["ephemeris", "--duration", "-5"], "--duration"),
    (["ephemeris", "--step", "0"], "--step"),
    (["ephemeris", "--step", "nan"], "--step"),
    (["ephemeris", "--duration", "86400", "--step", "0.001"], "--step"),
    (["passes", "--hours", "0"], "--hours"),
    (["passes", "--hours", "1000"], "--hours"),
    (["passes", "--workers", "0"], "--workers"),
    (["passes", "--workers", "1.5"], "--workers"),
    (["visible", "--ut1-utc", "5"], "--ut1-utc"),
    (["passes", "--sat", ""], "--sat"),
]


@pytest.mark.parametrize(("argv", "flag"), BAD_VALUES)
def test_bad_argument_values_are_usage_errors(capsys, argv, flag) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main([*argv, *ELEMENTS])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    last = err.strip().splitlines()[-1]
    assert flag in last and "Traceback" not in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["ephemeris", *ELEMENTS, "--observer", "1,2", "--sat", "1", "--start", "2026-05-08"], "not in the catalog"),
        (["passes", *ELEMENTS, "--observer", "1,2", "--sat", "NOSUCHSAT"], "not in the catalog"),
        (["passes", *ELEMENTS, "--observer", "1,2", "--start", "2026-05-08", "--horizon", "/nonexistent"], "--horizon"),
        (["visible", "--elements", "/nonexistent/keps.txt", "--observer", "1,2"],
         "cannot read /nonexistent/keps.txt: no such file or directory"),
        (["visible", "--config", "/nonexistent/config.toml"], "configuration refused"),
    ],
)
def test_runtime_errors_are_one_sentence_exit_1(capsys, argv, message) -> None:
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert message in err.strip().splitlines()[-1] and "Traceback" not in err


def test_a_far_propagated_object_is_skipped_and_stale_sets_are_named(capsys) -> None:
    """STARLINK-34061 (63876), propagated eight weeks past its epoch, is 4.7e10 km away per SGP4."""
    from sgp4.api import jday

    active = load_element_file(DATA / "active.txt").sets
    far = next(s for s in active if s.catalog_number == 63876)
    error, position, _ = far.satrec.sgp4(*jday(2026, 7, 1, 0, 0, 0))
    assert error == 0 and sum(p * p for p in position) ** 0.5 > 1e9  # the library's own verdict
    assert main(["visible", "--elements", str(DATA / "active.txt"), "--observer", "52.2,0.12",
                 "--at", "2026-07-01T00:00Z", "--format", "csv"]) == 0
    out, err = capsys.readouterr()
    rows = list(csv.DictReader(io.StringIO(out)))
    assert rows and all(float(r["range_km"]) <= 1.5e6 for r in rows)
    assert "63876" not in {r["catalog_number"] for r in rows}
    assert "cannot be computed or is implausibly far" in err
    assert "days old at 2026-07-01T00:00:00.000Z (more than [elements] stale_days" in err
    assert main(["visible", *ELEMENTS, "--observer", "52.2,0.12", "--at", "2026-05-08T00:00Z"]) == 0
    err = capsys.readouterr().err
    assert "older than" not in err and "implausibly" not in err


@pytest.mark.parametrize("command", [
    ["passes", "--start", "2026-05-08T00:00Z", "--hours", "6"],
    ["visible", "--at", "2026-05-08T03:00:00"],
    ["ephemeris", "--sat", "25544", "--start", "2026-05-08", "--duration", "600", "--step", "60"],
])
def test_json_holds_the_csv_rows_as_typed_values(capsys, command) -> None:
    common = [*command, *ELEMENTS, "--observer", "52.2,0.12", "--ut1-utc", "0"]
    assert main([*common, "--format", "csv"]) == 0
    rows = _csv(capsys)
    assert main([*common, "--format", "json"]) == 0
    out = capsys.readouterr().out
    docs = json.loads(out)
    assert len(docs) == len(rows) > 0 and out.count("\n") == len(rows) + 2  # "[", one object a line, "]"
    for doc, row in zip(docs, rows):
        assert list(doc) == list(row)
        for key, text in row.items():
            value = doc[key]
            if text in ("Y", "N"):
                assert value is (text == "Y")
            elif text == "":
                assert value is None
            elif isinstance(value, str):
                assert value == text
            else:
                assert value == (int(text) if key == "catalog_number" else float(text))


def test_passes_table_csv_and_json_of_the_same_passes(capsys) -> None:
    common = ["passes", *ELEMENTS, "--observer", "52.2,0.12", "--start", "2026-05-08T00:00Z", "--hours", "24"]
    assert main([*common, "--format", "table", "--wide"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert main([*common, "--format", "csv"]) == 0
    rows = _csv(capsys)
    assert main([*common, "--format", "json"]) == 0
    docs = json.loads(capsys.readouterr().out)
    assert len(table) - 1 == len(rows) == len(docs) > 50
    header = table[0].split()
    starts = [table[0].index(name) for name in header]
    for line, row in zip(table[1:], rows):
        assert line == line.rstrip() and row["name"] in line
        assert line[: starts[1]].strip() == row["catalog_number"]
        if row["aos_utc"]:
            assert row["aos_utc"] in line
        assert f"{float(row['max_elevation_deg']):.1f}" in line.split()


def test_passes_leaves_out_an_object_unusable_at_the_start_and_says_so(capsys, tmp_path) -> None:
    """The search itself leaves out the sets whose positions at the start are unusable (the same check as
    `visible`, judged by SGP4's own result: 63876 is 4.7e10 km away on 2026-07-01); `passes` names them
    once, and every other satellite's passes are those of a search without them."""
    from sgp4.api import jday

    from nfwserver.tracking.passes import find_passes

    active = load_element_file(DATA / "active.txt").sets
    far = next(s for s in active if s.catalog_number == 63876)
    iss = next(s for s in active if s.catalog_number == 25544)
    error, position, _ = far.satrec.sgp4(*jday(2026, 7, 1, 0, 0, 0))
    assert error == 0 and sum(p * p for p in position) ** 0.5 > 1e9  # the library's own verdict
    start = datetime(2026, 7, 1, tzinfo=timezone.utc)
    observer = parse_observer("52.2,0.12")
    both = find_passes([far, iss], observer, start, start + timedelta(hours=12))
    alone = find_passes([iss], observer, start, start + timedelta(hours=12))
    assert both.skipped == (63876,) and alone.skipped == ()
    assert len(both) == len(alone) >= 3 and list(both) == list(alone)
    elements = tmp_path / "two.txt"
    elements.write_text(far.tle_text() + iss.tle_text())
    assert main(["passes", "--elements", str(elements), "--observer", "52.2,0.12", "--start", "2026-07-01T00:00Z",
                 "--hours", "12", "--format", "csv"]) == 0
    out, err = capsys.readouterr()
    rows = list(csv.DictReader(io.StringIO(out)))
    assert {r["catalog_number"] for r in rows} == {"25544"} and len(rows) == len(alone)
    assert err.count("skipped 1 object(s) whose position at 2026-07-01T00:00:00.000Z cannot be computed") == 1


@pytest.mark.parametrize(("content", "why"), [
    ("", "{path} is empty"),
    ("<html><body>404 Not Found</body></html>\n", "{path} holds no TLE, AMSAT or OMM (JSON or CSV) element set"),
    ("1 25544U 98067A   26128.50000000  .00016717  00000-0  10270-3 0  9990\n"
     "2 25544  51.6400 208.9163 0006317  69.9862  25.2906 15.54225995 12345\n",
     "{path}: its 1 set(s) were refused (reasons above)"),
])
def test_an_element_file_without_a_usable_set_is_named_with_the_reason(capsys, tmp_path, content, why) -> None:
    path = tmp_path / "elements.txt"
    path.write_text(content)
    assert main(["passes", "--elements", str(path), "--observer", "52.2,0.12"]) == 1
    last = capsys.readouterr().err.strip().splitlines()[-1]
    assert last == "nfwserver: no usable element sets: " + why.format(path=path)
