"""``nfwserver stop`` on Windows needs no disk write: it sets the verified station's named stop event
(nfwserver/cli/stop_event.py), and withdraws exactly the request the station has not taken.

Real ``nfwserver run --headless`` processes, the real ``nfwserver stop`` program, real kernel events (Windows, or
the Windows Python under Wine).  Each station gets a state folder of its own (platformdirs'
``WIN_PD_OVERRIDE_LOCAL_APPDATA``), and DDE service names of its own, so it never meets
the suite's other station.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.waiting import wait_for
from tests.windows.station_config import write_station_config

pytestmark = pytest.mark.skipif(sys.platform != "win32", reason="Windows kernel events (tools/wine/test)")
ROOT = Path(__file__).resolve().parent.parent.parent
#: ``[server]`` lines of these stations: DDE names and no TCP port of their own, beside the suite's station.
OWN_NAMES = "services = ['NFW_STOP_TEST']\n[tcp]\nenabled = false\n"


def _env(home: Path) -> dict[str, str]:
    return {**os.environ, "WIN_PD_OVERRIDE_LOCAL_APPDATA": str(home / "local"),
            "WIN_PD_OVERRIDE_APPDATA": str(home / "roaming")}


def _run_station(tmp_path: Path) -> tuple[subprocess.Popen[bytes], Path]:
    """A headless station of this user (its own names, folders under ``tmp_path``) for 300 s, and its log."""
    config = write_station_config(tmp_path / "cfg", extra=OWN_NAMES)
    log = tmp_path / "station.log"
    station = subprocess.Popen(
        [sys.executable, "-m", "nfwserver", "run", "--headless", "--config", str(config), "--log-file", str(log),
         "--duration", "300"], cwd=ROOT, env=_env(tmp_path), stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE)
    return station, log


def test_stop_stops_the_station_when_its_control_file_cannot_be_written(tmp_path) -> None:
    from nfwserver.cli.station_channel import StationChannel

    station, log = _run_station(tmp_path)
    try:
        channel = StationChannel(tmp_path / "local" / "nfwserver")
        wait_for(lambda: station.poll() is not None or channel.serving() is not None, 90, "the station to serve")
        assert station.poll() is None, station.stderr.read() if station.stderr else ""
        channel.default_control.mkdir()  # the control file cannot be written (as on a full disk)
        done = subprocess.run([sys.executable, "-m", "nfwserver", "stop", "--timeout", "60"], cwd=ROOT,
                              env=_env(tmp_path), stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              timeout=120)
        assert done.returncode == 0, done.stdout + done.stderr
        assert f"stopped the station (process {station.pid})" in done.stdout
        assert station.wait(30) == 0
        text = log.read_text(encoding="utf-8", errors="replace")
        assert "nfwserver stop (event Local\\nfwserver-stop-" in text and "stopped" in text, text[-2000:]
    finally:
        if station.poll() is None:
            station.kill()
            station.wait(10)


def _own_event(start: int) -> int:
    """An auto-reset event under the name the station ``(this process, start)`` would create, as the station does."""
    import ctypes

    from nfwserver.cli.stop_event import event_name

    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)
    kernel32.CreateEventW.restype = ctypes.c_void_p
    handle = kernel32.CreateEventW(None, False, False, event_name(os.getpid(), start))
    assert handle
    return int(handle)


def _taken(handle: int) -> bool:
    """Take the event if it is set (the station's wait), True when it was."""
    import ctypes

    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)
    return bool(kernel32.WaitForSingleObject(ctypes.c_void_p(handle), 0) == 0)


def test_a_withdrawn_request_never_reaches_the_station_and_a_taken_one_is_said_to_be_taken() -> None:
    import ctypes

    from nfwserver.cli.stop_event import ask_to_stop

    handle = _own_event(start=424242)
    try:
        assert ask_to_stop(os.getpid(), 1) is None  # no such event: `stop` falls back to the control file
        sent = ask_to_stop(os.getpid(), 424242)
        assert sent is not None
        assert sent.withdraw() is True  # not taken yet: taken back ...
        assert not _taken(handle)  # ... so the station never sees it
        sent = ask_to_stop(os.getpid(), 424242)
        assert sent is not None
        assert _taken(handle)  # the station takes it ...
        assert sent.withdraw() is False  # ... and `stop` says so
    finally:
        ctypes.WinDLL("kernel32").CloseHandle(ctypes.c_void_p(handle))


def test_a_name_taken_before_the_station_creates_its_event_is_not_trusted() -> None:
    import ctypes

    from nfwserver.cli.stop_event import StopEvent

    handle = _own_event(start=515151)
    try:
        assert StopEvent.create(os.getpid(), 515151, lambda _word, _origin: None) is None
    finally:
        ctypes.WinDLL("kernel32").CloseHandle(ctypes.c_void_p(handle))


def _suspend(pid: int, resume: bool = False) -> None:
    """Suspend (or resume) every thread of process ``pid`` (``NtSuspendProcess``, as a debugger does)."""
    import ctypes

    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)
    kernel32.OpenProcess.restype = ctypes.c_void_p
    handle = kernel32.OpenProcess(0x0800, False, pid)  # PROCESS_SUSPEND_RESUME
    assert handle
    try:
        ntdll = ctypes.WinDLL("ntdll")
        call = ntdll.NtResumeProcess if resume else ntdll.NtSuspendProcess
        assert call(ctypes.c_void_p(handle)) == 0
    finally:
        kernel32.CloseHandle(ctypes.c_void_p(handle))


def test_a_stop_that_gives_up_on_a_suspended_station_withdraws_its_request_and_the_station_goes_on(tmp_path) -> None:
    from nfwserver.cli.station_channel import StationChannel

    station, log = _run_station(tmp_path)

    def stop(timeout_s: float) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "nfwserver", "stop", "--timeout", f"{timeout_s:g}"], cwd=ROOT,
                              env=_env(tmp_path), stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              timeout=120)

    try:
        channel = StationChannel(tmp_path / "local" / "nfwserver")
        wait_for(lambda: station.poll() is not None or channel.serving() is not None, 90, "the station to serve")
        channel.default_control.mkdir()  # nothing can be written, as on a full disk
        _suspend(station.pid)
        try:
            gave_up = stop(1.0)
        finally:
            _suspend(station.pid, resume=True)
        assert gave_up.returncode == 3, gave_up.stdout + gave_up.stderr
        assert "the request is withdrawn: it will go on running" in gave_up.stderr
        assert station.poll() is None and "stopping" not in log.read_text(encoding="utf-8", errors="replace")
        done = stop(60.0)  # the station was never asked: this stop is the one that ends it
        assert done.returncode == 0, done.stdout + done.stderr
        assert station.wait(30) == 0
        assert log.read_text(encoding="utf-8", errors="replace").count("nfwserver stop (event") == 1
    finally:
        if station.poll() is None:
            station.kill()
            station.wait(10)
