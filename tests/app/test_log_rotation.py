"""The headless station's log file rotates (#44 item 5): at 5 MiB a file and 72.6 KB/h no run had ever
reached a rotation.  The real handler with its size lowered to 2 KiB: every file stays under it, five
backups are kept, and no record is lost or repeated across the files that remain."""

from __future__ import annotations

import logging
import re
import uuid
from datetime import datetime, timezone

from nfwserver.cli.log_file import StationLogFile
from nfwserver.clock import VirtualClock


def test_the_log_file_rotates_keeping_five_backups_and_every_recent_record(tmp_path) -> None:
    path = tmp_path / "logs" / "nfwserver.log"
    handler = StationLogFile(path, VirtualClock(datetime(2026, 5, 8, tzinfo=timezone.utc)))
    handler.maxBytes = 2048
    logger = logging.getLogger(f"tests.rotation.{uuid.uuid4().hex}")
    logger.propagate = False
    logger.setLevel(logging.INFO)
    logger.addHandler(handler)
    try:
        for n in range(1000):  # ~90 KB: about 45 rotations
            logger.info("record %05d of a long unattended run", n)
    finally:
        logger.removeHandler(handler)
        handler.close()
    files = [path] + [path.with_name(f"{path.name}.{k}") for k in range(1, 6)]
    assert all(f.exists() for f in files) and not path.with_name(f"{path.name}.6").exists()
    assert all(f.stat().st_size <= 2048 for f in files)
    numbers = [int(m) for f in reversed(files) for m in re.findall(r"record (\d{5})", f.read_text("utf-8"))]
    assert numbers == list(range(numbers[0], 1000))  # oldest backup to the live file: none lost, none twice
    assert numbers[0] > 0 and handler.health.ok
