"""Forked helper processes (nfwserver/forked_children.py): none outlives a parent that is killed, and forking is
refused where it is not safe."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from nfwserver.forked_children import can_fork
from tests.conftest import ROOT
from tests.waiting import wait_for

# Three children that send without end (each send blocks once the pipe is full); the parent never reads.
_PARENT = """
import signal, sys, time
from nfwserver.forked_children import ForkedChildren

signal.signal(signal.SIGTERM, signal.SIG_DFL)  # a station run in the test process leaves it ignored (inherited)

def talk(results):
    try:
        while True:
            results.send(b"x" * 1_000_000)
    except OSError:  # the parent has gone: nobody reads this pipe any more
        pass
    finally:
        results.close()

with ForkedChildren("a talking") as children:
    for _ in range(3):
        children.start(talk, ())
    print(" ".join(str(p.pid) for p in children._processes), flush=True)
    time.sleep(600)
"""


def _gone(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return True
    return state in ("Z", "X")  # ended (a zombie waits only for whoever adopted it to reap it)


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_no_child_outlives_a_killed_parent(sig: signal.Signals) -> None:
    """Each child closes the parent's reading ends it inherited, so the parent's death breaks its pipe."""
    parent = subprocess.Popen([sys.executable, "-c", _PARENT], cwd=ROOT, stdout=subprocess.PIPE, text=True)
    children: list[int] = []
    try:
        assert parent.stdout is not None
        children = [int(pid) for pid in parent.stdout.readline().split()]
        assert len(children) == 3 and not any(_gone(pid) for pid in children)
        parent.send_signal(sig)
        parent.wait(timeout=30)
        wait_for(lambda: all(_gone(pid) for pid in children), timeout_s=30, what="every child ended")
    finally:
        for pid in [parent.pid, *children]:  # (the children too, should this test fail)
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        parent.wait()
        if parent.stdout is not None:
            parent.stdout.close()


def test_forking_is_refused_while_other_threads_run() -> None:
    assert can_fork() is (sys.platform != "win32" and threading.active_count() == 1)
    release = threading.Event()
    other = threading.Thread(target=release.wait, daemon=True)
    other.start()
    try:
        assert not can_fork()
    finally:
        release.set()
        other.join()


def test_the_pid_helper_sees_a_live_process() -> None:
    assert not _gone(os.getpid())
