"""kill_session ends a program its launcher left behind (the case of a Wine launcher under ``timeout``)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.waiting import wait_for
from tests.windows.wine_session import kill_session, session_members

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="Linux processes")


def _programs(sid: int) -> list[str]:
    """The command names of the live processes of session ``sid``."""
    names = []
    for pid in session_members(sid):
        try:
            names.append(Path(f"/proc/{pid}/comm").read_text().strip())
        except OSError:
            continue  # ended meanwhile
    return names


def test_kill_session_ends_the_program_the_launcher_left_running() -> None:
    # Like nfw_wine_exec: `timeout` runs the program in a process group of its own; the launcher exits.
    launcher = subprocess.Popen(["bash", "-c", "timeout 60 sleep 60 & exit 0"], start_new_session=True)
    launcher.wait(10)
    # The program itself, not only `timeout` (which starts it a moment later), must be running to be left behind.
    wait_for(lambda: "sleep" in _programs(launcher.pid), what="the program to outlive its launcher")
    kill_session(launcher)
    assert session_members(launcher.pid) == []  # kill_session returns when nothing of the session is left


def test_kill_session_ends_what_a_member_starts_while_it_is_being_killed() -> None:
    # A member that keeps starting programs (as `timeout` starts the program, or a launcher starts wine)
    # between kill_session's reading of the session and its signals: nothing may be left running.
    launcher = subprocess.Popen(["bash", "-c", "bash -c 'for i in $(seq 400); do sleep 60 & done; wait' & exit 0"],
                                start_new_session=True)
    launcher.wait(10)
    assert wait_for(lambda: len(session_members(launcher.pid)) >= 20)
    try:
        kill_session(launcher)
        assert session_members(launcher.pid) == []
    finally:
        for _ in range(3):  # whatever an unfixed kill_session left behind must not outlive the test
            for pid in session_members(launcher.pid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            time.sleep(0.05)
