"""One HTTP(S) GET with a deadline for the whole transfer, redirects kept on http(s), and a way to abort it.

``urllib``'s ``timeout`` bounds each socket operation, not the transfer: a server that sends one byte a second
holds a download (or its headers) for hours.  :func:`open_url` opens ``url`` through handlers whose connections
register their sockets with a :class:`Deadline`; when the deadline passes, or ``cancel`` is set (the station
stopping), the sockets are shut down, so the read in progress ends at once with an error the caller reports.
Redirects are followed only to http and https (``urllib`` would follow one to ``ftp://``).

The network modules load only when this module does (3 MiB that ``passes`` never needs).
"""

from __future__ import annotations

import http.client
import socket
import threading
import urllib.error
import urllib.request
from typing import IO, Any

__all__ = ["Deadline", "RedirectRefused", "open_url"]


class RedirectRefused(urllib.error.URLError):
    """A redirect to something other than http(s)."""


class Deadline:
    """Shuts down every registered socket ``seconds`` after :meth:`start`, or as soon as ``cancel`` is set."""

    def __init__(self, seconds: float, cancel: threading.Event | None = None) -> None:
        self.seconds = seconds
        self.cancel = cancel if cancel is not None else threading.Event()
        self.expired = False  #: the deadline passed (or the fetch was cancelled) and the sockets were shut
        self._done = threading.Event()
        self._lock = threading.Lock()
        self._socks: list[socket.socket] = []
        self._thread = threading.Thread(target=self._watch, name="nfw-fetch-deadline", daemon=True)

    def start(self) -> Deadline:
        self._thread.start()
        return self

    def finish(self) -> None:
        """The transfer is over: stop watching."""
        self._done.set()
        self._thread.join(5.0)

    @property
    def cancelled(self) -> bool:
        return self.cancel.is_set()

    def register(self, sock: socket.socket | None) -> None:
        if sock is None:
            return
        with self._lock:
            self._socks.append(sock)
            late = self.expired
        if late:
            _shut(sock)

    def _watch(self) -> None:
        waited = 0.0
        step = min(0.1, self.seconds)
        while waited < self.seconds and not self._done.is_set() and not self.cancel.is_set():
            self._done.wait(step)
            waited += step
        if self._done.is_set():
            return
        with self._lock:
            self.expired = True
            socks = list(self._socks)
        for sock in socks:
            _shut(sock)


def _shut(sock: socket.socket) -> None:
    try:
        sock.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass


def _watched(base: type[http.client.HTTPConnection], deadline: Deadline) -> type[http.client.HTTPConnection]:
    class Watched(base):  # type: ignore[valid-type,misc]
        def connect(self) -> None:
            super().connect()
            deadline.register(self.sock)

    return Watched


class _Http(urllib.request.HTTPHandler):
    def __init__(self, deadline: Deadline) -> None:
        super().__init__()
        self.deadline = deadline

    def http_open(self, req: urllib.request.Request) -> http.client.HTTPResponse:
        return self.do_open(_watched(http.client.HTTPConnection, self.deadline), req)


class _Https(urllib.request.HTTPSHandler):
    def __init__(self, deadline: Deadline) -> None:
        super().__init__()
        self.deadline = deadline

    def https_open(self, req: urllib.request.Request) -> http.client.HTTPResponse:
        extra: dict[str, Any] = {"context": getattr(self, "_context", None)}
        check_hostname = getattr(self, "_check_hostname", None)  # gone from Python 3.12 on
        if check_hostname is not None:
            extra["check_hostname"] = check_hostname
        return self.do_open(_watched(http.client.HTTPSConnection, self.deadline), req, **extra)


class _HttpOnlyRedirects(urllib.request.HTTPRedirectHandler):
    max_redirections = 10

    def redirect_request(self, req: urllib.request.Request, fp: IO[bytes], code: int, msg: str,
                         headers: http.client.HTTPMessage, newurl: str) -> urllib.request.Request | None:
        scheme = newurl.partition(":")[0].lower()
        if scheme not in ("http", "https"):
            raise RedirectRefused(f"redirected to {newurl[:80]!r}, which is not http(s)")
        return super().redirect_request(req, fp, code, msg, headers, newurl)


def open_url(url: str, timeout_s: float, deadline: Deadline) -> http.client.HTTPResponse:
    """GET ``url`` with ``timeout_s`` per socket operation, its sockets watched by ``deadline`` (started)."""
    opener = urllib.request.build_opener(_Http(deadline), _Https(deadline), _HttpOnlyRedirects())
    request = urllib.request.Request(url, headers={"User-Agent": "nfwserver"})
    return opener.open(request, timeout=timeout_s)  # type: ignore[no-any-return]
