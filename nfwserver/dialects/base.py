"""What a dialect formats: one tick's view of the selected satellite, with its radio channel."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from nfwserver.core.sample import TickSample
from nfwserver.radio.transponder import Channel


@dataclass(frozen=True)
class DialectView:
    """The values the other trackers publish.  Frequencies are Doppler-corrected, Hz."""

    name: str  #: element name ("ISS (ZARYA)")
    dde_name: str
    azimuth_deg: float
    elevation_deg: float
    range_rate_km_s: float
    above_horizon: bool
    downlink_hz: int | None
    uplink_hz: int | None
    downlink_mode: str | None
    uplink_mode: str | None
    phase: float | None = None  #: mean anomaly in 256ths of an orbit


def view_from_sample(sample: TickSample, element_name: str, channel: Channel | None,
                     phase: float | None = None) -> DialectView | None:
    """The view for a tick, or None when there is no position."""
    la = sample.look_angles
    if la is None or sample.dde_name is None:
        return None
    rx = tx = None
    if channel is not None:
        rx_f, tx_f = channel.ground_frequencies(la.range_rate_km_s)
        rx, tx = int(round(rx_f)), (int(round(tx_f)) if tx_f is not None else None)
    return DialectView(element_name, sample.dde_name, la.azimuth_deg, la.elevation_deg, la.range_rate_km_s,
                       sample.above_horizon, rx, tx, channel.downlink_mode if channel else None,
                       channel.uplink_mode if channel and channel.uplink_hz else None, phase)


@dataclass(frozen=True)
class Dialect:
    """A tracker's DDE names and string format."""

    name: str
    service: str
    topic: str
    items: tuple[str, ...]
    format: Callable[[DialectView | None], str]  #: None: no satellite selected or no position
