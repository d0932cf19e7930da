"""Doppler tuning: keep a transceiver on a channel as the range rate changes.

Each :meth:`DopplerTuner.update` computes the ground receive and transmit frequencies for the
current range rate (:meth:`nfwserver.channels.channel.Channel.ground_frequencies`) and sends a
frequency only when it moved by at least ``step_hz`` since it was last sent (radios tune in steps,
and fewer commands keep the CAT bus quiet).

The operator's knob wins: before tuning, the receive frequency is read back; if it differs from
what was last sent by more than ``knob_tolerance_hz``, the operator has retuned, and the channel's
passband offset is moved by the same amount (referred to the satellite), so tuning continues from
where the operator put it instead of fighting the knob.  On an inverting transponder the uplink
then moves the opposite way.

When the radio is unreachable, nothing is raised to the caller: the state is marked, and after
the radio returns the split setting, modes and both frequencies are sent again.  A radio that keeps
refusing is reported once and then summarised (:mod:`nfwserver.ratelimited_log`), not once per tick.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

from nfwserver.channels.channel import Channel
from nfwserver.clock import Clock, SystemClock
from nfwserver.radio.backend import RadioBackend, RadioError, RadioUnavailable
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.tracking.doppler import downlink_frequency_hz

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class TuneResult:
    rx_hz: int
    tx_hz: int | None
    sent_rx: bool
    sent_tx: bool
    knob_offset_hz: float  #: satellite-side offset adopted from the operator's knob this update (0 if none)


class DopplerTuner:
    """Tunes ``backend`` for ``channel``; see the module docstring."""

    def __init__(self, channel: Channel, backend: RadioBackend, step_hz: float = 10.0,
                 knob_tolerance_hz: float = 100.0, follow_knob: bool = True, clock: Clock | None = None) -> None:
        if step_hz <= 0 or knob_tolerance_hz < step_hz:
            raise ValueError("step_hz must be positive and knob_tolerance_hz at least step_hz")
        self.channel = channel
        self.backend = backend
        self.step_hz = step_hz
        self.knob_tolerance_hz = knob_tolerance_hz
        self.follow_knob = follow_knob
        self.available = True
        self.last_error: str | None = None
        self._last_rx: int | None = None
        self._last_tx: int | None = None
        self._prepared = False
        #: Repeated refusals are logged once, then counted (real time unless a clock is given).
        self.warnings = RateLimitedLog(log, clock if clock is not None else SystemClock())

    def set_channel(self, channel: Channel) -> None:
        """Switch channel (e.g. another satellite): everything is sent again."""
        self.channel = channel
        self._last_rx = self._last_tx = None
        self._prepared = False

    def _prepare(self) -> None:
        has_uplink = self.channel.uplink_hz is not None
        self.backend.set_split(has_uplink)
        self.backend.set_modes(self.channel.downlink_mode, self.channel.uplink_mode if has_uplink else None)
        self._prepared = True

    def _adopt_knob(self, range_rate_km_s: float) -> float:
        if not self.follow_knob or self._last_rx is None:
            return 0.0
        heard = self.backend.get_rx_frequency()
        moved = heard - self._last_rx
        if abs(moved) <= self.knob_tolerance_hz:
            return 0.0
        at_satellite = moved / downlink_frequency_hz(1.0, range_rate_km_s)
        self.channel = self.channel.with_offset(self.channel.passband_offset_hz + at_satellite)
        self._last_rx = heard
        log.info("operator retuned by %+.0f Hz; following from there", moved)
        return at_satellite

    def probe(self) -> None:
        """Read the receive frequency back, only to learn whether the radio can be reached while nothing is
        tuned (no channel, tuning off, the satellite not computed): :attr:`available` stays true either way.
        A radio found lost is prepared again (split, modes, frequencies) when tuning resumes."""
        try:
            self.backend.get_rx_frequency()
        except RadioUnavailable as exc:
            if self.available:
                log.warning("radio unavailable: %s", exc)
            self.available, self.last_error = False, str(exc)
            self._prepared, self._last_rx, self._last_tx = False, None, None
            return
        except RadioError:
            pass  # it answered: reachable, whatever it thinks of the question
        if not self.available:
            log.info("radio available again")
            self.available, self.last_error = True, None

    def update(self, range_rate_km_s: float) -> TuneResult | None:
        """Tune for ``range_rate_km_s``; returns what happened, or None when the radio is unreachable."""
        try:
            if not self._prepared:
                self._prepare()
            knob = self._adopt_knob(range_rate_km_s)
            rx, tx = self.channel.ground_frequencies(range_rate_km_s)
            rx_hz = int(round(rx))
            tx_hz = int(round(tx)) if tx is not None else None
            sent_rx = self._last_rx is None or abs(rx_hz - self._last_rx) >= self.step_hz
            if sent_rx:
                self.backend.set_rx_frequency(rx_hz)
                self._last_rx = rx_hz
            sent_tx = tx_hz is not None and (self._last_tx is None or abs(tx_hz - self._last_tx) >= self.step_hz)
            if sent_tx and tx_hz is not None:
                self.backend.set_tx_frequency(tx_hz)
                self._last_tx = tx_hz
        except RadioUnavailable as exc:
            if self.available:
                log.warning("radio unavailable: %s", exc)
            self.available, self.last_error = False, str(exc)
            self._prepared, self._last_rx, self._last_tx = False, None, None
            return None
        except RadioError as exc:
            self.warnings.error("radio refused a command", "radio refused a command: %s", exc)
            self.last_error = str(exc)
            self._prepared, self._last_rx, self._last_tx = False, None, None
            return None
        if not self.available:
            log.info("radio available again; tuning resumed")
        if self.last_error is not None:
            self.warnings.clear("radio refused a command")
        self.available, self.last_error = True, None
        return TuneResult(rx_hz, tx_hz, sent_rx, sent_tx, knob)
