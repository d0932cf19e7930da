"""A component that owns one background thread: start, stop (wake, join), and the loop it runs.

Subclasses name their thread (:attr:`ServiceThread.thread_name`) and implement :meth:`_run`, which
must return soon after :attr:`_stop` is set; :attr:`_wake` lets :meth:`stop` (or a request) interrupt
a wait.  :meth:`start` and :meth:`stop` are idempotent and called by the owner's thread.
"""

from __future__ import annotations

import threading


class ServiceThread:
    """See the module docstring."""

    thread_name = "nfw-thread"

    def __init__(self) -> None:
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._thread: threading.Thread | None = None

    def _run(self) -> None:
        raise NotImplementedError

    @property
    def running(self) -> bool:
        """Started and not stopped since."""
        return self._thread is not None

    @property
    def thread(self) -> threading.Thread | None:
        """The service's thread while it runs (None before :meth:`start` and after :meth:`stop`)."""
        return self._thread

    def start(self) -> None:
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(target=self._run, name=self.thread_name, daemon=True)
            self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(5.0)
            self._thread = None
