"""``passes`` for a few satellites: the small search and writer (no numpy), byte for byte the catalog path's text.

The pure-Python writer (nfwserver/cli/pass_text.py) is checked against the numpy writer the command used
before it (nfwserver/cli/bulk_output.py), given the same passes: both paths are run on one set of rows,
including passes whose AOS or LOS is unknown or outside the window, and names CSV must quote.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from datetime import datetime, timezone

import numpy as np
import pytest

import nfwserver.cli.few_passes_command as few_command
import nfwserver.tracking.few_passes as few_module
import nfwserver.tracking.passes as passes_module
from nfwserver.cli import main
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.few_passes import FewPasses
from nfwserver.tracking.pass_records import PassList
from nfwserver.tracking.pass_spill import SpilledPasses
from tests.conftest import DATA, ROOT

START = datetime(2026, 5, 8, tzinfo=timezone.utc)
#: catalog number, AOS, TCA, LOS (s after the start; None unknown), max elevation, azimuths at AOS and LOS
ROWS = [
    (25544, -120.25, 200.5, 530.125, 45.04999, 271.95, 96.7),  # in progress at the start
    (90001, None, 3000.0, 3600.0004, 12.25, None, 180.05),  # AOS unknown
    (90002, 5000.0001, 5999.9999, None, 0.0001, 359.96, None),  # LOS unknown
    (25544, 80000.5, 80300.0, 86500.0, 89.99, 0.04, 179.949),  # LOS after the end
]


@pytest.fixture
def elements(tmp_path):
    iss = next(s for s in load_element_file(DATA / "active.txt").sets if s.catalog_number == 25544)
    lines = iss.tle_text().splitlines()
    path = tmp_path / "few.txt"
    text = iss.tle_text()
    for number, name in ((90001, 'SAT, "ONE"'), (90002, "ÅNGSTRÖM-2")):
        line1 = lines[1][:2] + f"{number:05d}" + lines[1][7:68]
        line2 = lines[2][:2] + f"{number:05d}" + lines[2][7:68]
        text += f"{name}\n{line1}{_checksum(line1)}\n{line2}{_checksum(line2)}\n"
    path.write_text(text, encoding="utf-8")
    return path


def _checksum(line: str) -> int:
    return sum(int(c) if c.isdigit() else c == "-" for c in line[:68]) % 10


def _run_both(capsys, monkeypatch, argv: list[str]) -> tuple[str, str]:
    """The command's output through the small path and through the catalog path, given the same rows."""
    monkeypatch.setattr(few_module, "find_few_passes", lambda *a, **k: FewPasses(list(ROWS)))
    assert main(argv) == 0
    small = capsys.readouterr().out
    columns = {name: np.array([math.nan if v is None else v for v in values], dtype=float)
               for name, values in zip(("catalog_number", "aos_s", "tca_s", "los_s", "max_elevation_deg",
                                        "aos_azimuth_deg", "los_azimuth_deg"), zip(*ROWS))}
    monkeypatch.setattr(few_command, "FEW", 0)
    monkeypatch.setattr(passes_module, "find_passes", lambda *a, **k: PassList(START, 86400.0, columns))
    # CSV and JSON are written from passes kept in a temporary file
    monkeypatch.setattr(passes_module, "find_passes_spilled", lambda *a, **k: _spilled(columns))
    assert main(argv) == 0
    return small, capsys.readouterr().out


def _spilled(columns: dict[str, np.ndarray]) -> SpilledPasses:
    spilled = SpilledPasses(START, 86400.0)
    spilled.add(columns)
    return spilled.seal()


@pytest.mark.parametrize("options", [["--format", "table"], ["--format", "table", "--wide"], ["--format", "csv"],
                                     ["--format", "json"], ["--format", "table", "--local"], ["--min-el", "20"]])
