"""Pass records: one :class:`Pass` per pass, and :class:`PassList`, a catalog's passes kept compact.

A catalog search finds tens of thousands of passes; as Python objects with three datetimes each
they would take ~440 bytes apiece (20 MiB for 8,000 satellites over a day).  :class:`PassList`
keeps them column-wise in numpy arrays (56 bytes a pass) and builds a :class:`Pass` only when one
is read (indexing, slicing, iteration).  It is a read-only ``Sequence``: ``len``, ``[i]``,
``[a:b]``, ``for``, ``sorted``, ``max(..., key=...)`` all work as with a list of passes.

Times are aware UTC datetimes on the records and float seconds after the list's ``start`` (NaN
for unknown) in the columns; angles degrees.
"""

from __future__ import annotations

import mmap
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta
from typing import overload

import numpy as np

#: Passes materialised at a time while iterating (bounds the temporary Python objects).
_BLOCK = 1024


@dataclass(frozen=True, slots=True)
class Pass:
    """One pass of one satellite over the horizon table."""

    catalog_number: int
    aos: datetime | None  #: rise above the horizon table (None: earlier than the search reached)
    tca: datetime  #: maximum elevation
    los: datetime | None  #: set below the horizon table (None: later than the search reached)
    max_elevation_deg: float
    aos_azimuth_deg: float | None
    los_azimuth_deg: float | None
    aos_before_start: bool = False  #: the pass was in progress at the window start
    los_after_end: bool = False  #: the pass is still in progress at the window end

    @property
    def duration_s(self) -> float | None:
        """LOS - AOS in seconds, when both are known."""
        if self.aos is None or self.los is None:
            return None
        return (self.los - self.aos).total_seconds()


#: Column names and dtypes of a :class:`PassList`; times in s after ``start``, NaN when unknown.
COLUMNS = (("catalog_number", np.int64), ("aos_s", np.float64), ("tca_s", np.float64), ("los_s", np.float64),
           ("max_elevation_deg", np.float64), ("aos_azimuth_deg", np.float64), ("los_azimuth_deg", np.float64))


class PassList(Sequence[Pass]):
    """Passes sorted by AOS (TCA when AOS is unknown), then catalog number, stored column-wise.

    ``window_s`` is the length of the searched window: a pass whose AOS is unknown or before 0
    has ``aos_before_start``, one whose LOS is unknown or after ``window_s`` has ``los_after_end``.
    ``skipped`` are the catalog numbers of the satellites the search left out because their positions at
    the window start cannot be computed or are implausibly far (:mod:`~nfwserver.tracking.screening`),
    ascending.
    """

    __slots__ = ("start", "window_s", "columns", "skipped")

    def __init__(self, start: datetime, window_s: float, columns: dict[str, np.ndarray] | None = None,
                 sort: bool = True, skipped: Sequence[int] = ()) -> None:
        self.start = start
        self.window_s = float(window_s)
        self.skipped: tuple[int, ...] = tuple(sorted(skipped))
        cols = {name: np.asarray((columns or {}).get(name, np.empty(0)), dtype=dt) for name, dt in COLUMNS}
        if sort and len(cols["tca_s"]):
            first = np.where(np.isnan(cols["aos_s"]), cols["tca_s"], cols["aos_s"])
            order = np.lexsort((cols["catalog_number"], first))
            cols = {name: col[order] for name, col in cols.items()}
        self.columns = cols

    @classmethod
    def concat(cls, start: datetime, window_s: float, parts: Sequence[PassList | dict[str, np.ndarray]]) -> PassList:
        """One sorted list from several lists or column dicts, all with times after ``start``.

        Column by column, emptying ``parts`` as it goes, so that the peak memory stays near one
        copy of the result.
        """
        skipped = [n for p in parts if isinstance(p, PassList) for n in p.skipped]
        cols = [p.columns if isinstance(p, PassList) else p for p in parts if len(p)]
        if not cols:
            return cls(start, window_s, skipped=skipped)
        first = np.concatenate([np.where(np.isnan(c["aos_s"]), c["tca_s"], c["aos_s"]) for c in cols])
        order = np.lexsort((np.concatenate([c["catalog_number"] for c in cols]), first))
        del first
        merged = {}
        for name, _ in COLUMNS:
            merged[name] = np.concatenate([c.pop(name) for c in cols])[order]
        return cls(start, window_s, merged, sort=False, skipped=skipped)

    def __len__(self) -> int:
        return len(self.columns["tca_s"])

    def catalog_numbers(self) -> list[int]:
        """The catalog numbers that have passes, ascending, each once."""
        numbers: list[int] = distinct(self.columns["catalog_number"]).tolist()
        return numbers

    def _make(self, rows: np.ndarray) -> list[Pass]:
        cols = [self.columns[name][rows].tolist() for name, _ in COLUMNS]
        start, window = self.start, self.window_s
        out = []
        for cat, aos, tca, los, el, aos_az, los_az in zip(*cols):
            aos_known, los_known = aos == aos, los == los  # False for NaN
            out.append(Pass(
                catalog_number=cat,
                aos=start + timedelta(seconds=aos) if aos_known else None,
                tca=start + timedelta(seconds=tca),
                los=start + timedelta(seconds=los) if los_known else None,
                max_elevation_deg=el,
                aos_azimuth_deg=aos_az if aos_known else None,
                los_azimuth_deg=los_az if los_known else None,
                aos_before_start=not aos_known or aos < 0.0,
                los_after_end=not los_known or los > window,
            ))
        return out

    @overload
    def __getitem__(self, index: int) -> Pass: ...

    @overload
    def __getitem__(self, index: slice) -> list[Pass]: ...

    def __getitem__(self, index: int | slice) -> Pass | list[Pass]:
        if isinstance(index, slice):
            return self._make(np.arange(len(self))[index])
        n = len(self)
        if not -n <= index < n:
            raise IndexError("pass index out of range")
        return self._make(np.array([index % n]))[0]

    def __iter__(self) -> Iterator[Pass]:
        for b0 in range(0, len(self), _BLOCK):
            yield from self._make(np.arange(b0, min(b0 + _BLOCK, len(self))))

    def __repr__(self) -> str:
        return f"PassList({len(self)} passes from {self.start.isoformat()})"


