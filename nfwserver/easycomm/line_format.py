"""EasyComm I lines, as Nova for Windows wrote them and as the WiSP EasyComm specification defines them.

The specification's template is ``AZaaa.a ELeee.e UPuuuuuuuuu UUU DNddddddddd DDD``: azimuth and
elevation in degrees with one decimal and *not* fixed width; uplink and downlink frequencies in Hz;
``UUU``/``DDD`` the uplink and downlink modes.  Decisions where the template leaves room:

- ``AZ``: one decimal, 0.0..359.9 (a value rounding to 360.0 is written 0.0), no padding; ``EL``:
  one decimal, a minus sign only when negative, never ``-0.0``, no padding -- the same text as the
  Nova DDE string's ``AZ:``/``EL:`` fields.
- ``uplink = "range-rate"`` (Nova's own behaviour): ``UP`` carries the range rate in km/s
  (positive receding) written exactly like the DDE string's ``RR:`` field (ten decimals);
  ``DN`` carries nine zeros (the template's width) and both modes are ``XXX``.
- ``uplink = "doppler"``: ``UP`` and ``DN`` carry the Doppler-corrected ground transmit and receive
  frequencies of the satellite's channel in whole Hz, zero-padded to the template's nine digits
  (wider, never cut, from 1 GHz up); modes are the channel's, upper case, letters and digits only,
  at most three characters (``FM``, ``USB``, ``LSB``).  A channel without an uplink, or a satellite
  without a channel, writes nine zeros and ``XXX`` for what is missing.
- Every line ends with CR LF (controllers end a command at CR, LF or a blank; CR LF suits all).
- ``SA SE`` (EasyComm II: stop azimuth, stop elevation) is written as one line.
"""

from __future__ import annotations

from nfwserver.channels.channel import Channel
from nfwserver.core.nova_protocol import format_azimuth, format_elevation, format_range_rate

LINE_END = "\r\n"
STOP_LINE = "SA SE"
NO_FREQUENCY = "000000000"
NO_MODE = "XXX"


def format_mode(mode: str | None) -> str:
    """A mode for the UUU/DDD fields: upper case, letters and digits, at most 3 characters."""
    text = "".join(ch for ch in (mode or "").upper() if ch.isascii() and ch.isalnum())[:3]
    return text or NO_MODE


def format_frequency(hz: float | None) -> str:
    """Whole Hz, at least nine digits; nine zeros when there is none."""
    if hz is None or hz <= 0:
        return NO_FREQUENCY
    return f"{round(hz):09d}"


def easycomm_line(az_deg: float, el_deg: float, up: str, up_mode: str, down: str, down_mode: str) -> str:
    """One EasyComm I line without its terminator."""
    return f"AZ{format_azimuth(az_deg)} EL{format_elevation(el_deg)} UP{up} {up_mode} DN{down} {down_mode}"


def range_rate_line(az_deg: float, el_deg: float, range_rate_km_s: float) -> str:
    """Nova's form: the range rate in UP, zeros in DN, ``XXX`` modes."""
    return easycomm_line(az_deg, el_deg, format_range_rate(range_rate_km_s), NO_MODE, NO_FREQUENCY, NO_MODE)


def doppler_line(az_deg: float, el_deg: float, range_rate_km_s: float, channel: Channel | None) -> str:
    """UP/DN: the channel's Doppler-corrected transmit/receive frequencies and modes."""
    if channel is None:
        return easycomm_line(az_deg, el_deg, NO_FREQUENCY, NO_MODE, NO_FREQUENCY, NO_MODE)
    rx_hz, tx_hz = channel.ground_frequencies(range_rate_km_s)
    up_mode = format_mode(channel.uplink_mode) if tx_hz is not None else NO_MODE
    return easycomm_line(az_deg, el_deg, format_frequency(tx_hz), up_mode, format_frequency(rx_hz),
                         format_mode(channel.downlink_mode))
