"""A robust client for Hamlib's daemons' line protocol (rigctld, rotctld) over TCP.

Facts of the protocol this relies on (seen with Hamlib 4.5.4): a set command answers one line
``RPRT n`` (0 = success, negative = an error, see :mod:`nfwserver.hamlib.errors`); a get command
answers its values, one per line, with no ``RPRT`` on success but ``RPRT n`` on failure; an unknown
command gets no reply at all and a command missing an argument makes the daemon wait for more
input.  So only complete, known commands are sent, and every reply is awaited with a timeout.

When the daemon dies (EOF, broken pipe, refused connection) the connection is dropped and
:class:`HamlibUnavailable` is raised at once, saying "not reachable at HOST:PORT" until a first connection was
made (a wrong port, a daemon not started) and "lost" after one; reconnection is attempted on a later call, no
sooner than the back-off delay (doubling from ``backoff_initial_s`` to ``backoff_max_s``; measured on the
injected clock; the station uses 0.2 s then 0.4 s), so a dead daemon never stalls the caller.  The connection's
state is one
:class:`~nfwserver.health.LinkHealth` (the station puts it on its board as ``rotctld``/``rigctld``):
failing while the daemon cannot be reached or answers nonsense, cleared by the first whole reply.

Every reply must arrive whole within ``reply_deadline_s`` real seconds (a daemon that trickles one
byte at a time, each within the per-read timeout, would otherwise hold the caller for hours); past
it the connection is dropped as for a dead daemon.  A reply that arrives but took longer than
:data:`SLOW_REPLY_S` keeps the link failing ("answers slowly") until a prompt one.

A reply that makes no sense (a line over :data:`MAX_LINE_BYTES`, a value where ``RPRT`` was due, no
value where one was due, or a value the backend finds non-finite or out of range and reports with
:meth:`HamlibConnection.fault`) is a *device fault*: it is counted in ``faults``, raised as
:class:`HamlibError`, and the connection is dropped (reopened on the next call, without back-off)
because whatever else is in flight can no longer be matched to a command.  Warnings about a
daemon that keeps failing are rate-limited (:mod:`nfwserver.ratelimited_log`).
"""

from __future__ import annotations

import logging
import socket
import time

from nfwserver.clock import Clock
from nfwserver.hamlib.commands import HamlibCommand
from nfwserver.hamlib.errors import describe_rprt
from nfwserver.health import Backoff, LinkHealth
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)

#: Longest reply line accepted (bytes); Hamlib's replies are a few dozen.
MAX_LINE_BYTES = 65536
#: A whole reply must arrive within this many real seconds (rigctld behind a slow serial radio: ~0.3 s).
REPLY_DEADLINE_S = 2.0
#: A reply slower than this (real seconds) is answered but keeps the link failing ("answers slowly"): a daemon
#: that trickles its replies must not look healthy between the ones that miss the deadline.
SLOW_REPLY_S = 1.0


