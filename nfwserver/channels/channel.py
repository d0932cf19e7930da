"""Satellite channels and the ground frequencies that put a signal where it belongs on the satellite.

A plain record of the station's state (the core holds it; the radio, dialects and EasyComm adapters read it).

Frequencies are Hz, range rate km/s (positive receding).  A :class:`Channel` describes one
transponder or beacon: the satellite-side downlink and uplink centre frequencies, whether the
transponder inverts (uplink up = downlink down), per-satellite corrections for the satellite's own
oscillator drift, and which side is held constant while the Doppler shift changes:

- ``"satellite"`` (full-duplex practice): the frequency *at the satellite* stays put; both the
  receive and transmit frequencies on the ground move (``f_rx = f_d (1 - rr/c)``,
  ``f_tx = f_u (1 + rr/c)``).
- ``"uplink"``: the ground transmit frequency stays put; the satellite hears it shifted, the
  transponder converts it, and the receiver follows.
- ``"downlink"``: the ground receive frequency stays put; the transmitter moves so the signal
  comes back there.

``passband_offset_hz`` moves the operating point inside a linear transponder's passband on the
downlink side; the uplink moves the other way on an inverting transponder.

A channel checks itself when built and raises :class:`ValueError` with one clear sentence: frequencies
finite and within 100 kHz..300 GHz, corrections finite and within ±1 MHz, the passband offset finite,
modes among Hamlib's names (:mod:`nfwserver.channels.modes`; stored upper-case).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from nfwserver.channels.modes import check_mode
from nfwserver.tracking.doppler import downlink_frequency_hz, uplink_frequency_hz

HOLD_SIDES = ("satellite", "uplink", "downlink")
#: Frequencies accepted for a channel (Hz): 100 kHz to 300 GHz.
MIN_FREQUENCY_HZ, MAX_FREQUENCY_HZ = 1e5, 3e11
#: Largest oscillator correction accepted (Hz): satellites drift by kHz, never by MHz.
MAX_CORRECTION_HZ = 1e6


@dataclass(frozen=True)
class Channel:
    """One transponder or beacon of a satellite."""

    name: str
    downlink_hz: float
    uplink_hz: float | None = None  #: None for a beacon or a receive-only channel
    downlink_mode: str = "FM"
    uplink_mode: str = "FM"
    inverting: bool = False
    hold: str = "satellite"  #: which side is constant: "satellite", "uplink" or "downlink"
    downlink_correction_hz: float = 0.0  #: satellite oscillator error on the downlink
    uplink_correction_hz: float = 0.0
    passband_offset_hz: float = 0.0

    def __post_init__(self) -> None:
        for name in ("downlink_hz", "uplink_hz"):
            value = getattr(self, name)
            if value is not None and (not math.isfinite(value) or not MIN_FREQUENCY_HZ <= value <= MAX_FREQUENCY_HZ):
                raise ValueError(f"channel {self.name!r}: {name} {value} is outside 100 kHz..300 GHz")
        if self.hold not in HOLD_SIDES:
            raise ValueError(f"channel {self.name!r}: hold must be one of {', '.join(HOLD_SIDES)}")
        for name in ("downlink_correction_hz", "uplink_correction_hz"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not abs(value) <= MAX_CORRECTION_HZ:
                raise ValueError(f"channel {self.name!r}: {name} {value} is not a number within "
                                 f"±{MAX_CORRECTION_HZ:.0f} Hz")
        if not isinstance(self.passband_offset_hz, (int, float)) or not math.isfinite(self.passband_offset_hz):
            raise ValueError(f"channel {self.name!r}: passband_offset_hz {self.passband_offset_hz} is not finite")
        for name in ("downlink_mode", "uplink_mode"):
            object.__setattr__(self, name, check_mode(getattr(self, name), f"channel {self.name!r}: {name}"))

    def with_offset(self, passband_offset_hz: float) -> Channel:
        return replace(self, passband_offset_hz=passband_offset_hz)

    # Satellite-side frequencies at the current operating point.
    def satellite_downlink_hz(self) -> float:
        return self.downlink_hz + self.downlink_correction_hz + self.passband_offset_hz

    def satellite_uplink_hz(self) -> float | None:
        if self.uplink_hz is None:
            return None
        sign = -1.0 if self.inverting else 1.0
        return self.uplink_hz + self.uplink_correction_hz + sign * self.passband_offset_hz

    def convert(self, uplink_at_satellite_hz: float) -> float:
        """Downlink frequency the transponder produces for a signal received at ``uplink_at_satellite_hz``."""
        assert self.uplink_hz is not None
        up0 = self.uplink_hz + self.uplink_correction_hz
        down0 = self.downlink_hz + self.downlink_correction_hz
        delta = uplink_at_satellite_hz - up0
        return down0 - delta if self.inverting else down0 + delta

    def ground_frequencies(self, range_rate_km_s: float) -> tuple[float, float | None]:
        """(receive, transmit) frequencies on the ground, Hz; transmit is None without an uplink."""
        shrink = downlink_frequency_hz(1.0, range_rate_km_s)  # downlink factor
        grow = uplink_frequency_hz(1.0, range_rate_km_s)  # uplink factor
        if self.uplink_hz is None or self.hold == "satellite":
            rx = self.satellite_downlink_hz() * shrink
            up = self.satellite_uplink_hz()
            return rx, (up * grow if up is not None else None)
        if self.hold == "uplink":
            tx = self.satellite_uplink_hz()
            assert tx is not None
            return self.convert(tx / grow) * shrink, tx
        # hold == "downlink": the receive frequency stays at the nominal downlink.
        rx = self.satellite_downlink_hz()
        at_sat_down = rx / shrink
        up0 = self.uplink_hz + self.uplink_correction_hz
        down0 = self.downlink_hz + self.downlink_correction_hz
        delta = at_sat_down - down0
        at_sat_up = up0 - delta if self.inverting else up0 + delta
        return rx, at_sat_up * grow
