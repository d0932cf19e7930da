"""The headless station's rotating log file, which never stops the station when it cannot be written.

A full disk, a read-only file system or a removed directory makes a plain :mod:`logging` file handler
print a ``--- Logging error ---`` traceback for every record, and the start-up ``mkdir`` of a read-only
log directory ended the station with a traceback.  :class:`StationLogFile` instead treats the file as
the ``log-file`` link (:mod:`nfwserver.health`): the first failure is one warning (on the terminal, and
in STATUS once the station's health board is attached), records are dropped while the back-off runs,
and the first record written after it ends clears the fault with one line saying how many were lost.
The file (and its directory) is opened on the first record, so a station started while the disk is
unwritable begins logging when it becomes writable.
"""

from __future__ import annotations

import io
import logging
import logging.handlers
from pathlib import Path

from nfwserver.clock import Clock
from nfwserver.health import Backoff, LinkHealth

__all__ = ["LOG_BACKOFF", "MAX_LOG_BYTES", "StationLogFile"]

MAX_LOG_BYTES = 5 * 2**20  #: size at which the file is rotated (bytes)
LOG_BACKOFF = Backoff(5.0, 300.0)  #: retries of an unwritable log file (seconds)


class StationLogFile(logging.handlers.RotatingFileHandler):
    """Rotating UTF-8 log file at ``path`` (five backups); failures go to ``health``, never to stderr."""

    def __init__(self, path: Path, clock: Clock) -> None:
        super().__init__(path, maxBytes=MAX_LOG_BYTES, backupCount=5, encoding="utf-8", delay=True)
        self.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
        self.health = LinkHealth("log-file", clock, LOG_BACKOFF)
        self.dropped = 0  #: records lost while the file could not be written (this fault)
        self._failed_now = False

    def attach(self, health: LinkHealth) -> None:
        """Report through ``health`` (the station's ``log-file`` link, shown by STATUS) from now on."""
        fault = self.health.fault
        self.health = health
        if fault is not None:
            health.failed(fault.reason)

    def close(self) -> None:
        try:
            super().close()
        except OSError:  # the last buffered records could not be written either
            self.stream = None

    def _open(self) -> io.TextIOWrapper:
        Path(self.baseFilename).parent.mkdir(parents=True, exist_ok=True)
        return super()._open()

    def emit(self, record: logging.LogRecord) -> None:
        if not self.health.may_try():
            self.dropped += 1
            return
        self._failed_now = False
        super().emit(record)  # calls handleError on failure
        if not self._failed_now and not self.health.ok:
            dropped, self.dropped = self.dropped, 0
            self.health.succeeded()
            if dropped:
                self.health.logger.warning("log-file: %d log records were lost while %s could not be written",
                                           dropped, self.baseFilename)

    def handleError(self, record: logging.LogRecord) -> None:  # noqa: N802 (logging's name)
        import sys

        self._failed_now = True
        self.dropped += 1
        error = sys.exc_info()[1]
        reason = getattr(error, "strerror", None) or str(error) or type(error).__name__
        stream, self.stream = self.stream, None
        if stream is not None:  # reopened on the next try; buffered bytes are part of what was lost
            try:
                stream.close()
            except OSError:
                pass
        # The fault is recorded before its warning is logged, so that warning is dropped here (no recursion)
        # and reaches the terminal's handler.
        self.health.failed(f"cannot write the log file {self.baseFilename} ({reason}); "
                           "the station keeps running, log records are dropped until it can be written")
