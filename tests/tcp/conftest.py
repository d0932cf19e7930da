"""Nova's TCP server on a virtual-clock station (tests/dde/conftest.py), with a plain socket client."""

from __future__ import annotations

import dataclasses
import socket
import time
from collections.abc import Iterator
from datetime import timedelta

import pytest

from nfwserver.config.schema import TcpConfig
from nfwserver.tcp.server import NovaTcpServer
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.elements import load_element_file, load_elements
from tests.conftest import DATA
from tests.dde.conftest import ISS_PASS, Station, make_station

LOOPBACK_ONLY = TcpConfig(enabled=True, host="127.0.0.1", port=0, allow=("127.0.0.1/32",))
SO_50 = 27607  #: in :func:`with_so_50`'s catalog, so that SAT=27607 takes effect if it runs


class LineClient:
    """A raw TCP client reading CR LF lines, with real-time timeouts (network I/O, not the clock)."""

    def __init__(self, address: tuple[str, int], bind: str | None = None, rcvbuf: int | None = None) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if rcvbuf:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
        if bind:
            self.sock.bind((bind, 0))
        self.sock.settimeout(5.0)
        self.sock.connect(address)
        self.buffer = b""

    def send(self, data: bytes) -> None:
        self.sock.sendall(data)

    def read_line(self, timeout: float = 5.0) -> bytes:
        """One line including its CR LF; b"" when the server closed the connection."""
        deadline = time.monotonic() + timeout
        while b"\r\n" not in self.buffer:
            self.sock.settimeout(max(0.01, deadline - time.monotonic()))
            chunk = self.sock.recv(65536)
            if not chunk:
                return b""
            self.buffer += chunk
        line, self.buffer = self.buffer.split(b"\r\n", 1)
        return line + b"\r\n"

    def text(self, timeout: float = 5.0) -> str:
        return self.read_line(timeout).decode("ascii").removesuffix("\r\n")

    def ask(self, line: str) -> str:
        self.send(line.encode("ascii") + b"\r\n")
        return self.text()

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def tcp_station() -> Iterator[tuple[Station, NovaTcpServer]]:
    station = make_station()
    server = NovaTcpServer(station.core, LOOPBACK_ONLY)
    server.start()
    try:
        yield station, server
    finally:
        server.stop()


@pytest.fixture
def client(tcp_station) -> Iterator[LineClient]:
    _, server = tcp_station
    c = LineClient(server.address)
    assert c.read_line() == b"Hello, this is Nova for Windows.\r\n"
    yield c
    c.close()


def with_so_50() -> Catalog:
    """The tests' catalog and SO-50 (27607), from the bundled test data."""
    lines = (DATA / "active.txt").read_text().splitlines()
    at = next(k for k, line in enumerate(lines) if line.startswith(f"1 {SO_50}U"))
    extra = load_elements("\n".join(lines[at - 1:at + 2]) + "\n", "so-50").sets
    return Catalog([*load_element_file(DATA / "visual.txt").sets, *extra])


@pytest.fixture
def http_station() -> Iterator[tuple[Station, NovaTcpServer]]:
    """A station tracking the ISS whose catalog holds SO-50 too; TCP open to 127.0.0.0/8."""
    station = make_station(ISS_PASS.aos - timedelta(seconds=60), catalog=with_so_50())
    server = NovaTcpServer(station.core, dataclasses.replace(LOOPBACK_ONLY, allow=("127.0.0.0/8",)))
    server.start()
    try:
        yield station, server
    finally:
        server.stop()
