"""The tracker: turns a clock tick into a :class:`~nfwserver.core.sample.TickSample` and hands it to every output.

Each :meth:`Tracker.tick` reads the live :class:`~nfwserver.core.state.StationState` once, computes
the AutoTracking satellite's look angles for the tick's instant (SGP4, topocentric az/el in degrees,
range rate in km/s), decides ``AH`` from the horizon table, formats Nova's string once, works out
OrbitDRV's status word, and calls every subscriber with the sample.

Status word (seed: OrbitDRV interrupt interface), as this tracker reads it:

- 0x0001 / 0x0002: no station / no (known) satellite selected.
- 0x0004: tracking disabled (Nova's ``TRACK OFF``); 0x0008: *tuning* disabled in OrbitDRV's sense,
  i.e. the radio gets no Doppler updates (:attr:`TickSample.doppler_on` off).  Nova's ``TUNE`` (the feed)
  is reported separately (:attr:`TickSample.feed_on`), because OrbitDRV's tuning is the radio's, not the feed's.
- 0x0010: an arithmetic error, with its code.  OrbitDRV's words are "No computations will be done
  until a new Enable call is made"; a server left unattended must not go silent for good on one bad
  instant (a clock step, a set past decay), so here the error **belongs to the tick** in which the
  computation failed: every tick computes again, the bit and its code are set for each tick that
  fails and clear on the first one that succeeds, and the feed resumes with it.  While it lasts the
  feed is empty, the ``tracking`` link on the health board says why (STATUS ``faults=tracking``), and
  the log has one line for the start of the fault (rate-limited repeats) and one for its end.
- 0x0020: not in view (only while tracking is enabled); 0x0040: not recomputed since the last
  parameter change.
- 0x4000 / 0x8000: the most recent command had a bad function (not a command we know) / a bad
  subfunction (a known command with a bad argument).  They describe that command and clear with the
  next accepted one (:meth:`Tracker.note_command`).

Threading: :meth:`tick` runs on the publisher thread (or the caller's, in virtual time).
Subscribers run on that thread and must be quick: they record the sample, post DDE advises or format
a string; anything slow belongs on a :class:`~nfwserver.core.tick_worker.TickWorker`.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import replace
from datetime import datetime

from nfwserver.clock import Clock
from nfwserver.core.events import Direction, EventLog
from nfwserver.core.nova_protocol import format_nova
from nfwserver.core.sample import TickSample
from nfwserver.core.state import StateSnapshot, StationState
from nfwserver.core.status import ArithmeticErrorCode, StatusBit
from nfwserver.health.link_health import LinkHealth
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.tracking.catalog import Satellite
from nfwserver.tracking.look_angles import LookAngleCalculator, LookAngles, PropagationError

log = logging.getLogger(__name__)

TickListener = Callable[[TickSample], None]


def _nova_string(snap: StateSnapshot, angles: LookAngles | None) -> tuple[str, bool]:
    """The Nova string for ``angles`` of the selected satellite in ``snap`` ("" while the feed is off or nothing
    is computed) and whether the satellite is above the horizon table (Nova's ``AH``)."""
    above = angles is not None and snap.horizon.is_above(angles.azimuth_deg, angles.elevation_deg)
    if angles is None or snap.satellite is None or not snap.feed_on:
        return "", above
    return format_nova(snap.satellite.dde_name, angles.azimuth_deg, angles.elevation_deg, angles.range_rate_km_s,
                       above), above


class Tracker:
    """Computes ticks from ``state``; see the module docstring."""

    def __init__(self, state: StationState, clock: Clock, events: EventLog,
                 health: LinkHealth | None = None) -> None:
        self.state = state
        self.health = health  #: the ``tracking`` link: failing while the selected satellite cannot be computed
        self.clock = clock
        self.events = events
        self._lock = threading.Lock()
        self._listeners: list[TickListener] = []
        self._calculator: tuple[object, LookAngleCalculator] | None = None
        self._last: TickSample | None = None
        self._text = ""
        self._computed_generation = -1
        self._error = ArithmeticErrorCode.NONE
        self._command_bits = 0
        #: per-tick failures (a listener, a satellite without a health link): one line, then a count a minute
        self._faults = RateLimitedLog(log, clock, 60.0)

    # -- subscribers -------------------------------------------------------------------------
    def subscribe(self, listener: TickListener) -> Callable[[], None]:
        """Call ``listener(sample)`` after every tick; returns a function that unsubscribes it."""
        with self._lock:
            self._listeners.append(listener)

        def unsubscribe() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    # -- what clients read -------------------------------------------------------------------
    @property
    def last_sample(self) -> TickSample | None:
        return self._last

    def current_text(self) -> str:
        """What a request answers now: the latest Nova string (this tick's, or the one computed when the
        satellite was changed or the output switched on since); "" before TUNE ON, after TUNE OFF, with
        no satellite, and while the computation fails."""
        return self._text  # replaced whole under the lock; reading one attribute needs none

    def status_word(self) -> int:
        """The status word now (OrbitDRV's Get Status Only)."""
        snap = self.state.snapshot()
        with self._lock:
            return self._status(snap, self._last)

    # -- what commands tell the tracker --------------------------------------------------------
    def selection_changed(self) -> None:
        """A new AutoTracking satellite: never serve the old one's string; the new one's is there at once."""
        self.refresh_text()

    def refresh_text(self) -> None:
        """Compute the Nova string for the live state now (a command's thread, right after ``SAT=`` or
        ``TUNE ON``), so a request that follows the command gets the new satellite's string rather than ""
        or the old one's.  No tick: subscribers are not called, the status word and the sample stay the
        tick's; a satellite that cannot be computed gives "" (its tick reports why)."""
        snap = self.state.snapshot()
        angles = None
        calc = self._calculator_for(snap)
        if snap.feed_on and snap.satellite is not None and calc is not None:
            try:
                angles = calc.compute(snap.satellite.satrec, self.clock.now())
            except (PropagationError, ArithmeticError, ValueError):
                angles = None
        text, _ = _nova_string(snap, angles)
        with self._lock:
            if self._still_current(snap):  # else a newer command refreshes after us
                self._text = text

    def _still_current(self, snap: StateSnapshot) -> bool:
        """The string computed from ``snap`` is still the one to serve: the same satellite, the output the same."""
        return self.state.catalog_number == snap.catalog_number and self.state.feed_on == snap.feed_on

    def why_not_computable(self, satellite: Satellite, when: datetime | None = None) -> str | None:
        """Why ``satellite`` cannot be computed at ``when`` (default now) for this station, or None if it can.

        Used before a ``SAT=`` takes effect, so a client never gets a silent OK for a set that will
        publish nothing (SGP4 error codes, a set past decay)."""
        calc = self._calculator_for(self.state.snapshot())
        if calc is None:
            return None  # no observer: nothing is computed for any satellite, and STATUS says why
        try:
            calc.compute(satellite.satrec, self.clock.now() if when is None else when)
        except (PropagationError, ArithmeticError, ValueError) as exc:
            return str(exc) or type(exc).__name__
        return None

    def feed_off(self) -> None:
        with self._lock:
            self._text = ""

    def note_command(self, bits: int) -> None:
        """Record the bad-function/subfunction bits of the most recent command (0 when accepted)."""
        with self._lock:
            self._command_bits = bits & (StatusBit.BAD_FUNCTION | StatusBit.BAD_SUBFUNCTION)

    # -- ticking -----------------------------------------------------------------------------
    def _status(self, snap: StateSnapshot, sample: TickSample | None) -> int:
        word = self._command_bits
        if snap.observer is None:
            word |= StatusBit.STATION_MISSING
        if snap.satellite is None:
            word |= StatusBit.SATELLITE_MISSING
        if not snap.tracking:
            word |= StatusBit.TRACKING_DISABLED
        if not snap.doppler_on:
            word |= StatusBit.TUNING_DISABLED
        if self._error:
            word |= StatusBit.ARITHMETIC_ERROR
        if snap.tracking and sample is not None and sample.look_angles is not None and not sample.above_horizon:
            word |= StatusBit.NOT_IN_VIEW
        if snap.generation != self._computed_generation:
            word |= StatusBit.NOT_RECOMPUTED
        return int(word)

    def _calculator_for(self, snap: StateSnapshot) -> LookAngleCalculator | None:
        if snap.observer is None:
            return None
        key = (snap.observer, snap.ut1_utc_s)
        cached = self._calculator
        if cached is None or cached[0] != key:
            cached = (key, LookAngleCalculator(snap.observer, snap.ut1_utc_s))
            self._calculator = cached
        return cached[1]

    def _compute(self, snap: StateSnapshot, when: datetime) -> tuple[LookAngles | None, ArithmeticErrorCode]:
        sat, calc = snap.satellite, self._calculator_for(snap)
        if sat is None or calc is None:
            return None, ArithmeticErrorCode.NONE
        reason: Exception
        try:
            return calc.compute(sat.satrec, when), ArithmeticErrorCode.NONE
        except PropagationError as exc:
            code, reason = ArithmeticErrorCode.DEGENERATE_ORBIT, exc
        except OverflowError as exc:
            code, reason = ArithmeticErrorCode.OVERFLOW, exc
        except (ValueError, ArithmeticError) as exc:
            code, reason = ArithmeticErrorCode.DOMAIN, exc
        if self.health is not None:
            self.health.failed(f"cannot compute {sat.dde_name} (arithmetic error {int(code):02X}): {reason}",
                               logging.ERROR)
        else:
            self._faults.error(f"compute:{sat.catalog_number}", "cannot compute %s at %s: %s", sat.dde_name,
                               when.isoformat(), reason)
        if self._error != code:
            self.events.add(when, Direction.INFO, "note",
                            f"arithmetic error {int(code):02X} for {sat.dde_name}: {reason}", accepted=False)
        return None, code

    def tick(self, when: datetime | None = None) -> TickSample:
        """Compute and hand out one sample for ``when`` (default: the clock's now).  Never raises for bad data."""
        when = self.clock.now() if when is None else when
        snap = self.state.snapshot()
        sat = snap.satellite
        angles, error = self._compute(snap, when)
        with self._lock:
            self._error = error
        if not error and self.health is not None and not self.health.ok:
            self.health.succeeded()
        text, above = _nova_string(snap, angles)
        with self._lock:
            if self.state.generation == snap.generation:
                self._computed_generation = snap.generation
            if self._still_current(snap):  # else a command changed the satellite or the output meanwhile
                self._text = text
            sample = TickSample(when, snap.catalog_number, sat.dde_name if sat else None, angles, above,
                                snap.feed_on, snap.tracking, text, 0, snap.doppler_on, self._error)
            sample = replace(sample, status=self._status(snap, sample))
            self._last = sample
            listeners = list(self._listeners)
        for listener in listeners:
            try:
                listener(sample)
            except Exception:
                self._faults.log(logging.ERROR, f"listener:{id(listener)}", "tick listener %r failed", listener,
                                 exc_info=True)
        return sample

