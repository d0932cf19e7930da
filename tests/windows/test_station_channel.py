"""The station's channel on Windows (issues 42 and 45): a second ``run`` refused naming the running station,
``status`` reaching it whatever its configuration file says, ``stop`` through the station's stop event (and,
through the control file, its request withdrawn when the station has not taken it in time), the station verified by
its start time (``GetProcessTimes``).

Runs only on Windows or under Wine (``tools/wine/test``); on Linux tests/app/test_stop_command.py and
test_stop_hostile.py check the POSIX side (signals, ``/proc/locks``).  Each test gets a state folder of its own
(``WIN_PD_OVERRIDE_LOCAL_APPDATA``, platformdirs' override of ``%LOCALAPPDATA%``), so the suite's own session
station does not count as "a station already running".
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from nfwserver.cli.stop_event import event_name
from tests.waiting import wait_for
from tests.windows.station_config import write_station_config

pytestmark = pytest.mark.skipif(sys.platform != "win32", reason="the station's Windows channel")

ROOT = Path(__file__).resolve().parent.parent.parent


@pytest.fixture
def state_folder(tmp_path, monkeypatch) -> Path:
    """``%LOCALAPPDATA%\\nfwserver`` of this test alone (the configuration file and the channel live there)."""
    appdata = tmp_path / "appdata"
    appdata.mkdir()
    monkeypatch.setenv("WIN_PD_OVERRIDE_LOCAL_APPDATA", str(appdata))
    return appdata / "nfwserver"


def nfwserver(*args: str, timeout_s: float = 120.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "nfwserver", *args], cwd=ROOT, stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=timeout_s)


def test_the_channel_names_the_running_station_and_stop_ends_it_cleanly(tmp_path, state_folder) -> None:
    from nfwserver.cli.station_channel import StationChannel
    from nfwserver.cli.station_process import process_start

    config = write_station_config(tmp_path, extra="[tcp]\nenabled = true\nport = 0\n")
    log = tmp_path / "station.log"
    station = subprocess.Popen(
        [sys.executable, "-m", "nfwserver", "run", "--headless", "--config", str(config), "--log-file", str(log),
         "--duration", "300"], cwd=ROOT, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE, text=True)
    try:
        channel = StationChannel(state_folder)
        info = wait_for(channel.serving, 60, "the station to describe itself as up in its own state folder")
        assert info.pid == station.pid and info.tcp is not None
        # The start time is the process's creation time (GetProcessTimes), not a value of the station's making.
        assert info.start is not None and info.start == process_start(station.pid)

        second = nfwserver("run", "--headless", "--config", str(config), "--duration", "5")
        assert second.returncode == 1, second.stdout + second.stderr
        assert second.stderr.strip() == (f"nfwserver: a station is already running for this user (process "
                                         f"{station.pid}): `nfwserver stop` stops it")

        (state_folder / "config.toml").write_text("[tcp\nport = 1\n", encoding="utf-8")  # a TOML syntax error
        status = nfwserver("status")
        assert status.returncode == 0, status.stderr
        assert status.stdout.startswith("satellite=25544 name=ISS "), status.stdout
        warnings = [line for line in status.stderr.splitlines() if "configuration refused" in line]
        assert len(warnings) == 1 and "not valid TOML" in warnings[0], status.stderr
        assert warnings[0].endswith("the running station runs on its last good configuration")

        stop = nfwserver("stop", "--timeout", "60")
        assert stop.returncode == 0, stop.stderr
        assert stop.stdout.strip() == f"stopped the station (process {station.pid})"
        assert station.poll() == 0  # ended (stop waits for the process itself), and cleanly: not killed
        text = log.read_text(encoding="utf-8")
        # the station's stop event (nfwserver/cli/stop_event.py): no file written (test_stop_event.py)
        assert f"nfwserver stop (event {event_name(info.pid, info.start)}): stopping" in text, text[-2000:]
        assert not (state_folder / "control").exists()
        assert text.rstrip().endswith("stopped")
        assert not (state_folder / "station.json").exists()

        again = nfwserver("stop")
        assert again.returncode == 1 and again.stderr.strip().endswith(
            "no station is running for this user: nothing to stop"), again.stderr
    finally:
        if station.poll() is None:
            station.kill()
        station.wait(30)
        if station.stderr is not None:
            station.stderr.close()


#: A process that holds the channel as a station does (the lock, a description verified by its start time) but
#: never looks at its control file: a station too busy to take a request in time.
DEAF_STATION = """
import os, sys, time
from pathlib import Path
from nfwserver.cli.station_channel import StationChannel, StationInfo
from nfwserver.cli.station_process import process_start
channel = StationChannel(Path(sys.argv[1]))
assert channel.claim(retry_s=0)
channel.describe(StationInfo(os.getpid(), process_start(os.getpid()), started=True))
print("up", flush=True)
sys.stdin.read()
"""


def test_stop_withdraws_its_request_when_the_station_has_not_taken_it_in_time(state_folder) -> None:
    from nfwserver.cli.station_channel import StationChannel

    deaf = subprocess.Popen([sys.executable, "-c", DEAF_STATION, str(state_folder)], cwd=ROOT, stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    try:
        assert deaf.stdout is not None and deaf.stdout.readline().strip() == "up"
        assert StationChannel(state_folder).verified(StationChannel(state_folder).info())
        stop = nfwserver("stop", "--timeout", "1")
        assert stop.returncode == 3, stop.stdout + stop.stderr
        assert stop.stderr.strip() == (
            f"nfwserver: the station (process {deaf.pid}) was asked to stop but is still running after 1 s; the "
            "request is withdrawn: it will go on running (its log says what it is waiting for)")
        assert not (state_folder / "control").exists()  # a station looking later finds nothing to act on
        assert deaf.poll() is None
    finally:
        if deaf.stdin is not None:
            deaf.stdin.close()
        deaf.wait(30)
