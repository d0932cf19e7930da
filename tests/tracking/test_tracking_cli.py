"""The ephemeris, passes and visible commands: columns, formats and errors."""

from __future__ import annotations

import csv
import io
import re
from datetime import datetime, timezone

import pytest

from nfwserver.cli import main
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.look_angles import LookAngleCalculator
from nfwserver.tracking.observer import Observer
from tests.conftest import DATA

ELEMENTS = ["--elements", str(DATA / "visual.txt")]
TIME = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$")


def _csv(capsys) -> list[dict]:
    return list(csv.DictReader(io.StringIO(capsys.readouterr().out)))


def test_ephemeris_csv_matches_the_library(capsys) -> None:
    assert main(["ephemeris", *ELEMENTS, "--observer", "-33.87,151.21,40", "--sat", "25544",
                 "--start", "2026-05-08T00:00:00", "--duration", "600", "--step", "60", "--format", "csv"]) == 0
    rows = _csv(capsys)
    assert list(rows[0])[:6] == ["time_utc", "azimuth_deg", "elevation_deg", "range_km", "range_rate_km_s",
                                 "above_horizon"]
    assert len(rows) == 11 and all(TIME.match(r["time_utc"]) for r in rows)
    sat = Catalog(load_element_file(DATA / "visual.txt").sets).get(25544)
    la = LookAngleCalculator(Observer(-33.87, 151.21, 40)).compute(
        sat.satrec, datetime(2026, 5, 8, 0, 5, tzinfo=timezone.utc))
    assert float(rows[5]["elevation_deg"]) == pytest.approx(la.elevation_deg, abs=1e-6)
    assert float(rows[5]["range_rate_km_s"]) == pytest.approx(la.range_rate_km_s, abs=1e-6)
    assert len(rows[5]["azimuth_deg"].split(".")[1]) >= 6


def test_passes_csv_and_horizon(capsys, tmp_path) -> None:
    horizon = tmp_path / "h.txt"
    horizon.write_text("0 30\n180 30\n")
    args = ["passes", *ELEMENTS, "--observer", "JO02ae", "--start", "2026-05-08", "--hours", "24",
            "--sat", "25544", "--format", "csv"]
    assert main(args) == 0
    flat = _csv(capsys)
    assert main([*args, "--horizon", str(horizon)]) == 0
    masked = _csv(capsys)
    assert list(flat[0])[:8] == ["catalog_number", "name", "aos_utc", "tca_utc", "los_utc", "max_elevation_deg",
                                 "aos_azimuth_deg", "los_azimuth_deg"]
    assert 1 <= len(masked) < len(flat)
    assert all(float(r["max_elevation_deg"]) > 30 for r in masked)
    assert all(r["aos_utc"] < r["tca_utc"] < r["los_utc"] for r in flat[1:-1])


def test_passes_of_all_satellites_and_visible(capsys) -> None:
    assert main(["passes", *ELEMENTS, "--observer", "52.2,0.12", "--start", "2026-05-08T00:00Z", "--hours", "1"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert table[0].startswith("catalog_number") and len(table) > 10
    at = ["--at", "2026-05-08T03:00:00", "--format", "csv"]
    assert main(["visible", *ELEMENTS, "--observer", "52.2,0.12", *at]) == 0
    rows = _csv(capsys)
    assert rows and all(float(r["elevation_deg"]) > 0 for r in rows)
    assert [float(r["elevation_deg"]) for r in rows] == sorted((float(r["elevation_deg"]) for r in rows), reverse=True)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["ephemeris", *ELEMENTS, "--observer", "1,2", "--sat", "1", "--start", "2026-05-08"], "not in the element"),
        (["ephemeris", *ELEMENTS, "--observer", "100,2", "--sat", "25544", "--start", "2026-05-08"], "--observer"),
        (["passes", *ELEMENTS, "--observer", "1,2", "--start", "tomorrow"], "--start"),
        (["passes", *ELEMENTS, "--observer", "1,2", "--start", "2026-05-08", "--horizon", "/nonexistent"], "--horizon"),
    ],
)
def test_errors_are_one_sentence(capsys, argv, message) -> None:
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
