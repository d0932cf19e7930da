"""Clients for Nova's TCP protocol: connect, check the greeting, send a line, read the reply.

:func:`ask` is the one-question client of ``nfwserver poke`` and ``nfwserver status``; :class:`StationLink` keeps
one connection for many questions (``nfwserver watch``).  Any script can do the same with three lines of
socket code (README).  Timeouts are real seconds: this runs in a separate process, never in the station.
"""

from __future__ import annotations

import socket

from nfwserver.tcp.greeting import GREETING

WILDCARDS = {"", "0.0.0.0", "::"}
MAX_LINE = 4096  #: bytes of one received line at most (a longer one is cut into lines of this size)


class StationUnreachable(Exception):
    """No station answered; the message is one sentence for the user."""


def connect_host(listen_host: str) -> str:
    """Where to connect for a server listening on ``listen_host`` (a wildcard means this machine)."""
    if listen_host in WILDCARDS:
        return "::1" if listen_host == "::" else "127.0.0.1"
    return listen_host


def _unreachable(where: str, exc: OSError) -> StationUnreachable:
    reason = exc.strerror or str(exc) or type(exc).__name__
    return StationUnreachable(f"no station answers on {where} ({reason}); is `nfwserver run` running "
                              "with [tcp] enabled = true?")


class StationLink:
    """One open connection to the station at ``host``:``port`` (greeting checked), asked one line at a time.

    Owned by one thread.  Every failure (refused, reset, closed, timed out after ``timeout_s`` real seconds, a
    peer that is not Nova) raises :class:`StationUnreachable` with one sentence; the link is then closed.
    :meth:`drain` takes the lines that have arrived without waiting (a ``WATCH`` stream)."""

    def __init__(self, host: str, port: int, timeout_s: float = 5.0) -> None:
        self.where = f"{host} port {port}"
        self.timeout_s = timeout_s
        try:
            self._sock = socket.create_connection((host, port), timeout=timeout_s)
        except OSError as exc:
            raise _unreachable(self.where, exc) from None
        self._buffer = bytearray()  #: received bytes not yet returned as lines
        self.greeted = False  #: the greeting was read: a closed connection now means the station went away
        try:
            greeting = self._line()
            if greeting != GREETING:
                raise StationUnreachable(f"{self.where} answered {greeting[:60]!r}, not Nova's greeting")
            self.greeted = True
        except StationUnreachable:
            self.close()
            raise

    def _closed(self) -> StationUnreachable:
        return StationUnreachable(f"the station at {self.where} closed the connection" + (
            " (stopped or restarting?)" if self.greeted else
            " (is this machine's address in its [tcp] allow list?)"))

    def _take_line(self) -> str | None:
        """The first whole line of the buffer (at most :data:`MAX_LINE` bytes), without its ending; None if none."""
        end = self._buffer.find(b"\n")
        if end < 0 and len(self._buffer) < MAX_LINE:
            return None
        cut = end + 1 if 0 <= end < MAX_LINE else MAX_LINE
        raw = bytes(self._buffer[:cut])
        del self._buffer[:cut]
        return raw.decode("ascii", errors="replace").rstrip("\r\n")

    def _line(self) -> str:
        while (line := self._take_line()) is None:
            try:
                chunk = self._sock.recv(4096)
            except OSError as exc:
                raise _unreachable(self.where, exc) from None
            if not chunk:
                raise self._closed()
            self._buffer += chunk
        return line

    def drain(self) -> list[str]:
        """The whole lines received so far, without waiting for more."""
        try:
            self._sock.setblocking(False)
            try:
                while chunk := self._sock.recv(65536):
                    self._buffer += chunk
                else:
                    raise self._closed()
            except (BlockingIOError, InterruptedError):
                pass
            finally:
                self._sock.settimeout(self.timeout_s)
        except OSError as exc:
            self.close()
            raise _unreachable(self.where, exc) from None
        except StationUnreachable:
            self.close()
            raise
        lines: list[str] = []
        while (line := self._take_line()) is not None:
            lines.append(line)
        return lines

    def send(self, line: str) -> None:
        """Send ``line`` (a CR LF is added) without waiting for a reply."""
        try:
            self._sock.sendall(line.encode("ascii") + b"\r\n")
        except OSError as exc:
            self.close()
            raise _unreachable(self.where, exc) from None

    def ask(self, line: str) -> str:
        """Send ``line`` and return the one-line reply."""
        self.send(line)
        return self.reply()

    def reply(self) -> str:
        """The next line the station sends (a reply of several lines, e.g. HELP's)."""
        try:
            return self._line()
        except StationUnreachable:
            self.close()
            raise

    def close(self) -> None:
        try:
            self._sock.close()
        except OSError:
            pass


def ask(host: str, port: int, line: str, timeout_s: float = 5.0, until: str | None = None) -> str:
    """Send ``line`` to the station at ``host``:``port`` and return its one-line reply (with ``until``:
    every line up to and without the one equal to ``until``, joined by newlines; ``HELP`` ends with OK)."""
    link = StationLink(host, port, timeout_s)
    try:
        reply = link.ask(line)
        if until is None:
            return reply
        lines: list[str] = []
        while reply != until and not reply.startswith("ERROR"):
            lines.append(reply)
            reply = link.reply()
        return "\n".join(lines) if reply == until else reply
    finally:
        link.close()