def test_the_small_writer_writes_the_catalog_writers_bytes(capsys, monkeypatch, elements, options) -> None:
    monkeypatch.setenv("TZ", "America/St_Johns")  # a zone with half hours, for --local
    time.tzset()
    try:
        small, catalog = _run_both(capsys, monkeypatch, [
            "passes", "--elements", str(elements), "--observer", "52.2,0.12", "--start", "2026-05-08T00:00Z",
            "--hours", "24", "--sat", "25544", "--sat", "90001", "--sat", "90002", *options])
    finally:
        monkeypatch.undo()
        time.tzset()
    assert small == catalog
    assert small.count("\n") >= 2


def test_one_satellite_is_searched_and_written_without_numpy(tmp_path) -> None:
    """numpy's import alone costs more than the whole search for one satellite (docs/BENCHMARKS.md); OpenSSL's
    libcrypto (hashlib, secrets: about 3.5 MiB), which only the web token needs, is not loaded either; nor,
    without a configuration file, the configuration's records (nfwserver.config.schema), which cost as much."""
    iss = next(s for s in load_element_file(DATA / "visual.txt").sets if s.catalog_number == 25544)
    path = tmp_path / "iss.txt"
    path.write_text(iss.tle_text())
    code = ("import sys\nfrom nfwserver.cli import main\n"
            f"rc = main(['passes', '--elements', {str(path)!r}, '--sat', 'ISS', '--observer', '52.2,0.12', "
            "'--start', '2026-05-08T00:00Z', '--format', 'csv'])\n"
            "print('numpy' in sys.modules, '_hashlib' in sys.modules, 'nfwserver.config.schema' in sys.modules, rc)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines()[-1] == "False False False 0"
    assert out.count("2026-05-0") >= 4  # the passes were written


@pytest.mark.skipif(sys.platform != "linux", reason="the user's configuration is moved by XDG_CONFIG_HOME on Linux")
def test_one_satellite_with_a_configuration_file_follows_it(tmp_path) -> None:
    """With the user's file the configuration is read: its DDE name for the set and its stale_days apply."""
    iss = next(s for s in load_element_file(DATA / "visual.txt").sets if s.catalog_number == 25544)
    path = tmp_path / "iss.txt"
    path.write_text(iss.tle_text())
    config = tmp_path / "xdg" / "nfwserver" / "config.toml"
    config.parent.mkdir(parents=True)
    config.write_text('[elements]\nstale_days = 1\n[satellites]\nnames = { "25544" = "ZARYA-1" }\n')
    result = subprocess.run([sys.executable, "-m", "nfwserver", "passes", "--elements", str(path), "--sat", "25544",
                             "--observer", "52.2,0.12", "--start", "2026-05-10T00:00Z", "--format", "table"],
                            capture_output=True, text=True, check=True, cwd=ROOT,
                            env={**os.environ, "PYTHONPATH": str(ROOT), "XDG_CONFIG_HOME": str(tmp_path / "xdg")})
    assert "ZARYA-1" in result.stdout  # the compact table shows DDE names
    assert "3 days old at 2026-05-10T00:00:00.000Z (more than [elements] stale_days, 1)" in result.stderr


def test_a_case_the_small_search_hands_back_is_searched_by_the_catalog_search(capsys, monkeypatch, elements) -> None:
    argv = ["passes", "--elements", str(elements), "--observer", "52.2,0.12", "--start", "2026-05-08T00:00Z",
            "--sat", "25544", "--format", "csv"]
    monkeypatch.setattr(few_command, "FEW", 0)
    assert main(argv) == 0
    catalog = capsys.readouterr().out
    monkeypatch.setattr(few_command, "FEW", 8)

    def hand_back(*args: object, **kwargs: object) -> FewPasses:
        raise few_module.NeedsCatalogSearch("test")

    monkeypatch.setattr(few_module, "find_few_passes", hand_back)
    assert main(argv) == 0
    assert capsys.readouterr().out == catalog and catalog.count("\n") >= 5
