"""Real Hamlib daemons (rotctld, rigctld) for tests, on free 127.0.0.1 ports.

Tests talk to the real programs from Debian's ``libhamlib-utils`` with the dummy models
(``-m 1``), never to a mock.  A daemon can be killed and restarted on the same port to test
reconnection.
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time

import pytest

from tests.waiting import wait_for


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def require_program(name: str) -> str:
    """Path of ``name``; skip the test if it is missing, except under CI where it must be there."""
    path = shutil.which(name)
    if path is None:
        if os.environ.get("CI") and sys.platform.startswith("linux"):
            pytest.fail(f"{name} is not installed (CI must install libhamlib-utils)")
        pytest.skip(f"{name} not installed (apt-get install libhamlib-utils)")
    return path


class HamlibDaemon:
    """One rotctld/rigctld process listening on 127.0.0.1:``port``.

    ``program`` is ``"rotctld"`` or ``"rigctld"``; ``extra`` are further command-line arguments
    (for example ``["--set-conf=min_az=0,max_az=450"]``).
    """

    def __init__(self, program: str, model: int = 1, extra: list[str] | None = None) -> None:
        self.program = require_program(program)
        self.model = model
        self.extra = list(extra or [])
        self.host = "127.0.0.1"
        self.port = free_port()
        self.proc: subprocess.Popen[bytes] | None = None
        self._reader: socket.socket | None = None
        self._pending = b""
        self._started_once = False

    def start(self, timeout: float = 10.0) -> HamlibDaemon:
        """Start the daemon and wait until it listens.

        The port is free when chosen, but another test running in parallel may take it before the daemon
        binds it; the daemon then exits and, on the first start, a new port is tried.  A listener is taken as
        the daemon only once it is seen to belong to this process (Linux: /proc), so a test never talks,
        unknowingly, to another test's daemon.

        Where /proc tells, no connection is made to find this out.  Hamlib 4.5's rigctld and rotctld close a
        finished client's descriptor three times (``fclose`` of its input stream, of its output stream, then
        ``close``: tests/rigctld.c ``handle_socket``, unchanged upstream); when the main thread accepts the next
        connection between those calls it gets the same descriptor number, and the late ``close`` shuts that
        new connection, whose first command then meets "Connection reset by peer".  A probe connection closed
        at once, just before the test's own client connected, did exactly that (1 in ~300 starts when idle,
        more under load; seen with strace: ``close(7) = 0``, ``close(7) = EBADF``, ``accept(...) = 7``,
        ``close(7) = 0``)."""
        deadline = time.monotonic() + timeout
        for _attempt in range(5):
            cmd = [self.program, "-m", str(self.model), "-T", self.host, "-t", str(self.port), *self.extra]
            proc = self.proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            try:
                outcome = wait_for(lambda proc=proc: "exited" if proc.poll() is not None else self._accepting(),
                                   max(0.0, deadline - time.monotonic()), f"{' '.join(cmd)} to listen",
                                   interval_s=0.02)
            except BaseException:  # not listening in time: no daemon left behind
                proc.kill()
                proc.wait()
                raise
            if outcome == "listening":
                self._started_once = True
                return self
            if self._started_once:  # a restart must keep its port: the test is about that port
                raise RuntimeError(f"{cmd[0]} exited with {self.proc.returncode}: {' '.join(cmd)}")
            self.port = free_port()
        raise RuntimeError(f"{self.program} could not listen on a free port in 5 attempts")

    def _accepting(self) -> str | None:
        """The word ``listening`` once this daemon holds the listening socket on ``port``.  Only where /proc
        cannot tell is a connection made (and then anything listening there counts: see :meth:`start`)."""
        here = self._listening_here()
        if here is not None:
            return "listening" if here else None
        try:
            with socket.create_connection((self.host, self.port), timeout=0.2):
                return "listening"
        except OSError:
            return None

    def _listening_here(self) -> bool | None:
        """Whether this daemon process holds the listening socket on ``port``; None where /proc cannot tell."""
        try:
            with open("/proc/net/tcp") as table:
                rows = [line.split() for line in table.readlines()[1:]]
        except OSError:
            return None
        wanted = f"0100007F:{self.port:04X}"
        inodes = {row[9] for row in rows if row[1] == wanted and row[3] == "0A"}  # 0A: LISTEN
        if not inodes or self.proc is None:
            return False
        try:
            fds = os.listdir(f"/proc/{self.proc.pid}/fd")
        except OSError:
            return False
        for fd in fds:
            try:
                link = os.readlink(f"/proc/{self.proc.pid}/fd/{fd}")
            except OSError:
                continue
            if link.startswith("socket:[") and link[8:-1] in inodes:
                return True
        return False

    def kill(self) -> None:
        """Kill the daemon (SIGKILL) and wait for it to be gone."""
        self._close_reader()
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=5)
        self.proc = None

    def restart(self) -> HamlibDaemon:
        """Kill and start again on the same port."""
        self.kill()
        return self.start()

    def query(self, line: str, lines: int = 1, timeout: float = 3.0) -> list[str]:
        """Send a get command on the test's own persistent connection and read ``lines`` reply lines."""
        for attempt in (1, 2):
            try:
                if self._reader is None:
                    self._reader = socket.create_connection((self.host, self.port), timeout=timeout)
                    self._reader.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                    self._pending = b""
                self._reader.sendall(line.encode("ascii") + b"\n")
                out = []
                while len(out) < lines:
                    while b"\n" not in self._pending:
                        chunk = self._reader.recv(4096)
                        if not chunk:
                            raise ConnectionResetError("closed")
                        self._pending += chunk
                    first, self._pending = self._pending.split(b"\n", 1)
                    out.append(first.decode("ascii", errors="replace"))
                return out
            except OSError:
                self._close_reader()
                if attempt == 2:
                    raise
        raise AssertionError("unreachable")

    def _close_reader(self) -> None:
        if self._reader is not None:
            self._reader.close()
            self._reader = None

    def command(self, line: str, timeout: float = 3.0) -> str:
        """Send one raw protocol line and return the reply text (for checks); retried once on a reset."""
        try:
            return self._command_once(line, timeout)
        except ConnectionResetError:
            time.sleep(0.05)
            return self._command_once(line, timeout)

    def _command_once(self, line: str, timeout: float) -> str:
        with socket.create_connection((self.host, self.port), timeout=timeout) as sock:
            sock.sendall(line.encode("ascii") + b"\n")
            sock.settimeout(timeout)
            chunks = []
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline:
                try:
                    chunk = sock.recv(4096)
                except TimeoutError:
                    break
                except ConnectionResetError:
                    if chunks:
                        break
                    raise
                if not chunk:
                    break
                chunks.append(chunk)
                sock.settimeout(0.1)
            return b"".join(chunks).decode("ascii", errors="replace")

    def __enter__(self) -> HamlibDaemon:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.kill()
