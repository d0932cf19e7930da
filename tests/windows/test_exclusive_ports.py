"""Issue 42 item 13 on Windows: every listener holds its port with SO_EXCLUSIVEADDRUSE, never SO_REUSEADDR, so
no other program (nor a second station) can bind over it, and a busy port is said to be in use.

Runs only on Windows or under Wine (``tools/wine/test``); on Linux tests/app/test_listener_errors.py checks the
POSIX side on a real busy port.
"""

from __future__ import annotations

import socket
import sys

import pytest

from nfwserver.listen_errors import bind_failure
from nfwserver.listen_socket import datagram_socket, stream_listener

pytestmark = pytest.mark.skipif(sys.platform != "win32", reason="SO_EXCLUSIVEADDRUSE is Windows' option")


def test_listeners_hold_their_port_exclusively() -> None:
    tcp = stream_listener("127.0.0.1", 0)
    udp = datagram_socket("127.0.0.1", 0)
    try:
        for sock in (tcp, udp):
            assert sock.getsockopt(socket.SOL_SOCKET, socket.SO_EXCLUSIVEADDRUSE) == 1
            assert sock.getsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR) == 0
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as thief:  # what SO_REUSEADDR allowed before
            thief.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            with pytest.raises(OSError):
                thief.bind(tcp.getsockname())
    finally:
        tcp.close()
        udp.close()


def test_a_busy_port_is_said_to_be_in_use() -> None:
    ours = stream_listener("127.0.0.1", 0)
    port = ours.getsockname()[1]
    try:
        with pytest.raises(OSError) as caught:
            stream_listener("127.0.0.1", port)
    finally:
        ours.close()
    text = bind_failure(caught.value, "tcp", "127.0.0.1", port).strerror
    assert text is not None and text.startswith(f"port {port} is already in use (by another program or another "
                                                "station)"), text
