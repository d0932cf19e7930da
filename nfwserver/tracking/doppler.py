"""Doppler shift from range rate.

Range rate ``rr`` is in km/s, positive when the satellite recedes from the observer (the sign
convention of Nova's ``RR:`` field).  Frequencies are in Hz.  The first-order (non-relativistic)
formulas are used, as every amateur tracking program does; the second-order term is below
1e-10 relative for satellites (|rr| < 10 km/s).

- Received at the ground (downlink): ``f_rx = f * (1 - rr / c)``.
- Sent from the ground so that the satellite hears ``f`` (uplink): ``f_tx = f * (1 + rr / c)``.
"""

from __future__ import annotations

from nfwserver.tracking.constants import SPEED_OF_LIGHT_KM_S

__all__ = ["SPEED_OF_LIGHT_KM_S", "doppler_shift_hz", "downlink_frequency_hz", "uplink_frequency_hz"]


def doppler_shift_hz(frequency_hz: float, range_rate_km_s: float) -> float:
    """Shift (Hz) of a signal of ``frequency_hz`` sent by the satellite, as received on the ground.

    Equals Nova's ``DopplerHz = -FreqHz * RR / c``.
    """
    return -frequency_hz * range_rate_km_s / SPEED_OF_LIGHT_KM_S


def downlink_frequency_hz(frequency_hz: float, range_rate_km_s: float) -> float:
    """Frequency (Hz) heard on the ground when the satellite transmits ``frequency_hz``."""
    return frequency_hz * (1.0 - range_rate_km_s / SPEED_OF_LIGHT_KM_S)


def uplink_frequency_hz(frequency_hz: float, range_rate_km_s: float) -> float:
    """Frequency (Hz) to transmit on the ground so that the satellite receives ``frequency_hz``."""
    return frequency_hz * (1.0 + range_rate_km_s / SPEED_OF_LIGHT_KM_S)
