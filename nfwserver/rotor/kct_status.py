"""The KCT driver's status byte (function 0)."""

from __future__ import annotations

import enum
from dataclasses import dataclass


class KctStatusBit(enum.IntFlag):
    """Bits of the status byte (function 0)."""

    CARD_ABSENT = 0x80  #: interface card absent or not answering
    DISABLED = 0x40  #: controller disabled (movements stopped)
    EL_STALLED = 0x20  #: elevation rotor stalled and disabled
    AZ_STALLED = 0x10  #: azimuth rotor stalled and disabled
    EL_MOVING = 0x08  #: elevation rotor moving or needs moving
    EL_INCREASING = 0x04  #: elevation moving towards larger angles (else smaller)
    AZ_MOVING = 0x02  #: azimuth rotor moving or needs moving
    AZ_INCREASING = 0x01  #: azimuth moving towards larger angles (else smaller)


@dataclass(frozen=True)
class DriverStatus:
    """What function 0 returns that the station shows."""

    bits: KctStatusBit
