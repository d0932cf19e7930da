"""The running station's local channel: one station per user, found and stopped by ``nfwserver stop``.

A station started by ``nfwserver run`` takes an exclusive lock on ``station.lock`` in the user's state
directory first of all (before it reads its configuration or loads anything heavy) and holds it for as long as
it runs.  It describes itself in ``station.json`` beside it: its process id and start time
(:mod:`nfwserver.cli.station_process`), and, once serving, where it listens (its TCP port, its web dashboard's
address).  The operating system releases the lock when the process ends,
however it ends, so a station killed outright never leaves a "running" station behind: the lock, not the
description, says whether one runs, and a description is believed only about a process it can verify
(:meth:`StationChannel.verified`).  The description never says where to write: the station's control file is
always ``control`` in this same directory (:attr:`StationChannel.default_control`), whatever ``station.json``
holds, so a forged description can make no command write elsewhere.

``nfwserver stop`` signals the verified process (Linux) or sets its named stop event (Windows,
:mod:`nfwserver.cli.stop_event`; the control file only when that cannot be opened) and waits until the lock is
free; ``nfwserver dashboard``, ``status``, ``poke`` and ``watch`` find the station's addresses here, whatever
state the configuration file is in. A second ``nfwserver run`` of the same user while one runs is refused at
once, naming the running one: two stations would offer the same DDE service names and ports.

The lock is :mod:`nfwserver.file_lock`'s (``fcntl.flock`` on Linux, ``msvcrt.locking`` of one byte on
Windows), held here for the whole run; the system releases it at process exit.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

from nfwserver.storage import atomic_write_text

log = logging.getLogger(__name__)

LOCK_NAME = "station.lock"
INFO_NAME = "station.json"
CONTROL_NAME = "control"
#: How long a station starting up retries the lock (a ``stop`` or ``status`` probing it holds it for an instant);
#: not at all when the description names a verified running station.
CLAIM_RETRY_S = 1.0


def user_run_dir() -> Path:
    """The user's state directory, where the lock, the description and the default control file live."""
    from platformdirs import user_state_dir

    return Path(user_state_dir("nfwserver", appauthor=False))


class _Lock:
    """An exclusive, non-blocking lock on one file, held through an open descriptor."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._fd: int | None = None

    def try_acquire(self) -> bool:
        """Take the lock if it is free; True when this object now holds it."""
        from nfwserver.file_lock import try_lock

        if self._fd is not None:
            return True
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | getattr(os, "O_BINARY", 0), 0o600)
        if not try_lock(fd):
            os.close(fd)
            return False
        self._fd = fd
        return True

    def release(self) -> None:
        from nfwserver.file_lock import unlock

        fd, self._fd = self._fd, None
        if fd is None:
            return
        with contextlib.suppress(OSError):
            unlock(fd)
        os.close(fd)


@dataclass(frozen=True)
class StationInfo:
    """What a running station says of itself in ``station.json``."""

    pid: int
    start: int | None = None  #: its process start time (:func:`~nfwserver.cli.station_process.process_start`)
    web_url: str | None = None  #: its dashboard's address, once it serves one
    started: bool = False  #: the station is up (until then its addresses are not known yet)
    tcp: tuple[str, int] | None = None  #: where a client on this machine reaches its TCP port, once it serves one


class StationChannel:
    """The lock, description and control file of the user's station, in ``directory``."""

    def __init__(self, directory: Path | None = None) -> None:
        self.directory = directory if directory is not None else user_run_dir()
        self.lock_path = self.directory / LOCK_NAME
        self.info_path = self.directory / INFO_NAME
        self._lock = _Lock(self.lock_path)
        self._describe_failed = False
        self._description: StationInfo | None = None  # the last one asked for (written again until it is)

    @property
    def default_control(self) -> Path:
        return self.directory / CONTROL_NAME

    # -- the station's side ---------------------------------------------------------------------------
    def claim(self, retry_s: float = CLAIM_RETRY_S) -> bool:
        """Take the lock for this process, and remove a description left by a station that was killed (a
        ``stop`` must never read that one's).  False at once when the lock is held by the station the
        description names (verified); otherwise the lock is retried for ``retry_s`` seconds, for a prober's
        brief hold or a station that has not described itself yet."""
        deadline = time.monotonic() + retry_s
        while not self._lock.try_acquire():
            if time.monotonic() >= deadline or self.verified(self.info()):
                return False
            time.sleep(0.05)
        with contextlib.suppress(OSError):
            self.info_path.unlink()
        return True

    def describe(self, info: StationInfo) -> None:
        """Write ``station.json`` (atomically); only while this process holds the lock.  On Windows the
        replace fails while a reader has the old file open: it is tried again for up to a second."""
        self._description = info
        record = {"pid": info.pid, "start": info.start, "web": info.web_url, "started": info.started,
                  "tcp": list(info.tcp) if info.tcp is not None else None}
        problem: OSError | None = None
        for _ in range(20):
            try:
                atomic_write_text(self.info_path, json.dumps(record) + "\n")
                if self._describe_failed:
                    log.info("the station's description %s is written again", self.info_path)
                self._describe_failed = False
                return
            except PermissionError as exc:
                problem = exc
                time.sleep(0.05)
            except OSError as exc:
                problem = exc
                break
        if not self._describe_failed:  # once per episode: the station runs on without it
            log.warning("cannot write the station's description %s (%s): `nfwserver stop` and `nfwserver "
                        "dashboard` will not find this station until it can (tried again every few tenths of a "
                        "second)", self.info_path, problem)
        self._describe_failed = True

    def describe_again(self) -> None:
        """Write the last description again if writing it failed (the control file's watcher calls this at each
        look, so the station is found again as soon as the file can be written); nothing otherwise."""
        if self._describe_failed and self._description is not None:
            self.describe(self._description)

    def release(self) -> None:
        """Remove the description, then free the lock (the order a waiting ``stop`` relies on)."""
        with contextlib.suppress(OSError):
            self.info_path.unlink()
        self._lock.release()

    # -- everyone else's side -------------------------------------------------------------------------
    def running(self) -> bool:
        """Whether a station holds the lock now (probed by taking it for an instant)."""
        probe = _Lock(self.lock_path)
        try:
            if probe.try_acquire():
                probe.release()
                return False
        except OSError:  # the directory cannot be written: no station of this user could run either
            return False
        return True

    def info(self) -> StationInfo | None:
        """The running station's description as written, or None (none running, not written yet, or not one);
        :meth:`verified` says whether it is the running station's."""
        try:
            record = json.loads(self.info_path.read_text(encoding="utf-8"))
            web, start, tcp = record.get("web"), record.get("start"), record.get("tcp")
            address = (str(tcp[0]), int(tcp[1])) if isinstance(tcp, list) and len(tcp) == 2 else None
            return StationInfo(int(record["pid"]), int(start) if start is not None else None,
                               str(web) if web else None, record.get("started") is True, address)
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return None

    def serving(self) -> StationInfo | None:
        """The running station's verified description once it is up (its addresses known), else None."""
        if not self.running():
            return None
        info = self.info()
        return info if info is not None and info.started and self.verified(info) else None

    def verified(self, info: StationInfo | None) -> bool:
        """Whether ``info`` describes the process holding this channel's lock: its start time is the one
        recorded and, where the system tells (Linux), it is the lock's holder."""
        from nfwserver.cli.station_process import lock_holders, process_start

        if info is None or info.start is None or process_start(info.pid) != info.start:
            return False
        holders = lock_holders(self.lock_path)  # none listed: a file system whose locks the system does not show
        return not holders or info.pid in holders
