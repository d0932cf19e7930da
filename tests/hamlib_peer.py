"""A scripted Hamlib peer on a real loopback socket, for hostile-reply tests and the reliability campaign."""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable


class ScriptedPeer:
    """A loopback TCP server speaking Hamlib's line protocol badly: ``answer(command, n)`` gives the
    bytes sent for the n-th command received (counted over all connections); b"" sends nothing,
    None closes that connection."""

    def __init__(self, answer: Callable[[str, int], bytes | None]) -> None:
        self.answer = answer
        self.commands = 0
        self.connections = 0
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="hamlib-peer", daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        self.listener.settimeout(0.05)
        while not self._stop.is_set():
            try:
                conn, _ = self.listener.accept()
            except OSError:
                continue
            self.connections += 1
            threading.Thread(target=self._talk, args=(conn,), daemon=True).start()

    def _talk(self, conn: socket.socket) -> None:
        pending = b""
        conn.settimeout(0.2)
        with conn:
            while not self._stop.is_set():
                try:
                    chunk = conn.recv(4096)
                except TimeoutError:
                    continue
                except OSError:
                    return
                if not chunk:
                    return
                pending += chunk
                while b"\n" in pending:
                    line, pending = pending.split(b"\n", 1)
                    self.commands += 1
                    reply = self.answer(line.decode("ascii", "replace"), self.commands)
                    if reply is None:
                        return
                    try:
                        conn.sendall(reply)
                    except OSError:
                        return

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2)
        self.listener.close()
