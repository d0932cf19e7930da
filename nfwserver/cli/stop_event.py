"""Windows: ``nfwserver stop`` reaches the station through a named kernel event, so it needs no disk write.

The station creates, once it knows its own start time, an auto-reset event named :func:`event_name` --
``Local\\nfwserver-stop-<pid>-<start>`` (its process id and ``GetProcessTimes`` creation time, the same two
numbers its description records).  ``Local\\`` is the logon session's namespace, and the event is created with
no security attributes, so it gets the creating user's default access list: other users and other sessions cannot
open it.  A name that already exists when the station creates it is someone else's: the station closes it and
relies on its control file alone (one warning).

The thread ``nfw-stop-event`` (:class:`StopEvent`) waits on it (``WaitForSingleObject``, :data:`WAIT_MS` at a
time so that it also notices when it is to end) and turns it into a stop request.  ``stop``, once it has
verified the station (:meth:`~nfwserver.cli.station_channel.StationChannel.verified`), opens the event by name
with ``EVENT_MODIFY_STATE | SYNCHRONIZE`` and sets it (:func:`ask_to_stop`): nothing is written, so a full or
read-only state folder does not matter.  When it gives up, it withdraws the request by waiting on the event
with a zero timeout (:meth:`SentRequest.withdraw`): an auto-reset event is taken by exactly one waiter, so
either ``stop`` takes it back (the station never sees it) or the station has already taken it (it is stopping),
and the sentence ``stop`` prints says which.  Only when the event cannot be opened (a station of an older
version, or one whose event could not be created) does ``stop`` fall back to writing the control file.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from nfwserver.core.service_thread import ServiceThread

log = logging.getLogger("nfwserver")

#: Milliseconds the station's thread waits on the event at a time (how soon it notices it is to end).
WAIT_MS = 200
_EVENT_MODIFY_STATE = 0x0002
_SYNCHRONIZE = 0x00100000
_WAIT_OBJECT_0 = 0
_ERROR_ALREADY_EXISTS = 183


def event_name(pid: int, start: int) -> str:
    """The stop event of the station process ``pid`` started at ``start`` (``GetProcessTimes`` units)."""
    return f"Local\\nfwserver-stop-{pid}-{start}"


def _kernel32() -> Any:
    """kernel32 with the prototypes used here (Windows only)."""
    if sys.platform != "win32":
        raise OSError("named events exist only on Windows")
    import ctypes
    from ctypes import wintypes

    k = ctypes.WinDLL("kernel32", use_last_error=True)
    k.CreateEventW.argtypes = [wintypes.LPVOID, wintypes.BOOL, wintypes.BOOL, wintypes.LPCWSTR]
    k.CreateEventW.restype = wintypes.HANDLE
    k.OpenEventW.argtypes = [wintypes.DWORD, wintypes.BOOL, wintypes.LPCWSTR]
    k.OpenEventW.restype = wintypes.HANDLE
    k.SetEvent.argtypes = [wintypes.HANDLE]
    k.SetEvent.restype = wintypes.BOOL
    k.WaitForSingleObject.argtypes = [wintypes.HANDLE, wintypes.DWORD]
    k.WaitForSingleObject.restype = wintypes.DWORD
    k.CloseHandle.argtypes = [wintypes.HANDLE]
    k.CloseHandle.restype = wintypes.BOOL
    return k


class StopEvent(ServiceThread):
    """The station's side: owns the event and calls ``request("stop", origin)`` each time it is set."""

    thread_name = "nfw-stop-event"

    def __init__(self, handle: int, name: str, request: Callable[[str, str], None]) -> None:
        super().__init__()
        self.handle = handle
        self.name = name
        self.request = request

    @classmethod
    def create(cls, pid: int, start: int | None, request: Callable[[str, str], None]) -> StopEvent | None:
        """Create the event of this station (``pid``, ``start``) and start waiting on it; None (logged) when
        it cannot be created or the name is already taken (``stop`` then writes the control file)."""
        if sys.platform != "win32" or start is None:
            return None
        import ctypes

        k = _kernel32()
        name = event_name(pid, start)
        handle = k.CreateEventW(None, False, False, name)
        error = ctypes.get_last_error()
        if not handle or error == _ERROR_ALREADY_EXISTS:
            if handle:
                k.CloseHandle(handle)
            log.warning("cannot create the stop event %s (error %d): `nfwserver stop` will write the control "
                        "file instead", name, error)
            return None
        watcher = cls(int(handle), name, request)
        watcher.start()
        return watcher

    def _run(self) -> None:
        k = _kernel32()
        while not self._stop.is_set():
            if k.WaitForSingleObject(self.handle, WAIT_MS) == _WAIT_OBJECT_0:
                self.request("stop", f"nfwserver stop (event {self.name})")

    def stop(self) -> None:
        """End the thread, then close the event (a later ``stop`` finds no event: the station is ending)."""
        super().stop()
        handle, self.handle = self.handle, 0
        if handle:
            _kernel32().CloseHandle(handle)


@dataclass
class SentRequest:
    """``stop``'s side: a stop request set on the station's event, held open until :meth:`withdraw`."""

    handle: int

    def withdraw(self) -> bool:
        """Take the request back if the station has not taken it: True when withdrawn (the station will not
        see it), False when the station had already taken it.  Closes the handle either way."""
        k = _kernel32()
        try:
            return bool(k.WaitForSingleObject(self.handle, 0) == _WAIT_OBJECT_0)
        finally:
            k.CloseHandle(self.handle)


def ask_to_stop(pid: int, start: int) -> SentRequest | None:
    """Set the stop event of the verified station (``pid``, ``start``); None when it cannot be opened."""
    if sys.platform != "win32":
        return None
    k = _kernel32()
    handle = k.OpenEventW(_EVENT_MODIFY_STATE | _SYNCHRONIZE, False, event_name(pid, start))
    if not handle:
        return None
    if not k.SetEvent(handle):
        k.CloseHandle(handle)
        return None
    return SentRequest(int(handle))
