"""Ending a Wine launcher together with the Windows program under it (Linux side).

``tools/wine/run`` and ``tools/wine/nfwserver`` run the program under ``timeout``, which puts it in a
process group of its own, and the launcher may be gone while the program still runs; killing the
launcher's pid or group then leaves ``python.exe`` serving (a station keeps ``NFW32`` registered
until its ``--duration`` ends, into whatever runs next).  Start launchers with
``start_new_session=True`` and end them with :func:`kill_session`: every process of that session.
Wine's own ``wineserver`` runs in a session of its own and is not touched.
"""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

from tests.waiting import wait_for


def session_members(sid: int) -> list[int]:
    """Pids of the live (not zombie) processes whose session id is ``sid`` (from /proc)."""
    pids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue  # the process ended meanwhile
        if int(fields[3]) == sid and fields[0] != "Z":  # after "pid (comm)": state ppid pgrp session ...
            pids.append(int(stat.parent.name))
    return pids


def kill_session(proc: subprocess.Popen, timeout_s: float = 30.0) -> None:
    """SIGKILL every process in ``proc``'s session (``proc`` was started with ``start_new_session``).

    Reading /proc and signalling are not one step: a member may start another process in between (``timeout``
    starting the program, a launcher starting ``wine``), which a single pass would leave running.  So the
    session is read and killed again until no live member is left (or ``timeout_s`` passes: WaitTimeout).
    """
    def emptied() -> bool:
        members = session_members(proc.pid)
        for pid in members:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        return not members  # else let the signalled ones die before the session is read again

    wait_for(emptied, timeout_s, lambda: f"session {proc.pid} to be empty after SIGKILL (left: "
             f"{session_members(proc.pid)})")
    if proc.poll() is None:
        proc.wait(timeout_s)
