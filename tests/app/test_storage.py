"""Atomic writes keep the file's permissions; temporaries of writers that are gone are removed at start
(issue 18 item 13)."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from nfwserver.app.element_store import ElementStore
from nfwserver.app.session_state import SessionState, StateFile
from nfwserver.storage import STALE_AFTER_S, atomic_write_text, remove_stale_temporaries

posix_only = pytest.mark.skipif(sys.platform == "win32", reason="POSIX permission bits")


@posix_only
@pytest.mark.parametrize("mode", [0o644, 0o640, 0o600, 0o664])
def test_a_replaced_file_keeps_its_permission_bits(tmp_path, mode: int) -> None:
    target = tmp_path / "elements.txt"
    target.write_text("old\n")
    target.chmod(mode)
    atomic_write_text(target, "new\n")
    assert target.read_text() == "new\n" and target.stat().st_mode & 0o777 == mode


@posix_only
def test_a_new_file_gets_the_umask_default_not_0600(tmp_path) -> None:
    old = os.umask(0o022)
    try:
        atomic_write_text(tmp_path / "new.txt", "x")
    finally:
        os.umask(old)
    assert (tmp_path / "new.txt").stat().st_mode & 0o777 == 0o644


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


@posix_only
def test_only_temporaries_of_writers_that_are_gone_are_removed(tmp_path) -> None:
    target = tmp_path / "elements.txt"
    target.write_text("catalog\n")
    dead = tmp_path / f".elements.txt.{_dead_pid()}.abcd1234.tmp"
    alive = tmp_path / f".elements.txt.{os.getpid()}.abcd1234.tmp"  # a write in progress right now
    old_style = tmp_path / ".elements.txt.k2j_x9q1.tmp"  # mkstemp's name, before PIDs were in it
    recent_old_style = tmp_path / ".elements.txt.zz9_aa11.tmp"
    other = tmp_path / ".state.json.123.abcd.tmp"
    for path in (dead, alive, old_style, recent_old_style, other):
        path.write_text("partial")
    past = time.time() - STALE_AFTER_S - 10
    os.utime(old_style, (past, past))
    removed = remove_stale_temporaries(target)
    assert sorted(removed) == sorted([dead, old_style])
    assert alive.exists() and recent_old_style.exists() and other.exists() and target.exists()


@posix_only
def test_stores_clean_up_when_opened(tmp_path) -> None:
    store = tmp_path / "elements.txt"
    state = tmp_path / "state.json"
    leftovers = [tmp_path / f".elements.txt.{_dead_pid()}.0011aabb.tmp", tmp_path / f".state.json.{_dead_pid()}.ff.tmp"]
    for path in leftovers:
        path.write_text("x" * 1000)
    ElementStore(store)
    StateFile(state).save(SessionState(7))
    assert not any(p.exists() for p in leftovers)
    assert StateFile(state).load() == SessionState(7)
