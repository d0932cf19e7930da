"""A file that asks a running station to stop or reload: the stop path where signals cannot reach it.

Under Wine a Linux ``SIGTERM`` ends the Windows ``python.exe`` without running any of its code (no state
saved, DDE clients never told), and Windows has no ``SIGHUP``.  So when the environment variable
``NFW_CONTROL_FILE`` names a file, ``nfwserver run`` looks for that file every
:data:`POLL_S` seconds; when it appears, the station reads its first word, removes it and acts:
``stop`` stops the station as ``SIGTERM`` does, ``reload`` re-reads the configuration as ``SIGHUP`` does.
Anything else gets one warning and is removed. ``tools/wine/nfwserver`` sets the variable and writes ``stop``
when it receives ``SIGTERM``, ``SIGINT`` or ``SIGHUP`` (``reload`` on ``SIGUSR1``); on Windows a service
wrapper can do the same. Besides that file, ``run`` always watches ``control`` in the user's state directory
(:mod:`nfwserver.cli.station_channel`), which is how ``nfwserver stop`` reaches it on Windows when it cannot
open the station's stop event (:mod:`nfwserver.cli.stop_event`). Writers should write another name and rename
it into place, so that the station never reads half a word (an empty file is left alone until it has a word).

Owned by its own thread, ``nfw-control``; it waits on the injected clock.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from pathlib import Path

from nfwserver.clock import Clock
from nfwserver.core.service_thread import ServiceThread

log = logging.getLogger("nfwserver")

#: The environment variable naming the control file.
ENV = "NFW_CONTROL_FILE"
#: Seconds between looks for the file.
POLL_S = 0.2
#: The file's words and what each asks for.
WORDS = ("stop", "reload")


def control_path(environ: dict[str, str] | None = None) -> Path | None:
    """The control file the environment names, or None."""
    value = (os.environ if environ is None else environ).get(ENV, "").strip()
    return Path(value) if value else None


class ControlFile(ServiceThread):
    """Calls ``request(word, origin)`` for each word written to ``path`` or ``also`` (see the module docstring)."""

    thread_name = "nfw-control"

    def __init__(self, path: Path, clock: Clock, request: Callable[[str, str], None],
                 interval_s: float = POLL_S, each_look: Callable[[], None] | None = None,
                 also: Path | None = None) -> None:
        super().__init__()
        self.path = path
        self.paths = (path,) if also is None or also == path else (path, also)  #: every file watched
        self.clock = clock
        self.request = request
        self.interval_s = interval_s
        self.each_look = each_look  #: also called at every look (the station's description, written again)

    def start(self) -> None:
        """Remove files left by an earlier run (they were meant for that run), then watch."""
        for path in self.paths:
            try:
                path.unlink()
                log.info("removed %s, left by an earlier run", path)
            except OSError:
                pass
        super().start()

    def check(self) -> str | None:
        """One look at each file: the last word found (and acted on), or None."""
        found = None
        for path in self.paths:
            found = self._check(path) or found
        return found

    def _check(self, path: Path) -> str | None:
        try:
            text = path.read_text(encoding="ascii", errors="replace")
        except OSError:
            return None  # absent (the usual case) or not readable yet
        words = text.split()
        if not words:
            return None  # being written: the next look reads it
        try:
            path.unlink()
        except FileNotFoundError:  # its writer took it back (`nfwserver stop` giving up) before this look
            log.info("control file %s: the request was withdrawn before it was read", path)
            return None
        except OSError as exc:
            log.warning("cannot remove the control file %s: %s", path, exc.strerror or exc)
        word = words[0].lower()
        if word not in WORDS:
            log.warning("control file %s: %r is not a request (stop or reload); ignored", path, words[0][:40])
            return None
        self.request(word, f"control file {path}")
        return word

    def _run(self) -> None:
        while not self.clock.wait(self._stop, self.interval_s):
            try:
                self.check()
                if self.each_look is not None:
                    self.each_look()
            except Exception:  # the watcher must outlive any surprise
                log.exception("checking the control file failed")
