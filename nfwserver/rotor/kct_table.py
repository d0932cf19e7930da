"""The KCT driver's 23-byte time/target table records, byte for byte.

Normal mode (little-endian words, as on the PC):

====== ====== ==========================================================
offset size   field
====== ====== ==========================================================
0      word   year (e.g. 1987)
2      byte   month 1-12
3      byte   day 1-31
4      byte   hour 0-23 UTC; OR 0x80 marks the first entry of a pass
5      byte   minute 0-59 UTC; OR 0x80 marks the last entry of a pass
6      byte   second 0-59 UTC
7      word   target elevation, signed, -90..269
9      word   target azimuth 0..359
11     8      satellite identifier, ASCII
19     dword  Doppler-shifted beacon frequency, Hz (least significant byte first)
====== ====== ==========================================================

Repetitive mode: word 0xFFFF, word starting minute within the cycle, word azimuth 0..359,
10 bytes ASCII segment description, 7 unused bytes.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from datetime import datetime, timezone

ENTRY_SIZE = 23
_NORMAL = struct.Struct("<HBBBBBhH8sI")
_REPEAT = struct.Struct("<HHH10s7s")
FIRST_OF_PASS = 0x80
LAST_OF_PASS = 0x80
REPEAT_MARK = 0xFFFF
MAX_CYCLE_MINUTES = 10_080


class TableEntryError(ValueError):
    """A record that the driver would refuse (status code 1)."""


def _ascii(text: str, size: int) -> bytes:
    raw = text.encode("ascii", errors="replace")[:size]
    return raw.ljust(size, b" ")


@dataclass(frozen=True)
class NormalEntry:
    """A time-tagged target of normal table processing."""

    time: datetime  #: aware UTC, whole seconds
    elevation_deg: int  #: -90..269
    azimuth_deg: int  #: 0..359
    satellite_id: str  #: up to 8 ASCII characters
    beacon_hz: int = 0  #: Doppler-shifted beacon frequency, 0..2^32-1
    first_of_pass: bool = False
    last_of_pass: bool = False

    def validate(self) -> None:
        if not -90 <= self.elevation_deg <= 269 or not 0 <= self.azimuth_deg <= 359:
            raise TableEntryError("target elevation must be -90..269 and azimuth 0..359")
        if not 0 <= self.beacon_hz < 2**32:
            raise TableEntryError("beacon frequency does not fit 32 bits")
        if not 0 < self.time.year < 65536:
            raise TableEntryError("year out of range")

    def encode(self) -> bytes:
        self.validate()
        t = self.time.astimezone(timezone.utc)
        return _NORMAL.pack(t.year, t.month, t.day, t.hour | (FIRST_OF_PASS if self.first_of_pass else 0),
                            t.minute | (LAST_OF_PASS if self.last_of_pass else 0), t.second,
                            self.elevation_deg, self.azimuth_deg, _ascii(self.satellite_id, 8), self.beacon_hz)


@dataclass(frozen=True)
class RepetitiveEntry:
    """A segment of repetitive table processing: from ``start_minute`` of the cycle, point at ``azimuth_deg``."""

    start_minute: int
    azimuth_deg: int
    description: str = ""

    def validate(self) -> None:
        if not 0 <= self.start_minute < MAX_CYCLE_MINUTES or not 0 <= self.azimuth_deg <= 359:
            raise TableEntryError("start minute must be 0..10079 and azimuth 0..359")

    def encode(self) -> bytes:
        self.validate()
        return _REPEAT.pack(REPEAT_MARK, self.start_minute, self.azimuth_deg, _ascii(self.description, 10),
                            b"\x00" * 7)


def decode_entry(data: bytes) -> NormalEntry | RepetitiveEntry:
    """Decode one 23-byte record; raises :class:`TableEntryError` for a malformed one."""
    if len(data) != ENTRY_SIZE:
        raise TableEntryError(f"a table record has {ENTRY_SIZE} bytes, got {len(data)}")
    if data[0:2] == b"\xff\xff":
        _, minute, azimuth, text, _ = _REPEAT.unpack(data)
        description = text.decode("ascii", "replace").rstrip()
        entry: NormalEntry | RepetitiveEntry = RepetitiveEntry(minute, azimuth, description)
    else:
        year, month, day, hour, minute, second, el, az, ident, beacon = _NORMAL.unpack(data)
        try:
            when = datetime(year, month, day, hour & 0x7F, minute & 0x7F, second, tzinfo=timezone.utc)
        except ValueError as exc:
            raise TableEntryError(f"invalid date or time in record ({exc})") from None
        entry = NormalEntry(when, el, az, ident.decode("ascii", "replace").rstrip(), beacon,
                            bool(hour & FIRST_OF_PASS), bool(minute & LAST_OF_PASS))
    entry.validate()
    return entry
