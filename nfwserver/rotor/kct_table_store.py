"""The KCT driver's time/target table: its two modes, the table calls, and what is in force.

Service calls served here (numbers from the KCT document):

- 05h clear; 07h add (0 ok, 1 invalid, 2 full); 0Ch set the mode (clears the table);
  13h delete the rest of the pass.
- 06h read: "CX contains the maximum number of table records to be returned / DX contains the
  relative table-record number of the first table entry to be returned.  The first entry of the
  table has a relative table-record number of zero.  If the relative table-record number is out of
  range the returned-entry count in CX will be zero."  At exit "AL contains the driver's current
  table mode", "CX contains the number of table entries returned", and "DX if the driver is in
  BBSROTOR mode, DX contains the relative table entry# of the Time/Target table currently in force";
  the records are copied to ES:[BX] as their 23-byte images.  :class:`TableRead` holds exactly that.
  BBSROTOR mode is the repetitive-table-processing mode (the mode the BBS rotor program used); in
  normal mode ``in_force`` is None, as DX is undefined there.
- 0Dh count: "This function returns the number of time-target table entries defined within the
  driver.  At Exit: AX contains the number of table entries defined within the driver".
  **Decision**: the number of entries currently in the table, not its capacity.  An entry is
  *defined* by an Add call (07h) and undefined again by Clear (05h), expiry or Delete rest of pass
  (13h); the document never speaks of defining room for entries, and the count is what a program
  needs to page through the table with 06h (whose own out-of-range rule implies the caller may not
  know it).  A full table is reported by 07h's code 2, so a program never needs the capacity.
- Repetitive mode: the segment in force is the last one whose starting minute has been reached in
  the current cycle; before the first segment's start, the cycle's last segment (still in force from
  the previous cycle, the table being cyclic).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from datetime import datetime

from nfwserver.rotor.kct_table import (
    MAX_CYCLE_MINUTES,
    NormalEntry,
    RepetitiveEntry,
    TableEntryError,
    decode_entry,
)

ADD_OK, ADD_INVALID, ADD_FULL = 0, 1, 2

Entry = NormalEntry | RepetitiveEntry


class TableMode(enum.IntEnum):
    NORMAL = 0
    REPETITIVE = 1  #: repetitive-table-processing ("BBSROTOR") mode


@dataclass(frozen=True)
class TableRead:
    """What function 06h returns."""

    mode: TableMode  #: AL
    in_force: int | None  #: DX: relative number of the entry in force (repetitive mode only)
    images: tuple[bytes, ...]  #: the records copied to ES:[BX], 23 bytes each

    @property
    def count(self) -> int:
        """CX: the number of records returned."""
        return len(self.images)

    @property
    def data(self) -> bytes:
        """The bytes written at ES:[BX]."""
        return b"".join(self.images)

    def entries(self) -> list[Entry]:
        return [decode_entry(image) for image in self.images]


class TimeTargetTable:
    """The table and its mode; ``capacity`` is how many entries it holds (07h answers 2 beyond)."""

    def __init__(self, capacity: int = 1000) -> None:
        self.capacity = capacity
        self.mode = TableMode.NORMAL
        self.cycle_minutes = 0
        self.cycle_start: datetime | None = None
        self.entries: list[Entry] = []

    def __len__(self) -> int:
        """Function 0Dh (see the module docstring)."""
        return len(self.entries)

    def clear(self) -> None:
        """Function 05h."""
        self.entries.clear()

    def add(self, entry: Entry | bytes) -> int:
        """Function 07h: ADD_OK, ADD_INVALID (bad record or the other mode's format) or ADD_FULL."""
        try:
            if isinstance(entry, bytes | bytearray):
                entry = decode_entry(bytes(entry))
            entry.validate()
        except TableEntryError:
            return ADD_INVALID
        if isinstance(entry, RepetitiveEntry) != (self.mode is TableMode.REPETITIVE):
            return ADD_INVALID
        if len(self.entries) >= self.capacity:
            return ADD_FULL
        self.entries.append(entry)
        if isinstance(entry, NormalEntry):
            # every entry has the table's one kind (checked above): here all are NormalEntry
            self.entries.sort(key=lambda e: e.time)  # type: ignore[union-attr]
        else:
            self.entries.sort(key=lambda e: e.start_minute)  # type: ignore[union-attr]  # all RepetitiveEntry
        return ADD_OK

    def set_mode(self, mode: TableMode, cycle_minutes: int, now: datetime) -> bool:
        """Function 0Ch: normal, or repetitive with a cycle of 1..10080 minutes; clears the table."""
        if mode is TableMode.REPETITIVE and not 1 <= cycle_minutes <= MAX_CYCLE_MINUTES:
            return False
        self.mode = mode
        self.cycle_minutes = cycle_minutes if mode is TableMode.REPETITIVE else 0
        self.cycle_start = now if mode is TableMode.REPETITIVE else None
        self.entries.clear()
        return True

    def cycle_minute(self, now: datetime) -> int:
        """The current minute within the repetitive cycle (0 outside repetitive mode)."""
        if self.cycle_start is None or self.cycle_minutes <= 0:
            return 0
        return int((now - self.cycle_start).total_seconds() / 60.0) % self.cycle_minutes

    def in_force(self, now: datetime) -> int | None:
        """Relative number of the repetitive segment in force; None in normal mode or when empty."""
        if self.mode is not TableMode.REPETITIVE or not self.entries:
            return None
        minute = self.cycle_minute(now)
        started = [i for i, e in enumerate(self.entries) if isinstance(e, RepetitiveEntry) and e.start_minute <= minute]
        return started[-1] if started else len(self.entries) - 1

    def read(self, first: int, count: int, now: datetime) -> TableRead:
        """Function 06h: up to ``count`` records from relative record ``first``."""
        chosen: list[Entry] = []
        if 0 <= first < len(self.entries) and count > 0:
            chosen = self.entries[first : first + count]
        return TableRead(self.mode, self.in_force(now), tuple(e.encode() for e in chosen))

    def pop_due(self, now: datetime) -> list[NormalEntry]:
        """Normal mode: remove and return, oldest first, the entries whose time has come."""
        due: list[NormalEntry] = []
        while self.entries and isinstance(self.entries[0], NormalEntry) and self.entries[0].time <= now:
            entry = self.entries.pop(0)
            assert isinstance(entry, NormalEntry)
            due.append(entry)
        return due

    def delete_rest_of_pass(self) -> None:
        """Function 13h: drop entries up to and including the end of the current pass.

        "If the first entry in the table is a start-of-pass record the entire pass is deleted."
        """
        if not self.entries or self.mode is not TableMode.NORMAL:
            return
        cut = len(self.entries)
        for i, entry in enumerate(self.entries):
            assert isinstance(entry, NormalEntry)
            if i > 0 and entry.first_of_pass:  # the next pass starts here: keep it
                cut = i
                break
            if entry.last_of_pass:
                cut = i + 1
                break
        del self.entries[:cut]
