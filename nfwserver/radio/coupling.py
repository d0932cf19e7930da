"""Coupling the Doppler tuner to the server's ticks without ever slowing the publish loop.

:class:`RadioCoupling` is a tick listener: it only records the newest sample.  A worker thread
(or a direct :meth:`RadioCoupling.process` call in tests) tunes the radio for it, so a slow or dead
``rigctld`` cannot delay the DDE feed.  Tuning runs while tuning is enabled (OrbitDRV's "enable
tuning" call; off by default), the sample has a position, and the selected satellite has a channel.
"""

from __future__ import annotations

import logging

from nfwserver.dde.session import TickSample
from nfwserver.radio.transponder import Channel
from nfwserver.radio.tuning import DopplerTuner, TuneResult
from nfwserver.tick_worker import TickWorker

log = logging.getLogger(__name__)


class RadioCoupling(TickWorker):
    """Follows ticks with ``tuner``; ``channels`` maps catalog numbers to their channel."""

    worker_name = "nfw-radio"

    def __init__(self, tuner: DopplerTuner, channels: dict[int, Channel], enabled: bool = False) -> None:
        super().__init__()
        self.tuner = tuner
        self.channels = dict(channels)
        self.enabled = enabled
        self.last_result: TuneResult | None = None
        self._catalog_number: int | None = None

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

    def stop(self) -> None:
        super().stop()
        self.tuner.backend.close()
