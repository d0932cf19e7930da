"""One HTTP(S) GET with a deadline for the whole transfer, redirects kept on http(s), and a way to abort it.

``urllib``'s ``timeout`` bounds each socket operation, not the transfer: a server that sends one byte a second
holds a download (or its headers) for hours.  :func:`open_url` opens ``url`` through handlers whose connections
register each socket with a :class:`Deadline` before it connects; when the deadline passes, or ``cancel`` is set
(the station stopping), the sockets are shut down, so the connect or read in progress ends at once with an error
the caller reports.  Each connect attempt is given at most the time left, and the deadline is measured on the
injected clock's ``monotonic`` (not by counting its own waits, which ran 15 % slow under Wine: 23 s for 20).
Redirects are followed only to http and https (``urllib`` would follow one to ``ftp://``).

The network modules load only when this module does (3 MiB that ``passes`` never needs).
"""

from __future__ import annotations

import functools
import http.client
import socket
import threading
import urllib.error
import urllib.request
from typing import IO, Any

from nfwserver.clock import Clock, SystemClock

__all__ = ["Deadline", "RedirectRefused", "open_url"]


class RedirectRefused(urllib.error.URLError):
    """A redirect to something other than http(s)."""


class Deadline:
    """Shuts down every registered socket ``seconds`` (of ``clock``'s time) after :meth:`start`, or as soon as
    ``cancel`` is set (noticed within :data:`CANCEL_POLL_S`)."""

    #: how often (``clock`` seconds) the watcher looks at ``cancel``
    CANCEL_POLL_S = 0.1

    def __init__(self, seconds: float, cancel: threading.Event | None = None, clock: Clock | None = None) -> None:
        self.seconds = seconds
        self.cancel = cancel if cancel is not None else threading.Event()
        self.clock: Clock = clock if clock is not None else SystemClock()
        self._ends_at = 0.0
        self.expired = False  #: the deadline passed (or the fetch was cancelled) and the sockets were shut
        self._done = threading.Event()
        self._lock = threading.Lock()
        self._socks: list[socket.socket] = []
        self._thread = threading.Thread(target=self._watch, name="nfw-fetch-deadline", daemon=True)

    def start(self) -> Deadline:
        self._ends_at = self.clock.monotonic() + self.seconds
        self._thread.start()
        return self

    def remaining(self) -> float:
        """Seconds left before the deadline (0 once it has passed)."""
        if self.expired:
            return 0.0
        return max(0.0, self._ends_at - self.clock.monotonic())

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
        while not self._done.is_set() and not self.cancel.is_set():
            left = self._ends_at - self.clock.monotonic()
            if left <= 0:
                break
            self.clock.wait(self._done, min(self.CANCEL_POLL_S, left))
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


def _connect_within(deadline: Deadline, address: tuple[str, int], timeout: object,
                    source_address: tuple[str, int] | None = None) -> socket.socket:
    """``socket.create_connection`` whose sockets the deadline watches from before they connect, each attempt
    (one per address of the host) given at most the time left; ``timeout`` (seconds, or http.client's "the
    default") bounds each later socket operation."""
    host, port = address
    per_operation = float(timeout) if isinstance(timeout, (int, float)) else None
    failure: OSError | None = None
    addresses = socket.getaddrinfo(host, port, 0, socket.SOCK_STREAM)
    if not addresses:
        raise OSError(f"{host} has no address")
    for family, kind, proto, _, where in addresses:
        left = deadline.remaining()
        if left <= 0:
            break
        sock = socket.socket(family, kind, proto)
        deadline.register(sock)
        try:
            sock.settimeout(left if per_operation is None else min(per_operation, left))
            if source_address is not None:
                sock.bind(source_address)
            sock.connect(where)
            sock.settimeout(per_operation)
            return sock
        except OSError as exc:
            failure = exc
            sock.close()
    if failure is not None and not deadline.expired:
        raise failure
    raise TimeoutError(f"no connection to {host}:{port} before the deadline")


def _watched(base: type[http.client.HTTPConnection], deadline: Deadline) -> type[http.client.HTTPConnection]:
    class Watched(base):  # type: ignore[valid-type,misc]
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            self._create_connection = functools.partial(_connect_within, deadline)

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
