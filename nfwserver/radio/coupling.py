"""Coupling the Doppler tuner to the server's ticks without ever slowing the publish loop.

:class:`RadioCoupling` is a tick listener: it only records the newest sample.  A worker thread
(or a direct :meth:`RadioCoupling.process` call in tests) tunes the radio for it, so a slow or dead
``rigctld`` cannot delay the DDE feed.  Tuning runs while tuning is enabled (OrbitDRV's "enable
tuning" call; off by default), the sample has a position, and the selected satellite has a channel.
"""

from __future__ import annotations

import logging
import threading

from nfwserver.dde.session import TickSample
from nfwserver.radio.transponder import Channel
from nfwserver.radio.tuning import DopplerTuner, TuneResult

log = logging.getLogger(__name__)


class RadioCoupling:
    """Follows ticks with ``tuner``; ``channels`` maps catalog numbers to their channel."""

    def __init__(self, tuner: DopplerTuner, channels: dict[int, Channel], enabled: bool = False) -> None:
        self.tuner = tuner
        self.channels = dict(channels)
        self.enabled = enabled
        self.last_result: TuneResult | None = None
        self._catalog_number: int | None = None
        self._pending: TickSample | None = None
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def on_tick(self, sample: TickSample) -> None:
        """Tick listener: remember the newest sample (cheap, never blocks)."""
        self._pending = sample
        self._wake.set()

    def process(self, sample: TickSample) -> TuneResult | None:
        """Tune for one sample now (the worker's step; tests call it directly)."""
        if not self.enabled or sample.look_angles is None or sample.catalog_number is None:
            return None
        channel = self.channels.get(sample.catalog_number)
        if channel is None:
            return None
        if sample.catalog_number != self._catalog_number:
            self._catalog_number = sample.catalog_number
            self.tuner.set_channel(channel)
        self.last_result = self.tuner.update(sample.look_angles.range_rate_km_s)
        return self.last_result

    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(0.5)
            self._wake.clear()
            sample, self._pending = self._pending, None
            if sample is not None:
                try:
                    self.process(sample)
                except Exception:  # keep the worker alive whatever happens
                    log.exception("radio tuning failed")

    def start(self) -> None:
        if self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(target=self._run, name="nfw-radio", daemon=True)
            self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(5.0)
            self._thread = None
        self.tuner.backend.close()