class PassColumns:
    """Pass columns gathered part by part (unsorted), then sorted once into a :class:`PassList`.

    The columns are allocated at ``capacity`` rows up front (grown by doubling if a search finds more):
    pages never written cost no memory, and sorting needs one column's copy at a time, where joining
    many parts at the end would hold every part beside a second copy of the whole.  The initial capacity
    stays under 4 MiB a column, the size from which numpy asks for huge pages (committed 2 MiB at a time).
    """

    _MAX_INITIAL = (1 << 22) // 8 - 1

    def __init__(self, capacity: int) -> None:
        self._capacity = int(min(max(capacity, 1024), self._MAX_INITIAL))
        self._rows = 0
        self._columns: dict[str, np.ndarray] = {}

    def __len__(self) -> int:
        return self._rows

    def add(self, part: dict[str, np.ndarray]) -> None:
        """Append the rows of ``part`` (PassList columns, all of one length; an empty dict adds nothing)."""
        k = len(part["tca_s"]) if part else 0
        if not k:
            return
        n = self._rows
        if not self._columns or n + k > self._capacity:
            capacity = max(2 * self._capacity if self._columns else self._capacity, n + k)  # the first part too
            for name, dtype in COLUMNS:
                grown = mapped(capacity, dtype)
                if name in self._columns:
                    grown[:n] = self._columns[name][:n]
                self._columns[name] = grown
            self._capacity = capacity
        for name, _ in COLUMNS:
            self._columns[name][n : n + k] = part[name]
        self._rows = n + k

    def pass_list(self, start: datetime, window_s: float, skipped: Sequence[int] = ()) -> PassList:
        """The passes gathered, sorted as a :class:`PassList` (with ``skipped``); the gathered columns are
        released, one at a time."""
        n, columns = self._rows, self._columns
        self._columns, self._rows = {}, 0
        if not n:
            return PassList(start, window_s, skipped=skipped)
        first = np.where(np.isnan(columns["aos_s"][:n]), columns["tca_s"][:n], columns["aos_s"][:n])
        order = np.lexsort((columns["catalog_number"][:n], first))
        del first
        merged = {}
        for name, _ in COLUMNS:
            merged[name] = columns.pop(name)[:n][order]
        return PassList(start, window_s, merged, sort=False, skipped=skipped)


def mapped(rows: int, dtype: type) -> np.ndarray:
    """An array of ``rows`` in its own anonymous memory map: its pages take memory only once written, and it
    is unmapped (given back to the system) when the array is freed, whatever the C heap does meanwhile."""
    buffer = mmap.mmap(-1, max(rows, 1) * np.dtype(dtype).itemsize)
    return np.frombuffer(buffer, dtype=dtype)


def distinct(values: np.ndarray) -> np.ndarray:
    """The distinct values of ``values``, ascending (``np.unique``, which imports numpy.ma: 6 ms and 1.3 MiB)."""
    ordered = np.sort(values)
    first = np.ones(len(ordered), dtype=bool)
    first[1:] = ordered[1:] != ordered[:-1]
    picked: np.ndarray = ordered[first]
    return picked
