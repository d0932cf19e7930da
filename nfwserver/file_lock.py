"""An exclusive lock for a read-modify-write of a file shared between processes (``config set``, ``elements
update``, the station's own element refresher).

The lock is taken on a sidecar file beside the target (``.NAME.lock``, never removed), not on the target
itself: the target is replaced whole by :func:`nfwserver.storage.atomic_write_bytes`, so a lock on it would
be on the old file.  POSIX uses ``fcntl.flock`` and Windows ``msvcrt.locking`` on the sidecar's first byte;
both are released by the system when the holder exits, so a killed writer never leaves it locked.  Waiting
is bounded: :class:`LockTimeout` after ``timeout_s`` real seconds names the lock file.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["LockTimeout", "locked", "try_lock", "unlock"]

#: How often a waiting writer tries again (real seconds).
POLL_S = 0.02


class LockTimeout(OSError):
    """Another writer held the lock for longer than the wait allowed."""


def lock_path(target: Path) -> Path:
    """The sidecar lock file of ``target``."""
    return target.with_name(f".{target.name}.lock")


def try_lock(fd: int) -> bool:
    """Take the exclusive lock of the open file ``fd`` if it is free (its first byte on Windows); True if taken."""
    if sys.platform == "win32":
        import msvcrt

        try:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        except OSError:
            return False
        return True
    import fcntl

    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def unlock(fd: int) -> None:
    """Release the lock :func:`try_lock` took on ``fd``."""
    if sys.platform == "win32":
        import msvcrt

        os.lseek(fd, 0, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
    else:
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_UN)


@contextmanager
def locked(target: str | os.PathLike[str], timeout_s: float = 30.0) -> Iterator[None]:
    """Hold the exclusive lock of ``target`` for the block (any process, any thread: each call opens its own
    descriptor).  Raises :class:`LockTimeout` when it cannot be had within ``timeout_s``, or
    :class:`OSError` when the lock file cannot be created (a read-only directory)."""
    path = lock_path(Path(target))
    path.parent.mkdir(parents=True, exist_ok=True)
    fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_BINARY", 0), 0o600)
    try:
        deadline = time.monotonic() + timeout_s
        while not try_lock(fd):
            if time.monotonic() >= deadline:
                raise LockTimeout(f"{path} is held by another writer (waited {timeout_s:g} s)")
            time.sleep(POLL_S)
        try:
            yield
        finally:
            unlock(fd)
    finally:
        os.close(fd)
