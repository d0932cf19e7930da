"""A PREDICT UDP server on a free loopback port and a real UDP client for it (test helper)."""

from __future__ import annotations

import socket
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from nfwserver.clock import VirtualClock
from nfwserver.core.state import StationState
from nfwserver.dialects.predict_udp import PredictContext, PredictUdpServer
from tests.dde.conftest import CATALOG, ISS, ISS_PASS, OBSERVER

END = b"\x1a\n"  #: predict.c: fprintf(fd, "%c\n", 26) appended to every -f/-p output


@dataclass
class PredictPeer:
    client: socket.socket
    address: tuple[str, int]
    clock: VirtualClock
    state: StationState
    server: PredictUdpServer
    reloads: list[str]

    def send(self, payload: str | bytes) -> None:
        self.client.sendto(payload if isinstance(payload, bytes) else payload.encode("ascii"), self.address)

    def ask(self, payload: str | bytes) -> str:
        self.send(payload)
        return self.client.recvfrom(65536)[0].decode("ascii")

    def ask_listing(self, payload: str | bytes) -> list[bytes]:
        """Every datagram up to and including the end marker."""
        self.send(payload)
        datagrams = []
        while not datagrams or datagrams[-1] != END:
            datagrams.append(self.client.recvfrom(65536)[0])
        return datagrams


@contextmanager
def predict_peer(state: StationState | None = None, clock: VirtualClock | None = None,
                 client_port: int = 0) -> Iterator[PredictPeer]:
    clock = clock or VirtualClock(ISS_PASS.tca)
    state = state or StationState(CATALOG, OBSERVER)
    reloads: list[str] = []
    ctx = PredictContext(state, clock, lambda: [ISS, 694, 99999], callsign="G0XYZ",
                         on_reload=lambda: reloads.append("x"))
    server = PredictUdpServer(ctx, "127.0.0.1", 0)
    server.start()
    client = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    # A day-long listing is ~1,440 datagrams sent as fast as they are computed (as PREDICT does); on a busy
    # machine the default receive buffer overflows before this reader gets the processor, so give it room.
    for option in (getattr(socket, "SO_RCVBUFFORCE", None), socket.SO_RCVBUF):
        if option is not None:
            try:
                client.setsockopt(socket.SOL_SOCKET, option, 16 * 2**20)
                break
            except OSError:
                continue
    client.bind(("127.0.0.1", client_port))
    client.settimeout(5.0)
    try:
        yield PredictPeer(client, server.address, clock, state, server, reloads)
    finally:
        client.close()
        server.stop()