def _reason(exc: BaseException) -> str:
    """An OS error as words ("connection refused"), without ``[Errno n]``."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror[:1].lower() + exc.strerror[1:]
    return str(exc) or type(exc).__name__


class HamlibError(Exception):
    """The daemon answered with an error (``code`` is the RPRT value) or with nonsense."""

    def __init__(self, message: str, code: int | None = None) -> None:
        self.code = code
        super().__init__(message)


class HamlibUnavailable(HamlibError):
    """The daemon cannot be reached now (down, restarting, or not answering in time)."""


class HamlibConnection:
    """One TCP connection to a Hamlib daemon, reopened on demand."""

    def __init__(self, host: str, port: int, clock: Clock, name: str = "hamlib", timeout_s: float = 1.0,
                 backoff_initial_s: float = 0.25, backoff_max_s: float = 1.5, warn_interval_s: float = 60.0,
                 reply_deadline_s: float = REPLY_DEADLINE_S, health: LinkHealth | None = None) -> None:
        self.host, self.port, self.clock, self.name = host, port, clock, name
        self.timeout_s = timeout_s
        self.reply_deadline_s = reply_deadline_s
        #: reachability of the daemon: failing while it is down, silent or answering nonsense
        self.health = health if health is not None else LinkHealth(
            name, clock, Backoff(backoff_initial_s, backoff_max_s), logger=log)
        self._sock: socket.socket | None = None
        self._buffer = b""
        self.reconnects = 0
        self.ever_connected = False  #: a connection was made once: a failure now is "lost", not "not reachable"
        self.faults = 0  #: replies rejected as nonsense (device faults), in total
        self.warnings = RateLimitedLog(log, clock, warn_interval_s)

    @property
    def connected(self) -> bool:
        return self._sock is not None

    def _connect(self) -> socket.socket:
        if self._sock is not None:
            return self._sock
        if not self.health.may_try():
            fault = self.health.fault
            wait = fault.retry_at - self.clock.monotonic() if fault is not None else 0.0
            raise HamlibUnavailable(f"{self._down()}; retrying in {wait:.1f} s")
        try:
            sock = socket.create_connection((self.host, self.port), timeout=self.timeout_s)
        except OSError as exc:
            message = self._down(_reason(exc))
            self._fail(message)
            raise HamlibUnavailable(message) from None
        sock.settimeout(self.timeout_s)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)  # one short line per command
        self._sock, self._buffer = sock, b""
        self.ever_connected = True
        if not self.health.ok:
            self.reconnects += 1
        return sock

    def _drop(self) -> None:
        """Close the socket (if any) and forget what was buffered from it."""
        if self._sock is not None:
            try:
                self._sock.close()
            except OSError:
                pass
        self._sock, self._buffer = None, b""

    def _down(self, why: str = "") -> str:
        """Why the daemon cannot be used: "not reachable at HOST:PORT" until the first connection (a wrong port, a
        daemon not started), "at HOST:PORT lost" once one was made (the daemon stopped or restarts)."""
        detail = f" ({why})" if why else ""
        if self.ever_connected:
            return f"{self.name} at {self.host}:{self.port} lost{detail}"
        return f"{self.name} not reachable at {self.host}:{self.port}{detail}"

    def _fail(self, message: str) -> None:
        self._drop()
        self.health.failed(message)

    def fault(self, why: str) -> HamlibError:
        """Count a nonsense reply, drop the connection (it may be out of step) and return the error to raise.
        The link is failing until a whole reply makes sense again; the next call reconnects at once."""
        self.faults += 1
        self._drop()
        self.health.failed(f"{self.name} at {self.host}:{self.port} sent a reply that makes no sense ({why})")
        self.health.retry_now()
        return HamlibError(f"{self.name}: {why}")

    def _answered(self, command: str, sent_at: float) -> None:
        """A whole reply: the link is well unless it took longer than :data:`SLOW_REPLY_S`."""
        took = time.monotonic() - sent_at
        if took > SLOW_REPLY_S:
            self.health.failed(f"{self.name} at {self.host}:{self.port} answers slowly ({took:.1f} s for "
                               f"'{command.split()[0]}')", attempt=False)
        else:
            self.health.succeeded()

    def _read_line(self, sock: socket.socket, deadline: float) -> str:
        while b"\n" not in self._buffer:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError(f"no whole reply within {self.reply_deadline_s:g} s")
            sock.settimeout(min(self.timeout_s, remaining))
            try:
                chunk = sock.recv(4096)
            except TimeoutError:
                if time.monotonic() >= deadline:
                    raise TimeoutError(f"no whole reply within {self.reply_deadline_s:g} s") from None
                raise
            if not chunk:
                raise ConnectionResetError("the daemon closed the connection")
            self._buffer += chunk
            if len(self._buffer) > MAX_LINE_BYTES:
                raise self.fault(f"a reply line longer than {MAX_LINE_BYTES} bytes")
        line, self._buffer = self._buffer.split(b"\n", 1)
        return line.decode("ascii", errors="replace").strip()

    def transact(self, command: str, reply_lines: int) -> list[str]:
        """Send one complete command and read ``reply_lines`` lines (0 for set commands: read RPRT).

        Returns the value lines of a get command; raises :class:`HamlibError` for ``RPRT`` < 0 and
        :class:`HamlibUnavailable` when the daemon is down or silent.
        """
        if "\n" in command or "\r" in command:
            raise ValueError("a Hamlib command is one line")
        sock = self._connect()
        sent_at = time.monotonic()
        deadline = sent_at + self.reply_deadline_s
        try:
            sock.sendall(command.encode("ascii") + b"\n")
            first = self._read_line(sock, deadline)
            if first.startswith("RPRT"):
                parts = first.split()
                try:
                    code = int(parts[1]) if len(parts) > 1 else -8
                except ValueError:
                    raise self.fault(f"{first[:40]!r} is not an RPRT line") from None
                if code < 0:
                    self._answered(command, sent_at)  # the daemon answered: reachable, whatever the device says
                    raise HamlibError(f"{self.name}: '{command}' failed: {describe_rprt(code)} (RPRT {code})", code)
                if reply_lines:
                    raise self.fault(f"{first!r} instead of a value to '{command}'")
                self._answered(command, sent_at)
                return []
            if reply_lines == 0:
                raise self.fault(f"unexpected reply {first[:40]!r} to '{command}'")
            lines = [first] + [self._read_line(sock, deadline) for _ in range(reply_lines - 1)]
            self._answered(command, sent_at)
            return lines
        except HamlibError:
            raise
        except (OSError, ValueError) as exc:  # timeout, reset, broken pipe, garbage numbers
            message = self._down(_reason(exc))
            self._fail(message)
            raise HamlibUnavailable(message) from None

    def call(self, command: HamlibCommand, *args: object) -> list[str]:
        """Send one command from :mod:`nfwserver.hamlib.commands` and read its reply (see :meth:`transact`)."""
        return self.transact(command.line(*args), command.reply_lines)

    def close(self) -> None:
        if self._sock is not None:
            try:
                self._sock.close()
            finally:
                self._sock = None


def daemon_link_ok(device: object) -> bool:
    """False while the Hamlib daemon behind ``device`` (a backend holding a :class:`HamlibConnection` as
    ``connection``) has a fault on the station's board: unreachable, answering slowly or with nonsense.  True
    for a device without a daemon (the simulated rotor)."""
    connection = getattr(device, "connection", None)
    return not isinstance(connection, HamlibConnection) or connection.health.ok
