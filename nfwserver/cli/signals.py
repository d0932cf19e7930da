"""Signals to ``nfwserver run``, turned into stop and reload requests on a thread of their own.

What each signal does (README, "Running as a service"):

- ``SIGTERM`` (systemd's stop, ``kill``) and ``SIGINT`` (Ctrl+C; ``SIGBREAK`` on Windows): a clean stop --
  ``run`` stops the station (the session state saved, ``SA SE`` on EasyComm, DDE conversations ended,
  listeners closed) and exits with status 0.  More of them while the station stops are noted and
  otherwise ignored: a second Ctrl+C never interrupts the stop, and never prints a traceback.
- ``SIGHUP`` (``systemctl reload``): headless, the configuration file is read again and applied when it is
  whole (the daemon convention); under the console it stops the station like ``SIGTERM`` (the terminal
  has gone).

The handlers are installed before the station starts, so a signal during start-up is a request like
any other: the station finishes starting and then stops cleanly.  A handler only writes the signal's
number to a pipe: it takes no lock, so a signal arriving while the main thread holds one cannot
deadlock.  On POSIX the interpreter's own C-level handler writes it (``signal.set_wakeup_fd``), in whichever
thread the system delivers the signal to: a Python handler runs only in the main thread, which may be waiting
for minutes (a signal that arrives while the process is suspended by ``SIGSTOP`` goes to whichever thread runs
first when it is continued).  The interpreter writes there every signal that has a Python handler, also those of
others (the console's ``SIGTSTP`` and ``SIGCONT``): only this table's are acted on.  The thread
``nfw-signals`` reads the pipe and calls the action;
:meth:`StationSignals.request` does the same for requests that arrive otherwise (the control file,
:mod:`nfwserver.cli.control_file`).
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any

from nfwserver.core.service_thread import ServiceThread

log = logging.getLogger("nfwserver")

STOP = "stop"
RELOAD = "reload"


def stop_signals() -> list[signal.Signals]:
    """The signals that stop the station on this platform."""
    names = ("SIGTERM", "SIGINT", "SIGBREAK")
    return [getattr(signal, name) for name in names if hasattr(signal, name)]


def signal_actions(headless: bool) -> dict[signal.Signals, str]:
    """Each handled signal's request: stop, or (``SIGHUP`` while headless) reload."""
    actions = {sig: STOP for sig in stop_signals()}
    hup = getattr(signal, "SIGHUP", None)
    if hup is not None:
        actions[hup] = RELOAD if headless else STOP
    return actions


class StationSignals(ServiceThread):
    """Calls ``on_stop()`` or ``on_reload()`` for each signal of ``actions`` (see the module docstring).

    Owned by the main thread (:meth:`install`, :meth:`stopping`, :meth:`close`); the actions run on the
    thread ``nfw-signals``, one at a time.  After the first stop, requests only log that the station is
    already stopping; :meth:`stopping` returns once no action is running any more.
    """

    thread_name = "nfw-signals"

    def __init__(self, actions: dict[signal.Signals, str], on_stop: Callable[[], None],
                 on_reload: Callable[[], None]) -> None:
        super().__init__()
        self.actions = actions
        self._calls = {STOP: on_stop, RELOAD: on_reload}
        self._installed: list[signal.Signals] = []
        self._lock = threading.Lock()
        self._stopping = False
        self._read_fd, self._write_fd = os.pipe()
        self._wakeup = False  #: the interpreter writes the signals to the pipe itself (POSIX)
        self.start()  # reads the pipe the handlers write to, from now on

    def install(self) -> bool:
        """Install the handlers; False (nothing installed) off the main thread, as when embedded."""
        if threading.current_thread() is not threading.main_thread():
            return False
        handler: Callable[[int, Any], None] = self._handler
        if sys.platform != "win32":  # Windows takes only a socket there (and runs its handlers in the main thread)
            os.set_blocking(self._write_fd, False)
            signal.set_wakeup_fd(self._write_fd, warn_on_full_buffer=False)
            self._wakeup = True
            handler = self._noted
        for sig in self.actions:
            signal.signal(sig, handler)
            self._installed.append(sig)
        return True

    @staticmethod
    def _noted(_signum: int, _frame: Any) -> None:
        """The Python-level handler where the wakeup descriptor has already passed the signal on."""

    def _handler(self, signum: int, _frame: Any) -> None:
        try:
            os.write(self._write_fd, bytes([signum & 0xFF]))
        except OSError:  # closed: the run is over, nothing left to do
            pass

    def _run(self) -> None:
        while True:
            try:
                got = os.read(self._read_fd, 64)
            except OSError:
                return
            if not got:
                return
            for signum in got:
                try:
                    sig = signal.Signals(signum)
                except ValueError:
                    continue
                action = self.actions.get(sig)  # None: another handler's signal (the console's SIGTSTP, SIGCONT)
                if action is not None:
                    self.request(action, sig.name)

    def request(self, action: str, origin: str) -> None:
        """Carry out ``action`` (:data:`STOP` or :data:`RELOAD`) asked for by ``origin`` (any thread)."""
        with self._lock:
            if self._stopping:
                log.warning("%s: the station is already stopping (saving its state); please wait", origin)
                return
            if action == STOP:
                self._stopping = True
                log.info("%s: stopping", origin)
            elif action == RELOAD:
                log.info("%s: reloading the configuration", origin)
            try:
                self._calls[action]()
            except Exception:  # an action must never end this thread
                log.exception("%s: %s failed", origin, action)

    def stopping(self) -> None:
        """From now on every request only logs; returns once no action is running (main thread)."""
        with self._lock:
            self._stopping = True

    def close(self) -> None:
        """End the thread (main thread, once the station has stopped).  The signals handled are ignored
        from now on: the run is over and the process exits, and a late Ctrl+C must not turn that clean
        exit into death by ``SIGINT`` (Python puts back the default action of a handled signal while
        it finalises; an ignored one stays ignored)."""
        self.stopping()
        for sig in self._installed:
            signal.signal(sig, signal.SIG_IGN)
        self._installed.clear()
        if self._wakeup:
            signal.set_wakeup_fd(-1)
            self._wakeup = False
        os.close(self._write_fd)  # the thread reads the end of the pipe and returns
        self.stop()
        os.close(self._read_fd)
