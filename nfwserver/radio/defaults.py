"""Built-in channels of popular amateur satellites (frequencies in Hz, as published by their operators).

They make Doppler tuning work before any configuration; ``[[satellites.channels]]`` entries in the
configuration add to or replace them.
"""

from __future__ import annotations

from nfwserver.channels.channel import Channel

DEFAULT_CHANNELS: dict[int, Channel] = {
    25544: Channel("ISS FM repeater", 437_800_000, 145_990_000, "FM", "FM"),
    27607: Channel("SO-50 FM", 436_795_000, 145_850_000, "FM", "FM"),
    43017: Channel("AO-91 FM", 145_960_000, 435_250_000, "FM", "FM"),
    44909: Channel("RS-44 linear", 435_640_000, 145_965_000, "USB", "LSB", inverting=True),
    7530: Channel("AO-7 mode B linear", 145_950_000, 432_150_000, "USB", "LSB", inverting=True),
}
