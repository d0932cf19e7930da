"""A Windows client program that exits without disconnecting (killed while it holds a hot advise loop):
the station drops its conversation with one log line, and the other clients keep their stream.

Without that, every ``DdePostAdvise`` fails on the dead client's link (``DMLERR_POSTMSG_FAILED``,
0x400C) with a traceback in the log, and under Wine, which posts to the newest link first and stops at
the failure, the clients that connected before it get nothing at all.  Runs where DDEML exists
(``tools/wine/test``, or Windows).
"""

from __future__ import annotations

import json
import logging
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from tests.waiting import wait_for
from tests.windows.conftest import serving_station
from tests.windows.test_wine_advise_copies import pump_messages

pytestmark = [
    pytest.mark.windows,
    pytest.mark.skipif(sys.platform != "win32", reason="needs Windows DDEML"),
]

CLIENTS = Path(__file__).resolve().parent / "dde_clients.py"
SERVICES = ("NFW_GONE_A", "NFW_GONE_B")  # names of their own: the suite's other stations serve Nova's


def clients_program(service: str, seconds: float, out: Path, start_at: float = 0.0) -> subprocess.Popen[bytes]:
    return subprocess.Popen([sys.executable, str(CLIENTS), "--clients", "1", "--seconds", f"{seconds:g}",
                             "--services", service, "--out", str(out), "--start-at", f"{start_at:.3f}"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def pump_until(condition, timeout_s: float, what: str | Callable[[], str]) -> None:
    """Pump this thread's DDE messages 0.1 s at a time until ``condition`` holds; fail after ``timeout_s``."""
    def pumped() -> bool:
        if condition():
            return True
        pump_messages(0.1)
        return False

    wait_for(pumped, timeout_s, what, interval_s=0.0)


def test_a_client_killed_while_it_holds_a_hot_link_is_dropped_in_one_line(tmp_path, caplog) -> None:
    caplog.set_level(logging.INFO)
    with serving_station(SERVICES) as station:
        # The survivor connects first, so under Wine its link comes after the victim's; it counts the
        # strings it gets in a 3 s window that starts once the victim has been killed.
        window_at = time.time() + 25.0
        survivor = clients_program(SERVICES[0], 3.0, tmp_path / "survivor.json", start_at=window_at)
        victim = None
        try:
            pump_until(lambda: station.client_count()[1] == 1, 20.0,
                       lambda: f"one advise link ({station.client_count()})")
            victim = clients_program(SERVICES[1], 120.0, tmp_path / "victim.json")
            pump_until(lambda: station.client_count()[1] == 2, 20.0,
                       lambda: f"two advise links ({station.client_count()})")
            pump_messages(0.5)  # both links served for a few ticks
            victim.kill()  # TerminateProcess: no DdeDisconnect, no XTYP_DISCONNECT
            victim.wait(10)
            pump_until(lambda: station.client_count() == (1, 1), 5.0,
                       lambda: f"the victim dropped ({station.client_count()})")
            assert time.time() < window_at, "the survivor's window started before the victim was gone"
            pump_until(lambda: survivor.poll() is not None, 60.0, "the survivor to finish")
        finally:
            for program in (survivor, victim):
                if program is not None and program.poll() is None:
                    program.kill()
        record = json.loads((tmp_path / "survivor.json").read_text())[0]
        assert survivor.returncode == 0 and record["error"] is None and not record["late"], record
        # 10 Hz for 3 s: the survivor's stream goes on (0 without the drop, under Wine)
        assert record["advise"] >= 20 and record["program_deliveries"]["no data"] == 0, record
        assert record["still_connected"], record
    dropped = [r for r in caplog.records if "gone without disconnecting" in r.getMessage()]
    assert len(dropped) == 1, [r.getMessage() for r in dropped]
    assert "NFW_GONE_B/NFW_DATA" in dropped[0].getMessage() and "conversation dropped" in dropped[0].getMessage()
    assert dropped[0].levelno == logging.WARNING
    assert not [r for r in caplog.records if r.exc_info], [r.getMessage() for r in caplog.records if r.exc_info]
    assert not [r for r in caplog.records if "DdePostAdvise" in r.getMessage() and "failed" in r.getMessage()]
