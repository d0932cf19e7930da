"""One link's health: ok, or failing with a reason, retried with a bounded backoff, healed by one success.

Usage, from whatever thread owns the link::

    if health.may_try():            # ok, or the backoff since the last failure has run out
        try:
            do_the_io()
        except SomeError as exc:
            health.failed(str(exc))  # first failure: one warning; repeats: counted, rate-limited
        else:
            health.succeeded()       # clears the fault at once, with one line saying so

Delays are seconds on the injected clock (:meth:`Clock.monotonic`): the first retry comes
``initial_s`` after the first failure, each further one doubles the delay, up to ``max_s``.  A caller
may :meth:`LinkHealth.retry_now` (an operator action: a new satellite, ``TRACK ON``, a reload) to
skip the wait once.  A link that is tried on its own schedule anyway (the tracker computes every tick)
is made with ``paced=False``: it is never held back and its lines name no retry time.

Log lines are limited per episode, not per link: the first failure of each episode (a fault after the link
was well) and its recovery are written; only the repeats within an episode are rate-limited.  A fault that
comes back less than :data:`FLAP_GAP_S` after the last one cleared belongs to the same episode in the log
(a link flapping every tick writes a line a minute, not two a tick).

Thread-safe: the state is read by ``STATUS`` and the console from other threads.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass

from nfwserver.clock import Clock
from nfwserver.ratelimited_log import RateLimitedLog

__all__ = ["FLAP_GAP_S", "Backoff", "Fault", "LinkHealth"]

log = logging.getLogger(__name__)

#: A link well for less than this (clock seconds) between two faults is flapping: one episode in the log.
FLAP_GAP_S = 2.0


@dataclass(frozen=True)
class Backoff:
    """Retry delays: ``initial_s``, doubled after every further failure, at most ``max_s`` (seconds)."""

    initial_s: float = 1.0
    max_s: float = 60.0

    def __post_init__(self) -> None:
        if not 0 < self.initial_s <= self.max_s:
            raise ValueError("backoff needs 0 < initial_s <= max_s")

    def delay(self, failures: int) -> float:
        """Seconds to wait after the ``failures``-th failure in a row (1 = the first)."""
        if failures <= 0:
            return 0.0
        return min(self.max_s, self.initial_s * 2.0 ** min(failures - 1, 60))


@dataclass(frozen=True)
class Fault:
    """What is wrong with a link now."""

    reason: str  #: the latest failure, one line
    since: float  #: clock monotonic seconds of the first failure in this run
    failures: int  #: failures in a row
    retry_at: float  #: clock monotonic seconds of the next attempt

    def describe(self, now: float) -> str:
        """``reason (N failures in S s, retry in R s)``: what STATUS and the console show."""
        if self.failures == 0:
            return f"{self.reason} (for {now - self.since:.0f} s)"
        wait = max(0.0, self.retry_at - now)
        times = "failure" if self.failures == 1 else "failures"
        return f"{self.reason} ({self.failures} {times} in {now - self.since:.0f} s, retry in {wait:.0f} s)"


class LinkHealth:
    """The health of the link called ``name``; see the module docstring."""

    def __init__(self, name: str, clock: Clock, backoff: Backoff | None = None,
                 logger: logging.Logger | None = None, on_change: Callable[[LinkHealth], None] | None = None,
                 paced: bool = True) -> None:
        self.name = name
        self.paced = paced
        self.clock = clock
        self.backoff = backoff or Backoff()
        self.logger = logger or log
        self.on_change = on_change
        self._lines = RateLimitedLog(self.logger, clock)
        self._lock = threading.Lock()
        self._fault: Fault | None = None
        self.recoveries = 0  #: faults healed so far (for benchmarks and tests)
        self._announced = False  # the current fault's first failure was written to the log
        self._recovered_at: float | None = None  # clock monotonic seconds the last fault cleared

    # -- reading ---------------------------------------------------------------------------
    @property
    def ok(self) -> bool:
        return self._fault is None

    @property
    def fault(self) -> Fault | None:
        return self._fault

    def describe(self) -> str:
        """``ok`` or the fault, for STATUS and the console."""
        fault = self._fault
        if fault is None:
            return "ok"
        if not self.paced:
            now = self.clock.monotonic()
            times = "failure" if fault.failures == 1 else "failures"
            return f"{fault.reason} ({fault.failures} {times} in {now - fault.since:.0f} s)"
        return fault.describe(self.clock.monotonic())

    def may_try(self) -> bool:
        """True when the link is ok or its retry time has come."""
        fault = self._fault
        return fault is None or not self.paced or self.clock.monotonic() >= fault.retry_at

    # -- writing ---------------------------------------------------------------------------
    def failed(self, reason: str, level: int = logging.WARNING, *, attempt: bool = True) -> Fault:
        """Record a failure: the first of a run is logged at once, repeats are counted (rate-limited).

        ``attempt=False`` records a symptom seen between attempts (a refused command before the link is
        declared down): the fault shows with its reason, but the back-off does not grow."""
        reason = " ".join(str(reason).split()) or "failed"
        now = self.clock.monotonic()
        with self._lock:
            old = self._fault
            before = 0 if old is None else old.failures
            failures = before + 1 if attempt else before
            if attempt or old is None:
                delay = self.backoff.delay(failures) if self.paced else 0.0
                retry_at = now + delay
            else:
                retry_at = old.retry_at
            fault = Fault(reason, now if old is None else old.since, failures, retry_at)
            self._fault = fault
        # A new episode (the link was well for a while) is written whatever the rate limit; repeats are not.
        new_episode = old is None and (self._recovered_at is None or now - self._recovered_at >= FLAP_GAP_S)
        if self.paced:
            wait = fault.retry_at - now  # "0.2 s" for a short back-off, never "0 s"
            written = self._lines.log(level, self.name, "%s: %s; retrying in %s s", self.name, reason,
                                      f"{round(wait, 1) if wait < 10 else round(wait):g}", force=new_episode)
        else:
            written = self._lines.log(level, self.name, "%s: %s", self.name, reason, force=new_episode)
        if old is None:
            self._announced = written  # a link that flaps every tick writes a line a minute, not two a tick
        if old is None:
            self._changed()
        return fault

    def succeeded(self) -> None:
        """Record a success: a fault clears at once, with one line saying how long it lasted (when its
        first failure was written: a link flapping faster than the rate limit is summarised, not echoed)."""
        with self._lock:
            old, self._fault = self._fault, None
        if old is None:
            return
        self._recovered_at = self.clock.monotonic()
        self.recoveries += 1
        if self._announced:
            count = f" ({old.failures} failure{'s' if old.failures != 1 else ''})" if old.failures else ""
            self.logger.warning("%s: recovered after %.1f s%s", self.name, self.clock.monotonic() - old.since, count)
        self._changed()

    def retry_now(self) -> None:
        """Let the next :meth:`may_try` pass at once (an operator action); the fault stays until a success."""
        with self._lock:
            fault = self._fault
            if fault is not None:
                self._fault = Fault(fault.reason, fault.since, fault.failures, self.clock.monotonic())

    def _changed(self) -> None:
        if self.on_change is not None:
            try:
                self.on_change(self)
            except Exception:
                self.logger.exception("health listener for %s failed", self.name)
