"""A one-question client for Nova's TCP protocol: connect, check the greeting, send a line, read the reply.

Used by ``nfwserver poke`` and ``nfwserver status``; any script can do the same with three lines of
socket code (README).  Timeouts are real seconds: this runs in a separate, short-lived process.
"""

from __future__ import annotations

import socket
from typing import BinaryIO

from nfwserver.tcp.greeting import GREETING

WILDCARDS = {"", "0.0.0.0", "::"}


class StationUnreachable(Exception):
    """No station answered; the message is one sentence for the user."""


def connect_host(listen_host: str) -> str:
    """Where to connect for a server listening on ``listen_host`` (a wildcard means this machine)."""
    if listen_host in WILDCARDS:
        return "::1" if listen_host == "::" else "127.0.0.1"
    return listen_host


def _read_line(stream: BinaryIO, where: str) -> str:
    raw: bytes = stream.readline(4096)
    if not raw:
        raise StationUnreachable(f"the station at {where} closed the connection "
                                 "(is this machine's address in its [tcp] allow list?)")
    return raw.decode("ascii", errors="replace").rstrip("\r\n")


def ask(host: str, port: int, line: str, timeout_s: float = 5.0, until: str | None = None) -> str:
    """Send ``line`` to the station at ``host``:``port`` and return its one-line reply (with ``until``:
    every line up to and without the one equal to ``until``, joined by newlines; ``HELP`` ends with OK)."""
    where = f"{host} port {port}"
    try:
        with socket.create_connection((host, port), timeout=timeout_s) as sock, sock.makefile("rb") as stream:
            greeting = _read_line(stream, where)
            if greeting != GREETING:
                raise StationUnreachable(f"{where} answered {greeting[:60]!r}, not Nova's greeting")
            sock.sendall(line.encode("ascii") + b"\r\n")
            if until is None:
                return _read_line(stream, where)
            lines: list[str] = []
            while (reply := _read_line(stream, where)) != until and not reply.startswith("ERROR"):
                lines.append(reply)
            return "\n".join(lines) if reply == until else reply
    except OSError as exc:
        reason = exc.strerror or str(exc) or type(exc).__name__
        raise StationUnreachable(f"no station answers on {where} ({reason}); is `nfwserver run` running "
                                 "with [tcp] enabled = true?") from None
