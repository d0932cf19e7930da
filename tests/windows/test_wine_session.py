"""kill_session ends a program its launcher left behind (the case of a Wine launcher under ``timeout``)."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from tests.windows.wine_session import kill_session, session_members

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="Linux processes")


def test_kill_session_ends_the_program_the_launcher_left_running() -> None:
    # Like nfw_wine_exec: `timeout` runs the program in a process group of its own; the launcher exits.
    launcher = subprocess.Popen(["bash", "-c", "timeout 60 sleep 60 & exit 0"], start_new_session=True)
    launcher.wait(10)
    deadline = time.monotonic() + 5
    while not session_members(launcher.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    left = session_members(launcher.pid)
    assert left, "the program should outlive its launcher"
    kill_session(launcher)
    deadline = time.monotonic() + 5
    while session_members(launcher.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert session_members(launcher.pid) == []
