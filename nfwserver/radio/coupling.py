"""Coupling the Doppler tuner to the server's ticks without ever slowing the publish loop.

:class:`RadioCoupling` is a tick listener: it only records the newest sample.  A worker thread
(or a direct :meth:`RadioCoupling.process` call in tests) tunes the radio for it, so a slow or dead
``rigctld`` cannot delay the DDE feed.  Tuning runs while tuning is enabled (OrbitDRV's "enable
tuning" call, carried in the sample from the live station state; off by default), the sample has a
position, and the selected satellite has a channel in the live state's channel table.  The tuner and
backend are owned by the worker thread.

The radio's link is kept true whatever is selected: when a tick tunes nothing, the radio is probed (one
frequency read, :meth:`DopplerTuner.probe`) if nothing was sent to it for :data:`PROBE_S` seconds, so STATUS,
the console and the web page see its daemon leave or return within about a second, and the ``rigctld`` link
logs each outage once with its true length (#44: with a satellite without a channel selected, a restarted
daemon stayed ``unreachable`` until a satellite with one was selected).
"""

from __future__ import annotations

import logging

from nfwserver.channels.channel import Channel
from nfwserver.clock import Clock
from nfwserver.core.sample import TickSample
from nfwserver.core.state import StationState
from nfwserver.core.tick_worker import TickWorker
from nfwserver.hamlib.connection import daemon_link_ok
from nfwserver.radio.tuning import DopplerTuner, TuneResult

log = logging.getLogger(__name__)

#: clock seconds without a word to the radio after which a tick that tunes nothing probes it
PROBE_S = 1.0


class RadioCoupling(TickWorker):
    """Follows ticks with ``tuner``; channels come from ``state.channels`` (catalog number -> channel)."""

    thread_name = "nfw-radio"

    def __init__(self, tuner: DopplerTuner, state: StationState, clock: Clock | None = None) -> None:
        super().__init__(clock)
        self.tuner = tuner
        self.state = state
        self._contact = -PROBE_S  # clock monotonic seconds the radio was last spoken to
        self.last_result: TuneResult | None = None
        self._catalog_number: int | None = None
        self._channel: Channel | None = None

    def process(self, sample: TickSample) -> TuneResult | None:
        """Tune for one sample now, or probe an idle radio when it is due (the worker's step; tests call it
        directly)."""
        spoke, result = self._tune(sample)
        now = self.clock.monotonic()
        if spoke:
            self._contact = now
        elif now - self._contact >= PROBE_S:
            self._contact = now
            self.tuner.probe()
        return result

    def _tune(self, sample: TickSample) -> tuple[bool, TuneResult | None]:
        """Tune for ``sample``: whether the radio was spoken to, and the tuning (None when it failed or none
        was due)."""
        if not sample.doppler_on or sample.look_angles is None or sample.catalog_number is None:
            return False, None
        channel = self.state.channels.get(sample.catalog_number)
        if channel is None:
            self.last_result = None  # another satellite's frequencies are not this one's
            self._catalog_number = self._channel = None
            return False, None
        if sample.catalog_number != self._catalog_number or channel is not self._channel:
            # another satellite, or its channel was reconfigured (the knob offset starts again)
            self._catalog_number, self._channel = sample.catalog_number, channel
            self.tuner.set_channel(channel)
        self.last_result = self.tuner.update(sample.look_angles.range_rate_km_s)
        return True, self.last_result

    def link_state(self) -> str:
        """The radio's state in one word, as STATUS, the console and the web page show it: ``unreachable``,
        ``no-channel`` (Doppler tuning is on, but the selected satellite has no radio channel: nothing is
        tuned), ``refusing`` (the radio refused the last command), ``failing`` (its daemon answers slowly
        or with nonsense), else ``ok``.  Read from the live state, so it changes with ``SAT=`` at once."""
        if not self.tuner.available:
            return "unreachable"
        if self.without_channel():
            return "no-channel"
        if self.tuner.last_error is not None:
            return "refusing"
        return "ok" if daemon_link_ok(self.tuner.backend) else "failing"

    def without_channel(self) -> bool:
        """Doppler tuning is on and the selected satellite has no radio channel (so nothing is tuned)."""
        number = self.state.catalog_number
        return self.state.doppler_on and number is not None and number not in self.state.channels

    def current_result(self) -> TuneResult | None:
        """The last tuning, unless the selected satellite has no channel (then its frequencies are stale)."""
        return None if self.without_channel() else self.last_result

    def stop(self) -> None:
        super().stop()
        self.tuner.backend.close()
