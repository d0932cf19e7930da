"""A full or read-only disk never stops the station nor prints a traceback (issue 23 item 15).

``/dev/full`` answers every write with ENOSPC, so a symbolic link to it is a real full disk for one file;
``/proc`` and ``/sys`` are file systems where nothing can be created, also for root.
"""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import uuid
from datetime import datetime, timezone
from pathlib import Path

import pytest

from nfwserver.cli.log_file import LOG_BACKOFF, StationLogFile
from nfwserver.clock import VirtualClock

pytestmark = pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (Linux)")
ROOT = Path(__file__).resolve().parents[2]


def _run(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "nfwserver", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=120)


def test_a_full_log_disk_is_one_warning_records_dropped_and_it_heals_when_writable(tmp_path, caplog) -> None:
    path = tmp_path / "nfwserver.log"
    path.symlink_to("/dev/full")
    clock = VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc))
    logger = logging.getLogger(f"tests.logfile.{uuid.uuid4().hex}")
    logger.propagate = False
    handler = StationLogFile(path, clock)
    logger.addHandler(handler)
    caplog.set_level(logging.INFO)
    try:
        for k in range(100):
            logger.warning("line %d", k)
        warnings = [r.getMessage() for r in caplog.records if "cannot write the log file" in r.getMessage()]
        assert len(warnings) == 1 and "No space left on device" in warnings[0]
        assert not handler.health.ok
        path.unlink()  # space again: the file is opened afresh on the next try
        clock.advance(LOG_BACKOFF.initial_s / 2)
        logger.warning("too early")  # the back-off still runs: dropped, not tried
        assert not path.exists()
        clock.advance(LOG_BACKOFF.initial_s)
        logger.warning("written again")
        assert handler.health.ok
        assert "written again" in path.read_text() and "too early" not in path.read_text()
        assert any("101 log records were lost" in r.getMessage() for r in caplog.records)
    finally:
        logger.removeHandler(handler)
        handler.close()


def test_headless_station_with_a_full_or_unwritable_log_runs_and_stops_cleanly(tmp_path) -> None:
    (tmp_path / "c.toml").write_text('[server]\nstate_file = "none"\n[elements]\nstore = "none"\n')
    for log_file in ("/dev/full", "/proc/nfwserver-test/nfwserver.log"):
        done = _run("run", "--headless", "--config", "c.toml", "--log-file", log_file, "--duration", "1",
                    cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        assert "Traceback" not in done.stderr and "Logging error" not in done.stderr
        assert done.stderr.count("cannot write the log file") == 1


def test_config_init_into_an_unwritable_place_is_one_line(tmp_path) -> None:
    for target in ("/proc/nfwserver-test/config.toml", "/sys/nfwserver-test.toml"):
        done = _run("config", "init", "--config", target, cwd=tmp_path)
        assert done.returncode == 1
        assert done.stderr.startswith(f"nfwserver: cannot write {target}: ") and done.stderr.count("\n") == 1
