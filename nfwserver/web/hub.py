"""The newest frame of the station, shared by every browser connection.

The frame thread publishes one encoded frame per tick (:meth:`FrameHub.publish`); each browser's
connection thread waits for a frame newer than the one it sent last (:meth:`FrameHub.wait_newer`).
There is one slot, not a queue: a browser that reads slowly skips to the newest frame, so nothing is
ever buffered for it beyond the socket's own buffer, and no browser can hold the others back.  What a
skipped frame must not lose, the log lines, is not in the slot: each connection adds the lines its page
has not been sent to the frame it sends (:class:`~nfwserver.web.station_parts.LogCursor`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable


class FrameHub:
    """One slot holding (sequence number, frame bytes); any thread may use it."""

    def __init__(self) -> None:
        self._cond = threading.Condition()
        self._seq = 0
        self._frame: bytes | None = None
        self._closed = False

    @property
    def seq(self) -> int:
        return self._seq

    def publish(self, frame: bytes) -> int:
        """Make ``frame`` the newest and wake every waiting connection; returns its sequence number."""
        with self._cond:
            self._seq += 1
            self._frame = frame
            self._cond.notify_all()
            return self._seq

    def newest(self) -> tuple[int, bytes | None]:
        with self._cond:
            return self._seq, self._frame

    def wait_newer(self, seen: int, timeout_s: float | None = None,
                   ended: Callable[[], bool] | None = None) -> tuple[int, bytes | None]:
        """The newest frame once its number is above ``seen``; (seen, None) when closed, after ``timeout_s``
        real seconds (None: no limit), or when ``ended()`` is true (looked at on entry and at each
        :meth:`wake`)."""
        with self._cond:
            self._cond.wait_for(lambda: self._closed or self._seq > seen or (ended is not None and ended()),
                                timeout_s)
            if self._closed or self._seq <= seen:
                return seen, None
            return self._seq, self._frame

    def wake(self) -> None:
        """Make every waiting connection look at its ``ended`` condition again (a connection ended for another)."""
        with self._cond:
            self._cond.notify_all()

    def close(self) -> None:
        """Wake every waiting connection for good (server stopping)."""
        with self._cond:
            self._closed = True
            self._cond.notify_all()

    def reopen(self) -> None:
        with self._cond:
            self._closed = False
