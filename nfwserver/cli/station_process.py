"""Is process ``pid`` the station?  Its start time, the lock it holds, whether it runs or is suspended.

A process id alone names a process only while that process lives: once it ends, the system may give the id
to any other program.  A station therefore records its own start time in its description
(:mod:`nfwserver.cli.station_channel`), and ``nfwserver stop`` signals a process only when its start time is
the recorded one **and**, where the system tells (Linux ``/proc/locks``), it is the process holding the
station's lock: a description written by someone else (naming, say, a live ``sleep`` and copying its start
time) names a process that holds no such lock.

- :func:`process_start`: a process's start time as an opaque integer, or None when it does not run or the
  system cannot tell.  Linux: field 22 of ``/proc/PID/stat`` (clock ticks since boot); Windows: the creation
  time from ``GetProcessTimes`` (100 ns units since 1601).
- :func:`lock_holders`: the processes holding a ``flock`` on a file (Linux), or None where unknown.
- :func:`suspended`: whether a process is stopped by a signal (``SIGSTOP``, Ctrl+Z; Linux state ``T``).
- :func:`process_ended`: whether it has ended (a zombie counts as ended).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

#: Windows access right enough for GetProcessTimes and waiting (PROCESS_QUERY_LIMITED_INFORMATION | SYNCHRONIZE).
_QUERY_AND_WAIT = 0x1000 | 0x00100000


def _proc_stat_fields(pid: int) -> list[bytes] | None:
    """The fields of ``/proc/PID/stat`` after the command name (state first), or None."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as stat:
            return stat.read().rsplit(b")", 1)[1].split()
    except (OSError, IndexError):
        return None


def process_start(pid: int) -> int | None:
    """When process ``pid`` started, in the system's own units (compare, never convert); None if unknown."""
    if pid <= 0:
        return None
    if sys.platform == "win32":
        return _windows_creation_time(pid)
    fields = _proc_stat_fields(pid)
    if fields is None or len(fields) < 20:
        return None
    try:
        return int(fields[19])  # field 22 of the whole line: state is field 3, the first after the name
    except ValueError:
        return None


def _windows_creation_time(pid: int) -> int | None:
    """The creation time of Windows process ``pid`` (100 ns since 1601), or None."""
    if sys.platform != "win32":
        return None
    import ctypes
    from ctypes import wintypes

    kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)
    handle = kernel32.OpenProcess(_QUERY_AND_WAIT, False, pid)
    if not handle:
        return None
    try:
        created, ended, kernel, user = (wintypes.FILETIME() for _ in range(4))
        if not kernel32.GetProcessTimes(handle, ctypes.byref(created), ctypes.byref(ended), ctypes.byref(kernel),
                                        ctypes.byref(user)):
            return None
        return (int(created.dwHighDateTime) << 32) | int(created.dwLowDateTime)
    finally:
        kernel32.CloseHandle(handle)


def lock_holders(path: Path, locks: Path = Path("/proc/locks")) -> set[int] | None:
    """The ids of the processes holding a ``flock`` on ``path`` (from ``locks``, Linux); None where unknown."""
    try:
        inode = os.stat(path).st_ino
        text = locks.read_text(encoding="ascii", errors="replace")
    except OSError:
        return None
    holders: set[int] = set()
    for line in text.splitlines():
        fields = line.split()
        # "1: FLOCK  ADVISORY  WRITE 16533 fe:00:2163859 0 EOF" (a waiter's line has "->" after the number)
        if (len(fields) >= 6 and fields[1] == "FLOCK" and fields[4].isdigit()
                and fields[5].rsplit(":", 1)[-1] == str(inode)):
            holders.add(int(fields[4]))
    return holders


def suspended(pid: int) -> bool:
    """Whether process ``pid`` is stopped by a signal (it acts on nothing until it is continued); Linux only."""
    fields = _proc_stat_fields(pid)
    return fields is not None and bool(fields) and fields[0] in (b"T", b"t")


def process_ended(pid: int) -> bool:
    """Whether process ``pid`` has ended (a zombie left for its parent to reap counts as ended)."""
    if sys.platform == "win32":
        import ctypes

        wait_timeout = 0x102
        kernel32 = ctypes.WinDLL("kernel32", use_last_error=True)
        handle = kernel32.OpenProcess(_QUERY_AND_WAIT, False, pid)
        if not handle:
            return True  # no such process (any more)
        try:
            return bool(kernel32.WaitForSingleObject(handle, 0) != wait_timeout)
        finally:
            kernel32.CloseHandle(handle)
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    fields = _proc_stat_fields(pid)
    return fields is not None and bool(fields) and fields[0] == b"Z"
