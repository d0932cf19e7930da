"""What the campaign counts for each input family, and the watchers that count it.

- inputs tried;
- crashes: an exception escaping from the code under test, a thread dying (``threading.excepthook``),
  or the station no longer publishing;
- tracebacks: log records carrying exception information (or a formatted traceback in their text),
  caught by a handler on the root logger;
- data lost: state or element files not whole afterwards, values a client should have received and did
  not, a corrupt value accepted as good.
"""

from __future__ import annotations

import logging
import threading
import time
import traceback
from dataclasses import dataclass, field


@dataclass
class Budget:
    """How much of each family to run: counts of inputs, and seconds for the real-time run."""

    elements: int = 20_000  #: fuzzed element files through load_elements
    updates: int = 1000  #: fuzzed element files through `elements update`
    configs: int = 20_000
    pokes: int = 20_000  #: DDE pokes; as many TCP lines
    datagrams: int = 20_000
    hamlib_replies: int = 2400
    daemon_kills: int = 20  #: kills of both daemons together
    write_kills: int = 20  #: SIGKILLs of each writer (element store, state file)
    stop_attacks: int = 10  #: rounds of each attack on `nfwserver stop` (start-up, forged description, suspended)
    realtime_s: float = 600.0
    http_requests: int = 2000  #: web pages' requests to the TCP port (cross-protocol)
    lockout_rounds: int = 20  #: questions of the operator's status per crowd
    seed: int = 2026

    @classmethod
    def smoke(cls) -> Budget:
        """A few seconds of everything: for the test that keeps the campaign code working."""
        return cls(elements=40, updates=4, configs=60, pokes=60, datagrams=60, hamlib_replies=24,
                   daemon_kills=1, write_kills=1, stop_attacks=1, realtime_s=3.0, http_requests=20, lockout_rounds=2)


@dataclass
class Tally:
    family: str
    tried: int = 0
    crashes: int = 0
    tracebacks: int = 0
    lost: int = 0
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)  #: first few findings, each one line
    extra: dict[str, object] = field(default_factory=dict)  #: family-specific figures

    def note(self, text: str) -> None:
        if len(self.notes) < 8:
            self.notes.append(" ".join(text.split())[:300])

    def crash(self, what: str, exc: BaseException | None = None) -> None:
        self.crashes += 1
        detail = f"{type(exc).__name__}: {exc}" if exc is not None else ""
        self.note(f"crash: {what} {detail}")
        if exc is not None and len(self.notes) < 8:
            self.notes.append("".join(traceback.format_exception(exc)[-3:]).strip()[:600])

    def loss(self, what: str, count: int = 1) -> None:
        self.lost += count
        self.note(f"lost: {what}")

    @property
    def clean(self) -> bool:
        return not (self.crashes or self.tracebacks or self.lost)


class TracebackCounter(logging.Handler):
    """Counts log records that carry a traceback; attached to the root logger while a family runs.

    Also counts threads that die of an exception (through ``threading.excepthook``), which never
    reach the log."""

    def __init__(self) -> None:
        super().__init__(level=logging.DEBUG)
        self.tracebacks: list[str] = []
        self.warnings = 0
        self.dead_threads: list[str] = []
        self._old_hook = None
        self._old_level = logging.NOTSET

    def emit(self, record: logging.LogRecord) -> None:
        if record.levelno >= logging.WARNING:
            self.warnings += 1
        message = record.getMessage() if record.args else str(record.msg)
        if record.exc_info or record.stack_info or "Traceback (most recent call last)" in message:
            self.tracebacks.append(f"{record.name}: {message}"[:300])

    def _thread_died(self, args: threading.ExceptHookArgs) -> None:
        name = args.thread.name if args.thread is not None else "?"
        self.dead_threads.append(f"{name}: {args.exc_type.__name__}: {args.exc_value}")

    def __enter__(self) -> TracebackCounter:
        root = logging.getLogger()
        self._old_level = root.level
        root.setLevel(logging.INFO)
        root.addHandler(self)
        self._old_hook = threading.excepthook
        threading.excepthook = self._thread_died
        return self

    def __exit__(self, *exc: object) -> None:
        root = logging.getLogger()
        root.removeHandler(self)
        root.setLevel(self._old_level)
        threading.excepthook = self._old_hook


def run_family(tally: Tally, body) -> Tally:
    """Run ``body(tally)`` with a traceback counter; an exception escaping it is a crash of the family."""
    started = time.monotonic()
    with TracebackCounter() as counter:
        try:
            body(tally)
        except Exception as exc:  # the campaign goes on with the next family
            tally.crash("family stopped", exc)
    tally.tracebacks += len(counter.tracebacks)
    for text in counter.tracebacks[:3]:
        tally.note(f"traceback logged: {text}")
    tally.crashes += len(counter.dead_threads)
    for text in counter.dead_threads[:3]:
        tally.note(f"thread died: {text}")
    tally.extra.setdefault("warnings logged", counter.warnings)
    tally.seconds = time.monotonic() - started
    return tally
