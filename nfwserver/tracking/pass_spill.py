"""A catalog search's passes kept in a temporary file, read back in order a slab at a time.

A whole catalog over a week has ~650,000 passes: 36 MB of :class:`~nfwserver.tracking.pass_records.PassList`
columns, and sorting them needs the sort's keys and order and a column's copy beside them.  Writing them out
(CSV, JSON) needs only a few thousand rows at a time, in order, so :class:`SpilledPasses` appends each part the
search finds to a temporary file (row by row, 56 bytes a row) and keeps in memory only what orders the rows
(the time of the pass's first event and its catalog number: 16 bytes a row).
:meth:`SpilledPasses.sort_into_slabs` then copies the rows to a second file slab after slab, from which each slab
of the passes, sorted as a :class:`PassList` would hold them, is read in one piece by whichever process makes
its text.  The rows are those of the in-memory list, bit for bit and in the same order
(the same keys, the same stable sort of the rows in the order they were found).

Times are seconds after ``start`` (NaN when unknown), angles degrees, as in the PassList columns.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Iterator, Sequence
from datetime import datetime
from typing import IO

import numpy as np

from nfwserver.tracking.pass_records import COLUMNS, PassList, distinct, mapped

#: One pass as a record of the temporary file.
ROW = np.dtype(list(COLUMNS))
#: Rows read from a file at a time while sorting them into slabs (1.8 MiB).
_READ_ROWS = 1 << 15


class SpilledPasses:
    """Passes after ``start`` in a ``window_s`` window, appended part by part to temporary files (one per
    process that searched), sorted when read (:meth:`slabs`).  ``skipped`` as in :class:`PassList`."""

    def __init__(self, start: datetime, window_s: float, spill: IO[bytes] | None = None) -> None:
        self.start, self.window_s = start, float(window_s)
        self.skipped: tuple[int, ...] = ()
        self._files: list[tuple[IO[bytes], int]] = []  #: (file, rows) in the order of their rows
        self._file: IO[bytes] | None = spill
        self._rows = 0  #: rows in ``_file``
        self._first = _Growing(np.float64)  #: per row: AOS, or TCA when AOS is unknown (s)
        self._numbers = _Growing(np.int32)  #: per row: catalog number (at most 9 digits)
        self._up: list[np.ndarray] = []  #: per part: its rows with neither AOS nor LOS known (rows of its file)
        self._up_el: list[np.ndarray] = []  #: per part: those rows' maximum elevations (deg)

    def __len__(self) -> int:
        return sum(count for _, count in self._files) + self._rows

    def add(self, part: dict[str, np.ndarray]) -> None:
        """Append the rows of ``part`` (PassList columns, all of one length; an empty dict adds nothing)."""
        k = len(part["tca_s"]) if part else 0
        if not k:
            return
        if self._file is None:
            self._file = tempfile.TemporaryFile()  # noqa: SIM115 (kept until close(), which closes it)
        rows = np.empty(k, dtype=ROW)
        for name, _ in COLUMNS:
            rows[name] = part[name]
        self._file.write(rows.tobytes())
        self._rows += k
        aos_unknown = np.isnan(rows["aos_s"])
        self._first.add(np.where(aos_unknown, rows["tca_s"], rows["aos_s"]))
        self._numbers.add(rows["catalog_number"])
        up = aos_unknown & np.isnan(rows["los_s"])
        self._up.append(np.flatnonzero(up) + (self._rows - k))
        self._up_el.append(rows["max_elevation_deg"][up])

    def seal(self, skipped: Sequence[int] = ()) -> SpilledPasses:
        """The last part is added: the file is kept for reading, with the satellites the search left out."""
        if self._file is not None:
            self._file.flush()
            self._files.append((self._file, self._rows))
        self._file, self._rows = None, 0
        self.skipped = tuple(sorted((*self.skipped, *skipped)))
        self._join()
        return self

    def _join(self) -> None:
        """The always-up rows' parts joined."""
        self._up, self._up_el = [_joined(self._up, np.intp)], [_joined(self._up_el, np.float64)]

    def keys(self) -> tuple[np.ndarray, ...]:
        """What a forked worker hands back (the file stays with the parent, which made it): first times,
        catalog numbers, the rows with neither AOS nor LOS and their maximum elevations."""
        return (self._first.values(), self._numbers.values(), _joined(self._up, np.intp),
                _joined(self._up_el, np.float64))

    @classmethod
    def joined(cls, start: datetime, window_s: float, files: Sequence[IO[bytes]],
               parts: Sequence[tuple[tuple[np.ndarray, ...], Sequence[int]]]) -> SpilledPasses:
        """The passes of several workers, each of which wrote its rows to one of ``files`` and handed back its
        :meth:`keys` and skipped satellites (``parts``), in the order of ``files``."""
        joined = cls(start, window_s)
        skipped: list[int] = []
        at = 0  # rows of the files before this one
        for spill, ((first, numbers, up, up_el), left_out) in zip(files, parts):
            joined._files.append((spill, len(first)))
            joined._first.add(first)
            joined._numbers.add(numbers)
            joined._up.append(up + at)
            joined._up_el.append(up_el)
            skipped += left_out
            at += len(first)
        joined.skipped = tuple(sorted(skipped))
        joined._join()
        return joined

    def close(self) -> None:
        """Delete the temporary files."""
        for spill, _ in self._files:
            spill.close()
        self._files = []

    def catalog_numbers(self) -> list[int]:
        """The catalog numbers that have passes, ascending, each once."""
        numbers: list[int] = distinct(self._numbers.values()).tolist()
        return numbers

    def always_up(self, min_el: float = 0.0) -> list[int]:
        """Catalog numbers of the passes with neither AOS nor LOS (reaching ``min_el`` deg, unless 0), in the
        order of the sorted passes."""
        up, up_el = _joined(self._up, np.intp), _joined(self._up_el, np.float64)
        if min_el != 0.0:
            up = up[up_el >= min_el]
        numbers, first = self._numbers.values()[up], self._first.values()[up]
        # The sorted passes' order restricted to these rows: the same keys, ties in the order of the rows.
        shown: list[int] = numbers[np.lexsort((numbers, first))].tolist()
        return shown

    def sort_into_slabs(self, rows: int = 1 << 16) -> SortedSlabs:
        """The passes sorted by AOS (TCA when unknown), then catalog number, in a temporary file from which any
        slab of ``rows`` can be read (:meth:`SortedSlabs.slab`, also by a process forked after this call).  Once
        only: the keys are freed."""
        # PassColumns.pass_list's sort of the same rows in the same order (ties in the order the rows were found)
        order = np.lexsort((self._numbers.values(), self._first.values()))
        self._first, self._numbers = _Growing(np.float64), _Growing(np.int32)  # unmapped
        n = len(order)
        rank = np.empty(n, dtype=np.int32 if n < 2**31 else np.int64)  # each row's place in the sorted passes
        rank[order] = np.arange(n, dtype=rank.dtype)
        del order
        slabs = tempfile.TemporaryFile()  # noqa: SIM115 (closed by SortedSlabs.close)
        try:  # the rows again, slab after slab (in each, in the files' order)
            self._by_slab(rank, rows, slabs)
            slabs.flush()
        except BaseException:
            slabs.close()
            raise
        # The sorted places of the rows as they lie in that file: a slab's rows are there in the files' order.
        places = rank[np.argsort(rank // rows, kind="stable")]
        return SortedSlabs(self, places, rows, slabs)

    def _by_slab(self, rank: np.ndarray, rows: int, out: IO[bytes]) -> None:
        """Copy the files' rows to ``out`` grouped by slab (``rank // rows``), each slab's rows in the files'
        order: one sequential read of the files, and the slabs are then read one after the other."""
        written = np.arange(0, len(rank), rows, dtype=np.int64)  # where each slab's next row goes in ``out``
        at = 0  # rows of the files before the one read
        for spill, count in self._files:
            spill.seek(0)
            for b0 in range(0, count, _READ_ROWS):
                block = np.frombuffer(spill.read(min(_READ_ROWS, count - b0) * ROW.itemsize), dtype=ROW)
                which = rank[at + b0 : at + b0 + len(block)] // rows
                grouped = block[np.argsort(which, kind="stable")]
                bounds = np.searchsorted(np.sort(which), np.arange(len(written) + 1))
                for s, (lo, hi) in enumerate(zip(bounds[:-1].tolist(), bounds[1:].tolist())):
                    if hi > lo:
                        out.seek(int(written[s]) * ROW.itemsize)
                        out.write(grouped[lo:hi].tobytes())
                        written[s] += hi - lo
            at += count


class SortedSlabs:
    """Sorted passes (:meth:`SpilledPasses.sort_into_slabs`) ``rows`` at a time; a context manager that deletes
    its temporary file at its end.  ``places``: each row of the file's place in the sorted passes."""

    def __init__(self, passes: SpilledPasses, places: np.ndarray, rows: int, file: IO[bytes]) -> None:
        self.start, self.window_s, self.skipped = passes.start, passes.window_s, passes.skipped
        self.rows, self._places, self._file = rows, places, file

    def __len__(self) -> int:
        return -(-len(self._places) // self.rows)

    def __iter__(self) -> Iterator[PassList]:
        return (self.slab(k) for k in range(len(self)))

    def __enter__(self) -> SortedSlabs:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Delete the temporary file."""
        self._file.close()

    def slab(self, k: int) -> PassList:
        """Slab ``k`` (from 0): the sorted passes ``k * rows`` to ``(k + 1) * rows``, the last slab maybe shorter.
        Read at its place in the file (``pread``), so processes sharing the file's position do not disturb
        each other."""
        s0 = k * self.rows
        s1 = min(s0 + self.rows, len(self._places))
        if not 0 <= s0 < s1:
            raise IndexError(k)
        block = np.frombuffer(_read_at(self._file, (s1 - s0) * ROW.itemsize, s0 * ROW.itemsize), dtype=ROW)
        places = self._places[s0:s1] - s0
        slab = {name: np.empty(s1 - s0, dtype=dtype) for name, dtype in COLUMNS}
        for name, _ in COLUMNS:
            slab[name][places] = block[name]
        return PassList(self.start, self.window_s, slab, sort=False, skipped=self.skipped)


def _read_at(file: IO[bytes], size: int, offset: int) -> bytes:
    """``size`` bytes of ``file`` from ``offset``, its position left alone where the system allows (POSIX)."""
    if sys.platform == "win32":  # no pread there (and no forked process to share the position with)
        file.seek(offset)
        return file.read(size)
    return os.pread(file.fileno(), size, offset)


class _Growing:
    """A key column appended to part by part, in anonymous memory maps (grown by doubling: pages never written
    cost nothing, and the map is given back to the system when replaced, whatever the C heap holds)."""

    def __init__(self, dtype: type, capacity: int = 1 << 20) -> None:
        self._values, self._n = mapped(capacity, dtype), 0

    def add(self, part: np.ndarray) -> None:
        n, k = self._n, len(part)
        if n + k > len(self._values):
            grown = mapped(max(2 * len(self._values), n + k), self._values.dtype.type)
            grown[:n] = self._values[:n]
            self._values = grown
        self._values[n : n + k] = part
        self._n = n + k

    def values(self) -> np.ndarray:
        return self._values[: self._n]


def _joined(parts: list[np.ndarray], dtype: type) -> np.ndarray:
    """``parts`` end to end (an empty array of ``dtype`` for none)."""
    return parts[0] if len(parts) == 1 else np.concatenate(parts) if parts else np.empty(0, dtype=dtype)
