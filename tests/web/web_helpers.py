"""Raw HTTP on real loopback sockets, for the tests that send what no well-behaved client sends."""

from __future__ import annotations

import json
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import timedelta

from nfwserver.clock import VirtualClock
from nfwserver.config.schema import WebConfig
from nfwserver.core.station_core import StationCore
from nfwserver.web import WebServer
from tests.dde.conftest import CATALOG, ISS_PASS, OBSERVER
from tests.web.conftest import TOKEN


@contextmanager
def running_web(**options: object) -> Iterator[tuple[StationCore, WebServer]]:
    """A core and its web server on a free port, taking 127.0.0.0/8, control on with :data:`TOKEN`;
    ``options`` go to :class:`WebConfig` (its field names) or :class:`WebServer` (the others)."""
    fields = set(WebConfig.__dataclass_fields__)
    config = WebConfig(**{"enabled": True, "port": 0, "allow": ("127.0.0.0/8",), "control": True, "token": TOKEN,
                          **{k: v for k, v in options.items() if k in fields}})  # type: ignore[arg-type]
    clock = VirtualClock(ISS_PASS.aos + timedelta(seconds=200))
    core = StationCore(CATALOG, OBSERVER, clock, satellite=25544, rate_hz=5.0)
    core.set_feed(True)
    web = WebServer(core, config, **{k: v for k, v in options.items() if k not in fields})  # type: ignore[arg-type]
    web.start()
    try:
        yield core, web
    finally:
        web.stop()


def connect(web: WebServer, source: str = "127.0.0.1", timeout_s: float = 10.0) -> socket.socket:
    assert web.address is not None
    return socket.create_connection(web.address, timeout=timeout_s, source_address=(source, 0))


def read_all(sock: socket.socket) -> bytes:
    """Everything the server sends until it closes (a reset ends it too)."""
    chunks = []
    while True:
        try:
            chunk = sock.recv(65536)
        except (ConnectionResetError, TimeoutError):
            break
        if not chunk:
            break
        chunks.append(chunk)
    return b"".join(chunks)


def exchange(web: WebServer, data: bytes, source: str = "127.0.0.1") -> bytes:
    """Send ``data`` on a new connection and read the whole answer."""
    with connect(web, source) as sock:
        sock.sendall(data)
        return read_all(sock)


def status(reply: bytes) -> int:
    """The status code of a raw answer (0 for none)."""
    return int(reply.split(b" ", 2)[1]) if reply.startswith(b"HTTP/") else 0


def body(reply: bytes) -> bytes:
    return reply.split(b"\r\n\r\n", 1)[1] if b"\r\n\r\n" in reply else b""


def command_request(web: WebServer, command: str, token: str = TOKEN, content_type: str = "application/json",
                    headers: dict[str, str] | None = None, host: str | None = None) -> bytes:
    """A ``POST /api/command`` as raw bytes, Host the server's own address unless ``host`` is given."""
    assert web.address is not None
    payload = json.dumps({"command": command, "token": token}).encode()
    lines = ["POST /api/command HTTP/1.1", f"Host: {host or f'{web.address[0]}:{web.address[1]}'}",
             f"Content-Type: {content_type}", f"Content-Length: {len(payload)}",
             *(f"{k}: {v}" for k, v in (headers or {}).items())]
    return ("\r\n".join(lines) + "\r\n\r\n").encode() + payload
