"""What a dialect formats: one tick's view of the selected satellite, with its radio channel.

Units: angles degrees (azimuth 0..360 clockwise from north, elevation above the geodetic horizontal),
range km, range rate km/s (positive receding), frequencies Hz (Doppler-corrected), sub-satellite
point geodetic WGS84 (longitude east-positive -180..180, altitude km above the ellipsoid).
Formatters write numbers with Python's formatting, so the decimal point is always ``.`` whatever
the machine's locale.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, tzinfo

from nfwserver.channels.channel import Channel
from nfwserver.core.sample import TickSample


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
    range_km: float | None = None
    time: datetime | None = None  #: the instant the values are for, aware UTC
    local_time: datetime | None = None  #: the same instant in the station's local time zone
    subpoint: tuple[float, float, float] | None = None  #: (latitude, east longitude, altitude km)


def view_from_sample(sample: TickSample, element_name: str, channel: Channel | None,
                     phase: float | None = None, subpoint: tuple[float, float, float] | None = None,
                     local_zone: tzinfo | None = None) -> DialectView | None:
    """The view for a tick, or None when there is no position.

    ``local_zone`` is the station's time zone for local times; None means the machine's own.
    """
    la = sample.look_angles
    if la is None or sample.dde_name is None:
        return None
    rx = tx = None
    if channel is not None:
        rx_f, tx_f = channel.ground_frequencies(la.range_rate_km_s)
        rx, tx = int(round(rx_f)), (int(round(tx_f)) if tx_f is not None else None)
    return DialectView(element_name, sample.dde_name, la.azimuth_deg, la.elevation_deg, la.range_rate_km_s,
                       sample.above_horizon, rx, tx, channel.downlink_mode if channel else None,
                       channel.uplink_mode if channel and channel.uplink_hz else None, phase,
                       la.range_km, sample.time, sample.time.astimezone(local_zone), subpoint)


Formatter = Callable[[DialectView | None], str]  #: None: no satellite selected or no position


@dataclass(frozen=True)
class Dialect:
    """A tracker's DDE names and string formats: ``format`` for every item unless ``item_formats`` names it."""

    name: str
    service: str
    topic: str
    items: tuple[str, ...]
    format: Formatter
    item_formats: tuple[tuple[str, Formatter], ...] = ()

    def formatter(self, item: str) -> Formatter:
        """The formatter for ``item`` (compared without regard to case, as DDEML does)."""
        for name, fmt in self.item_formats:
            if name.upper() == item.upper():
                return fmt
        return self.format
