"""Watching the configuration file while the station runs.

:class:`ConfigWatcher` checks the file's size and modification time every ``interval_s`` seconds of
the station's clock, waits until a change has stopped changing (a writer may be halfway through),
then reads it.  Only a file that is whole is applied: it must parse and validate completely, hold at
least one setting (an empty or comment-only file is what an editor leaves halfway through a save,
never "reset everything to the defaults") and be unchanged between the start and the end of the read.
A valid file is handed to ``apply`` (the station's live reload); anything else is handed to ``refused``
with one sentence and the running configuration stays until a good file arrives.  Only regular files
are read, so a FIFO or device put in place of the file never blocks the watcher.

:meth:`ConfigWatcher.request` asks for a read now, whether or not the file looks changed (SIGHUP, the
daemon convention: ``nfwserver run`` calls it through ``Station.reload_config``); the same rules apply.
With ``interval_s=None`` the watcher reads only on request.

:meth:`ConfigWatcher.catch_up` applies a change at once on the caller's thread, for a check that must see
the file as it is now (the web face's control switch and token, before each command: ``config set
web.token`` has taken effect when it returns).  It costs one ``stat`` when nothing changed; a changed file is
read and applied only when whole and valid (``config set`` replaces the file in one rename), else it is left
to the watcher's thread, which settles and reports it as above.  Reading and applying are serialised.

Owned by its own thread, ``nfw-config``; it waits on the injected clock, so tests drive it with a
:class:`~nfwserver.clock.VirtualClock`.
"""

from __future__ import annotations

import logging
import os
import stat
import threading
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from nfwserver.clock import Clock
from nfwserver.config.schema import Config
from nfwserver.core.service_thread import ServiceThread

log = logging.getLogger(__name__)

Signature = tuple[int, int, int] | None  # (mtime ns, size, inode) of a regular file; None if absent/unusable


def file_signature(path: Path) -> Signature:
    try:
        st = os.stat(path)
    except OSError:
        return None
    if not stat.S_ISREG(st.st_mode):
        return None
    return st.st_mtime_ns, st.st_size, st.st_ino


def settled_signature(path: Path, now: Signature, clock: Clock, stop: threading.Event, settle_s: float) -> Signature:
    """``path``'s signature once it has stayed the same for ``settle_s`` seconds of ``clock`` (a writer has
    finished), starting from ``now``; returns at once, with the last one seen, when ``stop`` is set."""
    while not clock.wait(stop, settle_s):
        later = file_signature(path)
        if later == now:
            break
        now = later
    return now


class ConfigWatcher(ServiceThread):
    """Calls ``apply(config)`` for each valid change of ``path``; ``refused(message)`` for an invalid one."""

    thread_name = "nfw-config"

    #: station-clock seconds between looks when the watcher only reads on request
    IDLE_S = 3600.0

    def __init__(self, path: str | Path, clock: Clock, apply: Callable[[Config], None],
                 refused: Callable[[str], None], interval_s: float | None = 2.0, settle_s: float = 1.0) -> None:
        self.path = Path(path)
        self.clock = clock
        self.apply = apply
        self.refused = refused
        self.interval_s = interval_s
        self.settle_s = settle_s
        super().__init__()
        self._seen: Signature = None
        self._requested = False
        self._request_lock = threading.Lock()  #: a request is never lost between reading and clearing the flag
        self._apply_lock = threading.Lock()  #: one reading and applying at a time (the thread, catch_up)
        self._passed_over: Signature = None  #: the file's state catch_up last read and did not apply

    def request(self) -> None:
        """Read the file on the watcher's thread now, changed or not (any thread; only sets flags)."""
        with self._request_lock:
            self._requested = True
        self._wake.set()

    def start(self) -> None:
        if self._thread is None:
            self._seen = file_signature(self.path)
        super().start()

    def check(self, force: bool = False) -> bool:
        """One look at the file (the thread's step; returns True when a change was handled).  With
        ``force`` (a reload request) the file is read even if it looks unchanged, without settling first."""
        now = file_signature(self.path)
        if now == self._seen and not force:
            return False
        if not force:  # let a writer finish: read only once the file has stayed the same for settle_s
            now = settled_signature(self.path, now, self.clock, self._stop, self.settle_s)
        if self._stop.is_set():
            return False
        with self._apply_lock:
            if now == self._seen and not force:
                return False  # catch_up read it meanwhile
            return self._read(now)

    def catch_up(self) -> None:
        """Apply the file now if it changed since it was last read and is whole and valid (any thread)."""
        from nfwserver.config.loader import ConfigError, has_settings, parse_config, read_config_text

        if file_signature(self.path) in (self._seen, self._passed_over):
            return
        with self._apply_lock:
            now = file_signature(self.path)
            if now is None or now in (self._seen, self._passed_over):
                return
            self._passed_over = now  # looked at once: not read again until it changes (posts are anyone's)
            try:
                text = read_config_text(self.path)
                if file_signature(self.path) != now or not has_settings(text):
                    return
                new = replace(parse_config(text, str(self.path), self.path.parent), path=str(self.path))
            except ConfigError:
                return  # halfway written, or wrong: the watcher's thread settles and reports it
            self._seen = now
            self.apply(new)

    def _read(self, now: Signature) -> bool:
        """Read and apply the file whose signature is ``now`` (under the apply lock); see :meth:`check`."""
        from nfwserver.config.loader import ConfigError, has_settings, parse_config, read_config_text

        if now is None:
            self._seen = now
            self.refused(f"{self.path} is missing or not a regular file; keeping the running configuration")
            return True
        try:
            text = read_config_text(self.path)
        except ConfigError as exc:
            self._seen = now
            self.refused(f"configuration change refused, keeping the running one: {exc}")
            return True
        if file_signature(self.path) != now:
            return False  # written to while being read: the next look reads it again once it settles
        self._seen = now
        if not has_settings(text):
            self.refused(f"configuration change refused, keeping the running one: {self.path} has no settings "
                         "(empty, or an editor is halfway through saving it)")
            return True
        try:
            new = replace(parse_config(text, str(self.path), self.path.parent), path=str(self.path))
        except ConfigError as exc:
            self.refused(f"configuration change refused, keeping the running one: {exc}")
            return True
        self.apply(new)
        return True

    def _run(self) -> None:
        while True:
            self.clock.wait(self._wake, self.interval_s if self.interval_s is not None else self.IDLE_S)
            if self._stop.is_set():
                return
            self._wake.clear()
            with self._request_lock:
                forced, self._requested = self._requested, False
            if not forced and self.interval_s is None:
                continue
            try:
                handled = self.check(force=forced)
            except Exception:  # the watcher must outlive any surprise
                log.exception("checking the configuration file failed")
                continue
            if forced and not handled and not self.clock.wait(self._stop, self.settle_s):
                self.request()  # written to while being read: read it again once it has settled
