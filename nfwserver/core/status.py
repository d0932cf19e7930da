"""The tracker's status word, in the manner of OrbitDRV's function calls.

OrbitDRV returned a 16-bit status word with every call; the same bits describe our tracker's
state, so the console and clients that want it can read one number.  ``INTERFACE_VERSION`` is the
interface version OrbitDRV reported alongside (1).
"""

from __future__ import annotations

import enum

INTERFACE_VERSION = 1


class StatusBit(enum.IntFlag):
    """Bits of the status word."""

    STATION_MISSING = 0x0001  #: station (observer) elements missing or bad
    SATELLITE_MISSING = 0x0002  #: satellite elements missing or bad (no satellite selected)
    TRACKING_DISABLED = 0x0004  #: TRACK OFF (the default)
    TUNING_DISABLED = 0x0008  #: OrbitDRV's "tuning disabled": no Doppler updates to the radio (not Nova's TUNE OFF)
    ARITHMETIC_ERROR = 0x0010  #: the last computation failed; the code is in ``error_code``
    NOT_IN_VIEW = 0x0020  #: the satellite is below the horizon table (valid while tracking)
    NOT_RECOMPUTED = 0x0040  #: no position computed since the last parameter change
    BAD_FUNCTION = 0x4000  #: the last command was not understood
    BAD_SUBFUNCTION = 0x8000  #: the last command had a bad argument


class ArithmeticErrorCode(enum.IntEnum):
    """Error codes reported with ARITHMETIC_ERROR (OrbitDRV's codes where one fits)."""

    NONE = 0x00
    DOMAIN = 0x01  #: argument domain error
    OVERFLOW = 0x03  #: overflow range error
    DEGENERATE_ORBIT = 0x41  #: SGP4 could not propagate (decayed or degenerate orbit)
    NEGATIVE_TIME = 0x42


def describe(word: int) -> list[str]:
    """Names of the bits set in ``word``, for display."""
    return [bit.name.lower().replace("_", " ") for bit in StatusBit if word & bit and bit.name]
