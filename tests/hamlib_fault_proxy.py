"""A loopback proxy in front of a real ``rotctld``/``rigctld`` that can be told to misbehave.

Modes (:attr:`FaultProxy.mode`), switched at any time from the campaign's thread:

- ``"pass"``: every line goes to the daemon and every byte of its answer back (the real thing);
- ``"refuse"``: set commands (``P``, ``F``, ``I``, ``V``, ``M``) are answered ``RPRT -1`` without reaching
  the daemon, reads still pass (a rotor controller refusing moves);
- ``"jam"``: set commands are answered ``RPRT 0`` without reaching the daemon (accepted, nothing moves:
  iced or jammed);
- ``"trickle"``: answers come back one byte every ``trickle_s`` real seconds (a daemon stuck on a slow
  serial line);
- ``"down"``: connections are closed at once and new ones closed on accept (the daemon gone).

The client side is read line by line (Hamlib clients send one command and wait for its answer), so
a replaced answer is always in order.
"""

from __future__ import annotations

import socket
import threading
import time

SET_COMMANDS = ("P", "F", "I", "V", "M", "S")
MODES = ("pass", "refuse", "jam", "trickle", "down")


class FaultProxy:
    """Listens on 127.0.0.1 (ephemeral port) and relays to ``upstream``; see the module docstring."""

    def __init__(self, upstream: tuple[str, int], trickle_s: float = 0.05) -> None:
        self.upstream = upstream
        self.trickle_s = trickle_s
        self.mode = "pass"
        self.set_commands_relayed = 0  #: set commands that reached the daemon
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self._stop = threading.Event()
        self._conns: list[socket.socket] = []
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, name="fault-proxy", daemon=True).start()

    def set_mode(self, mode: str) -> None:
        if mode not in MODES:
            raise ValueError(f"mode must be one of {MODES}")
        self.mode = mode
        if mode == "down":
            with self._lock:
                conns, self._conns = self._conns, []
            for conn in conns:
                try:
                    conn.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass

    def _accept(self) -> None:
        self.listener.settimeout(0.05)
        while not self._stop.is_set():
            try:
                client, _ = self.listener.accept()
            except OSError:
                continue
            if self.mode == "down":
                client.close()
                continue
            with self._lock:
                self._conns.append(client)
            threading.Thread(target=self._serve, args=(client,), daemon=True).start()

    def _serve(self, client: socket.socket) -> None:
        try:
            upstream = socket.create_connection(self.upstream, timeout=2.0)
        except OSError:
            client.close()
            return
        threading.Thread(target=self._answers, args=(upstream, client), daemon=True).start()
        pending = b""
        client.settimeout(0.2)
        with client, upstream:
            while not self._stop.is_set():
                try:
                    chunk = client.recv(4096)
                except TimeoutError:
                    continue
                except OSError:
                    return
                if not chunk:
                    return
                pending += chunk
                while b"\n" in pending:
                    line, pending = pending.split(b"\n", 1)
                    word = line.strip().split(b" ", 1)[0].decode("ascii", "replace")
                    if self.mode in ("refuse", "jam") and word in SET_COMMANDS:
                        client.sendall(b"RPRT -1\n" if self.mode == "refuse" else b"RPRT 0\n")
                        continue
                    if word in SET_COMMANDS:
                        self.set_commands_relayed += 1
                    upstream.sendall(line + b"\n")

    def _answers(self, upstream: socket.socket, client: socket.socket) -> None:
        upstream.settimeout(0.2)
        while not self._stop.is_set():
            try:
                data = upstream.recv(4096)
            except TimeoutError:
                continue
            except OSError:
                break
            if not data:
                break
            try:
                if self.mode == "trickle":
                    for i in range(len(data)):
                        client.sendall(data[i:i + 1])
                        time.sleep(self.trickle_s)
                else:
                    client.sendall(data)
            except OSError:
                break
        try:
            client.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass

    def close(self) -> None:
        self._stop.set()
        self.set_mode("down")
        self.listener.close()
