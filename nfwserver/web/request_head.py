"""Reading one HTTP request head within a deadline and a size cap, before :mod:`http.server` parses it.

:mod:`http.server` reads the request line and each header line with the socket's timeout applied to
every read, so a peer that trickles a byte every few seconds holds a connection (and its thread) for as
long as it likes, and 100 header lines of 64 KiB each are read into memory.  :func:`read_head` reads
the whole head (up to the blank line) itself:

- within one deadline for the whole head (:data:`HEAD_DEADLINE_S` by default), or it answers 408;
- at most :data:`MAX_HEAD_BYTES` (32 KiB, about what nginx takes by default), or it answers 431;
- a first line without a version (HTTP/0.9) or with a version other than 1.0 or 1.1 is answered 505 as
  soon as that line is complete; a first line that is not ``METHOD TARGET VERSION``, 400.

A peer that closes or sends nothing before the deadline gets no answer (browsers open spare
connections they may never use).  :class:`HeadReader` then serves the head to :mod:`http.server`
as its ``rfile``, and the body after it from the socket within the same deadline.
"""

from __future__ import annotations

import io
import json
import re
import socket
import time
from dataclasses import dataclass

__all__ = ["HEAD_DEADLINE_S", "MAX_HEAD_BYTES", "SECURITY_HEADERS", "Head", "HeadReader", "error_response",
           "linger_close", "read_head"]

HEAD_DEADLINE_S = 10.0  #: real seconds a request head (and a request body) may take to arrive, all of it
MAX_HEAD_BYTES = 32 * 1024  #: request line and headers together
_VERSION = re.compile(rb"HTTP/1\.[01]")
#: sent with every response, an error's too (docs/WEB.md, "Security model")
SECURITY_HEADERS = (
    ("Content-Security-Policy", "default-src 'self'; img-src 'self' data:; style-src 'self'; script-src 'self'; "
                                "connect-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'"),
    ("X-Content-Type-Options", "nosniff"),
    ("Referrer-Policy", "same-origin"),  # the page's own requests carry their Origin; others learn nothing
)
_REASONS = {400: "Bad Request", 403: "Forbidden", 408: "Request Timeout", 413: "Content Too Large",
            421: "Misdirected Request", 431: "Request Header Fields Too Large", 503: "Service Unavailable",
            505: "HTTP Version Not Supported"}


@dataclass(frozen=True)
class Head:
    """What :func:`read_head` got: the head and any bytes after it, or the answer to refuse it with."""

    data: bytes = b""
    status: int = 0  #: 0: a complete head to parse; otherwise the HTTP status to answer with
    message: str = ""  #: why, for the answer and the log
    silent: bool = False  #: nothing came (closed or idle): close without an answer


def _first_line_problem(line: bytes) -> tuple[int, str] | None:
    words = line.split()
    if len(words) == 3 and _VERSION.fullmatch(words[2]):
        return None
    if len(words) == 2 or (len(words) == 3 and words[2].startswith(b"HTTP/")):
        return 505, "only HTTP/1.0 and HTTP/1.1 are served"
    return 400, "the request line must be METHOD TARGET HTTP/1.x"


def read_head(sock: socket.socket, deadline: float, max_bytes: int = MAX_HEAD_BYTES,
              io_timeout_s: float = 10.0) -> Head:
    """Read a request head from ``sock`` until ``deadline`` (:func:`time.monotonic` seconds); never raises
    for the peer's doing (a reset is a silent :class:`Head`)."""
    buf = bytearray()
    checked_first_line = False
    while True:
        first = buf.find(b"\n")
        if not checked_first_line and first >= 0:
            checked_first_line = True
            if problem := _first_line_problem(bytes(buf[:first])):
                return Head(bytes(buf), *problem)
        ends = [at for at in (buf.find(b"\r\n\r\n"), buf.find(b"\n\n")) if at >= 0]
        if ends and min(ends) <= max_bytes:
            return Head(bytes(buf))
        if ends or len(buf) > max_bytes:
            return Head(b"", 431, f"request head over {max_bytes // 1024} KiB")
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            return Head(b"", 408, "request head not complete in time") if buf else Head(silent=True)
        try:
            sock.settimeout(min(remaining, io_timeout_s))
            chunk = sock.recv(16384)
        except TimeoutError:
            continue  # the loop answers once the deadline has passed
        except OSError:
            return Head(silent=True)
        if not chunk:
            return Head(silent=True)
        buf += chunk


class HeadReader(io.RawIOBase):
    """The ``rfile`` of a request: the head read by :func:`read_head`, then the socket, until ``deadline``
    (a read after it raises :class:`TimeoutError`, which :mod:`http.server` takes as a timed-out request)."""

    def __init__(self, data: bytes, sock: socket.socket, deadline: float, io_timeout_s: float) -> None:
        super().__init__()
        self._data = memoryview(data)
        self._sock = sock
        self._deadline = deadline
        self._io_timeout_s = io_timeout_s

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: bytearray | memoryview) -> int:  # type: ignore[override]
        if self._data:
            count = min(len(buffer), len(self._data))
            buffer[:count] = self._data[:count]
            self._data = self._data[count:]
            return count
        remaining = self._deadline - time.monotonic()
        if remaining <= 0:
            raise TimeoutError("request body not complete in time")
        self._sock.settimeout(min(remaining, self._io_timeout_s))
        try:
            return self._sock.recv_into(buffer)
        finally:
            self._sock.settimeout(self._io_timeout_s)


def error_response(status: int, message: str, head_only: bool = False, reason: str | None = None) -> bytes:
    """A complete HTTP/1.0 answer ``{"ok": false, "error": message}`` with ``status`` (``reason`` its phrase,
    by default the usual one) and the :data:`SECURITY_HEADERS`, closing the connection."""
    body = json.dumps({"ok": False, "error": message[:300]}).encode()
    phrase = "".join(ch for ch in (reason or _REASONS.get(status, "Error")) if " " <= ch <= "~")[:60]
    lines = [f"HTTP/1.0 {status} {phrase}", "Server: nfwserver",
             "Content-Type: application/json", f"Content-Length: {len(body)}", "Cache-Control: no-store",
             "Connection: close", *(f"{name}: {value}" for name, value in SECURITY_HEADERS)]
    return ("\r\n".join(lines) + "\r\n\r\n").encode() + (b"" if head_only else body)


def linger_close(sock: socket.socket, budget_s: float = 0.5, max_bytes: int = 64 * 1024) -> None:
    """Say we are done sending, then read and drop what the peer still sends (at most ``max_bytes``,
    for at most ``budget_s`` real seconds), so closing does not reset the connection before the peer has
    read our answer."""
    try:
        sock.shutdown(socket.SHUT_WR)
        deadline = time.monotonic() + budget_s
        dropped = 0
        while dropped < max_bytes and (remaining := deadline - time.monotonic()) > 0:
            sock.settimeout(remaining)
            chunk = sock.recv(16384)
            if not chunk:
                break
            dropped += len(chunk)
    except OSError:
        pass
