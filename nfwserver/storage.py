"""Atomic file writes: a crash mid-write leaves the previous file intact, and nothing behind for long.

The new content goes to a temporary file in the same directory (``.NAME.PID.RANDOM.tmp``), is
flushed and fsync'ed, then replaces the target with ``os.replace`` (atomic on POSIX and Windows), and
the directory is fsync'ed where the platform allows it.  The replacement keeps the target's
permission bits (and, where allowed, its owner); a new file gets the usual ``0666`` less the umask.

A process killed between creating the temporary and the replace leaves the temporary behind.
:func:`remove_stale_temporaries` removes those of a target whose writer is gone (its PID no longer
runs, or -- where that cannot be asked, or for names without a PID -- the file is older than
:data:`STALE_AFTER_S`); stores call it when they are opened.
"""

from __future__ import annotations

import contextlib
import os
import re
import stat
import sys
import time
from pathlib import Path

#: Age (seconds) after which a temporary whose writer cannot be identified is taken as abandoned.
STALE_AFTER_S = 600.0


def _temporary_name(target: Path) -> Path:
    """A fresh name beside ``target``: pid and 8 random hex digits (``os.urandom``: the ``secrets`` module
    would load OpenSSL's libcrypto, 3.5 MiB in every command that writes or reads a state file)."""
    return target.with_name(f".{target.name}.{os.getpid()}.{os.urandom(4).hex()}.tmp")


def _create_like(tmp: Path, target: Path, mode: int | None = None) -> int:
    """Open ``tmp`` exclusively, with ``target``'s mode and owner if it exists; ``mode``, when given, instead
    of the mode (set before anything is written, so a secret never sits in a readable file)."""
    try:
        st: os.stat_result | None = os.stat(target)
    except OSError:
        st = None
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0),
                 0o666 if mode is None else mode)
    if st is not None:
        if sys.platform != "win32":  # Windows has no owner ids to keep
            with contextlib.suppress(OSError):
                if (st.st_uid, st.st_gid) != (os.geteuid(), os.getegid()):
                    os.fchown(fd, st.st_uid, st.st_gid)
        if hasattr(os, "fchmod"):
            os.fchmod(fd, stat.S_IMODE(st.st_mode))
        else:  # pragma: no cover - Windows: only the read-only bit exists
            os.chmod(tmp, stat.S_IMODE(st.st_mode))
    if mode is not None and hasattr(os, "fchmod"):
        os.fchmod(fd, mode)  # before a byte is written
    return fd


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes, mode: int | None = None) -> None:
    """Replace ``path`` with ``data`` atomically, keeping its permissions (or giving it ``mode``)."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = _temporary_name(target)
    fd = _create_like(tmp, target, mode)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    if hasattr(os, "O_DIRECTORY"):
        with contextlib.suppress(OSError):
            dir_fd = os.open(target.parent, os.O_DIRECTORY)
            try:
                os.fsync(dir_fd)
            finally:
                os.close(dir_fd)


def atomic_write_text(path: str | os.PathLike[str], text: str, mode: int | None = None) -> None:
    atomic_write_bytes(path, text.encode("utf-8"), mode)


def _pid_running(pid: int) -> bool | None:
    """True/False where the platform can tell, None where it cannot."""
    if sys.platform == "win32" or pid <= 0:
        return None
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, but not ours to signal
        return True
    return True


def remove_stale_temporaries(path: str | os.PathLike[str], now: float | None = None) -> list[Path]:
    """Remove temporaries of ``path`` left by writers that are gone; returns what was removed.

    ``now`` (POSIX seconds, for the age rule) defaults to the file system's idea of the present.
    Never raises: a temporary that cannot be examined or removed is left alone.
    """
    target = Path(path)
    pattern = re.compile(rf"\.{re.escape(target.name)}\.(?:(\d+)\.)?[A-Za-z0-9_]+\.tmp")
    removed: list[Path] = []
    try:
        candidates = [p for p in target.parent.iterdir() if pattern.fullmatch(p.name)]
    except OSError:
        return removed
    for tmp in candidates:
        match = pattern.fullmatch(tmp.name)
        pid_text = match.group(1) if match is not None else None
        running = _pid_running(int(pid_text)) if pid_text else None
        if running is None:
            try:
                age = (time.time() if now is None else now) - tmp.stat().st_mtime
            except OSError:
                continue
            running = age < STALE_AFTER_S
        if running:
            continue
        with contextlib.suppress(OSError):
            tmp.unlink()
            removed.append(tmp)
    return removed
