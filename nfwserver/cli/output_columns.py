"""Output columns and their cells: what :mod:`nfwserver.cli.bulk_output` writes, formatted a block at a time.

A command gives its output as columns (:class:`Text`, :class:`Integer`, :class:`Number`, :class:`Time`,
:class:`Duration`, :class:`Flag`); each makes the cells of a block of rows in a style (``table``, ``csv`` or
``json``) as a :class:`Cells` record: rows of code points in a zero-padded matrix (bytes unless a text holds
non-ASCII characters), each cell's length and start, and whether a table right-aligns it.

Every cell is the text that ``f"{value:.{decimals}f}"``, ``str(int)`` and
:func:`~nfwserver.cli.tracking_options.format_time` give (a table's numbers with the column's decimals, CSV
and JSON with at least six; JSON: times quoted, flags ``true``/``false``, ``null`` for an empty cell or a
number that is not finite).  A number whose rounding cannot be decided from its scaled double (within two
units in the last place of a tie) is formatted by Python instead.  No cell holds a NUL (names are
sanitised), so zeros mark where there is nothing.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from datetime import datetime, timedelta, timezone

import numpy as np

#: Fewest decimals of a number in CSV and JSON.
CSV_DECIMALS = 6
SPACE, _MINUS, _POINT, _ZERO = 32, 45, 46, 48
_POW10 = 10 ** np.arange(19, dtype=np.int64)
_EPOCH = datetime(1970, 1, 1, tzinfo=timezone.utc)
_DIGITS = np.frombuffer(b"0123456789", dtype=np.uint8)
#: "00".."99" and "000".."999" as rows of digit codes
_TWO = np.stack((_DIGITS.repeat(10), np.tile(_DIGITS, 10)), axis=1)
_THREE = np.stack((_DIGITS.repeat(100), np.tile(_DIGITS.repeat(10), 10), np.tile(_DIGITS, 100)), axis=1)


class Cells:
    """A block's cells of one column: code points in a zero-padded matrix (rows, width), each cell's length
    and where it starts in its row (0: left-aligned), and whether the table right-aligns it."""

    __slots__ = ("codes", "lengths", "right", "offsets")

    def __init__(self, codes: np.ndarray, lengths: np.ndarray, right: np.ndarray,
                 offsets: np.ndarray | None = None) -> None:
        self.codes, self.lengths, self.right = codes, lengths, right
        self.offsets = np.zeros(len(lengths), dtype=np.intp) if offsets is None else offsets


def codes_of(texts: Sequence[str]) -> np.ndarray:
    """Code points of ``texts`` as a zero-padded matrix (len(texts), longest): bytes when all are ASCII."""
    width = max(1, *map(len, texts)) if texts else 1
    joined = "".join(text.ljust(width, "\0") for text in texts)
    if joined.isascii():
        codes: np.ndarray = np.frombuffer(joined.encode("ascii"), dtype=np.uint8).reshape(len(texts), width)
        return np.array(codes)
    return np.frombuffer(joined.encode("utf-32-le"), dtype="<u4").reshape(len(texts), width).astype(np.uint32)


class Column:
    """A named column of ``len(self)`` cells."""

    name: str

    def __len__(self) -> int:
        raise NotImplementedError

    def cells(self, rows: slice, style: str) -> Cells:
        """The cells of ``rows`` in ``style`` (``table``, ``csv`` or ``json``)."""
        raise NotImplementedError

    def longest(self, rows: slice, style: str) -> int:
        """The length of the longest cell of ``rows`` in ``style``."""
        return int(self.cells(rows, style).lengths.max(initial=0))


class Text(Column):
    """Strings: ``values[index[row]]`` (``index`` None: one value a row).  In JSON a string (or null for
    ``""``), in CSV quoted as the ``csv`` module quotes."""

    def __init__(self, name: str, values: Sequence[str], index: np.ndarray | None = None) -> None:
        self.name, self.values = name, list(values)
        self.index = np.arange(len(self.values)) if index is None else np.asarray(index, dtype=np.intp)
        self._styles: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def __len__(self) -> int:
        return len(self.index)

    def picked(self, index: np.ndarray) -> Text:
        """The column of ``values[index[row]]``: the same strings, each styled once for both columns (a large
        output's slabs name the same satellites again and again)."""
        column = Text(self.name, (), np.asarray(index, dtype=np.intp))
        column.values, column._styles = self.values, self._styles
        return column

    def _styled(self, style: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if style not in self._styles:
            values = self.values
            if style == "csv":
                values = _csv_fields(values)
            elif style == "json":
                values = [json.dumps(v) if v else "null" for v in values]
            right = np.array([v[:1].isdigit() or v[:1] == "-" for v in values], dtype=bool)
            self._styles[style] = (codes_of(values), np.array([len(v) for v in values], dtype=np.intp), right)
        return self._styles[style]

    def cells(self, rows: slice, style: str) -> Cells:
        codes, lengths, right = self._styled(style)
        pick = self.index[rows]
        return Cells(codes[pick], lengths[pick], right[pick])

    def longest(self, rows: slice, style: str) -> int:
        return int(self._styled(style)[1][self.index[rows]].max(initial=0))


def _csv_fields(texts: list[str]) -> list[str]:
    """Each text as one field of a CSV row written by ``csv.writer`` (quoted where it must be)."""
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows([text, ""] for text in texts)
    return [line[:-1] for line in out.getvalue().split("\n")[:-1]]  # each "field," without its ","


class Integer(Column):
    """Whole numbers (``str(int)``)."""

    def __init__(self, name: str, values: np.ndarray) -> None:
        self.name, self.values = name, np.asarray(values, dtype=np.int64)

    def __len__(self) -> int:
        return len(self.values)

    def cells(self, rows: slice, style: str) -> Cells:
        values = self.values[rows]
        return _digits(np.abs(values), values < 0, np.zeros(len(values), dtype=bool), 0)


class Number(Column):
    """Numbers with ``decimals`` in a table and at least six elsewhere; ``empty`` rows have no cell."""

    def __init__(self, name: str, values: np.ndarray, decimals: int, empty: np.ndarray | None = None) -> None:
        self.name, self.values, self.decimals = name, np.asarray(values, dtype=np.float64), decimals
        self.empty = np.zeros(len(self.values), dtype=bool) if empty is None else np.asarray(empty, dtype=bool)

    def __len__(self) -> int:
        return len(self.values)

    def _values(self, rows: slice) -> np.ndarray:
        return self.values[rows]

    def _parts(self, rows: slice, style: str) -> tuple[int, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                       np.ndarray]:
        decimals = self.decimals if style == "table" else max(self.decimals, CSV_DECIMALS)
        values, empty = self._values(rows), self.empty[rows]
        if style == "json":
            empty = empty | ~np.isfinite(values)
        with np.errstate(invalid="ignore", over="ignore"):
            p = np.abs(values) * float(10**decimals)
            frac = p - np.floor(p)
            # A tie, or too close to one to tell from the rounded product, or too large: Python decides.
            python = ~empty & ~(np.isfinite(p) & (p < 2.0**52) & (np.abs(frac - 0.5) > 2.0 * np.spacing(p)))
            scaled = np.where(python | empty, 0.0, np.rint(p)).astype(np.int64)
        return decimals, values, empty, python, scaled, np.signbit(values)

    def cells(self, rows: slice, style: str) -> Cells:
        decimals, values, empty, python, scaled, negative = self._parts(rows, style)
        cells = _digits(scaled, negative, empty, decimals)
        for i in np.flatnonzero(python).tolist():
            _put(cells, i, f"{float(values[i]):.{decimals}f}")
        if style == "json":
            _fill(cells, empty, "null")
        return cells

    def longest(self, rows: slice, style: str) -> int:
        decimals, values, empty, python, scaled, negative = self._parts(rows, style)
        lengths = negative + _digit_count(scaled // int(_POW10[decimals])) + (decimals + 1 if decimals else 0)
        longest = int(np.where(empty | python, 0, lengths).max(initial=0))
        return max([longest, *(len(f"{float(values[i]):.{decimals}f}") for i in np.flatnonzero(python).tolist())])


class Time(Column):
    """UTC instants ``start + timedelta(seconds=s)`` (``empty`` rows have none), written with milliseconds
    (truncated) and ``Z``, as :func:`~nfwserver.cli.tracking_options.format_time`."""

    def __init__(self, name: str, start: datetime, seconds: np.ndarray, empty: np.ndarray | None = None) -> None:
        self.name, self.start, self.seconds = name, start, np.asarray(seconds, dtype=np.float64)
        self.empty = np.zeros(len(self.seconds), dtype=bool) if empty is None else np.asarray(empty, dtype=bool)

    def __len__(self) -> int:
        return len(self.seconds)

    def epoch_us(self, rows: slice) -> np.ndarray:
        """The instants of ``rows`` in microseconds since 1970 (as ``timedelta`` rounds)."""
        return epoch_us_after(self.start, self.seconds[rows])

    def cells(self, rows: slice, style: str) -> Cells:
        empty = self.empty[rows]
        codes = iso_codes(self.epoch_us(rows) // 1000, quoted=style == "json")
        codes[empty] = 0
        cells = Cells(codes, np.where(empty, 0, codes.shape[1]), ~empty)
        if style == "json":
            _fill(cells, empty, "null")
        return cells

    def longest(self, rows: slice, style: str) -> int:
        return 0 if self.empty[rows].all() else 24 + 2 * (style == "json")


class Duration(Number):
    """Seconds from one :class:`Time` to another, as ``(later - earlier).total_seconds()`` of the datetimes;
    empty where either is."""

    def __init__(self, name: str, earlier: Time, later: Time, decimals: int) -> None:
        self.name, self.decimals, self.earlier, self.later = name, decimals, earlier, later
        self.empty = earlier.empty | later.empty

    def __len__(self) -> int:
        return len(self.empty)

    def _values(self, rows: slice) -> np.ndarray:
        seconds: np.ndarray = (self.later.epoch_us(rows) - self.earlier.epoch_us(rows)) / 1e6
        return seconds


class Flag(Column):
    """Booleans: ``Y``/``N`` in tables and CSV, ``true``/``false`` in JSON."""

    def __init__(self, name: str, values: np.ndarray) -> None:
        self.name, self.values = name, np.asarray(values, dtype=bool)

    def __len__(self) -> int:
        return len(self.values)

    def cells(self, rows: slice, style: str) -> Cells:
        yes, no = ("true", "false") if style == "json" else ("Y", "N")
        values = self.values[rows]
        codes = codes_of([no, yes])[values.astype(np.intp)]
        return Cells(codes, np.where(values, len(yes), len(no)), np.zeros(len(values), dtype=bool))


def epoch_us_after(start: datetime, seconds: np.ndarray) -> np.ndarray:
    """``start + timedelta(seconds=s)`` for each ``s`` (NaN counts as 0), as integer microseconds since 1970.

    As ``timedelta`` converts a float: whole seconds exactly, then the fraction times 10**6 split into whole
    microseconds and a remainder, which is rounded to the nearest microsecond, a tie to an even total.
    """
    seconds = np.nan_to_num(np.asarray(seconds, dtype=np.float64), nan=0.0)
    fraction, whole = np.modf(seconds)
    sub, micro = np.modf(fraction * 1e6)
    total = whole.astype(np.int64) * 1_000_000 + micro.astype(np.int64)
    tie = np.abs(sub) == 0.5
    step = np.where(np.abs(sub) >= 0.5, np.sign(sub), 0.0).astype(np.int64)
    step = np.where(tie & (total % 2 == 0), 0, step)
    micros: np.ndarray = (start - _EPOCH) // timedelta(microseconds=1) + total + step
    return micros


def _fill(cells: Cells, where: np.ndarray, text: str) -> None:
    """Put ``text`` in the cells ``where``, left-aligned."""
    if not where.any():
        return
    width = max(cells.codes.shape[1], len(text))
    codes = np.zeros((len(cells.codes), width), dtype=cells.codes.dtype)
    codes[:, : cells.codes.shape[1]] = cells.codes
    codes[where] = 0
    codes[where, : len(text)] = codes_of([text])[0]
    cells.codes = codes
    cells.lengths = np.where(where, len(text), cells.lengths)
    cells.offsets = np.where(where, 0, cells.offsets)
    cells.right = np.where(where, False, cells.right)


def _digit_count(n: np.ndarray) -> np.ndarray:
    """Decimal digits of non-negative integers (1 for 0)."""
    return np.maximum(1, np.searchsorted(_POW10, n, side="right"))


def _digits(scaled: np.ndarray, negative: np.ndarray, empty: np.ndarray, decimals: int) -> Cells:
    """Right-aligned cells of ``-`` (where ``negative``), the non-negative integers ``scaled`` with a decimal
    point before their last ``decimals`` digits (at least one digit before it); "" where ``empty``."""
    rows = len(scaled)
    n_whole = _digit_count(scaled // int(_POW10[decimals]))
    sign = (negative & ~empty).astype(np.intp)
    lengths = np.where(empty, 0, sign + n_whole + (decimals + 1 if decimals else 0))
    # Every row's digits are laid out before the empty ones are cleared: room for one digit at least.
    width = max(1 + (decimals + 1 if decimals else 0), int(lengths.max(initial=0)))
    codes = np.zeros((rows, width), dtype=np.uint8)
    rest = scaled.copy()
    column = width - 1
    for _ in range(decimals):
        codes[:, column] = _ZERO + rest % 10
        rest //= 10
        column -= 1
    if decimals:
        codes[:, column] = _POINT
        column -= 1
    for q in range(int(n_whole.max(initial=1))):
        codes[:, column - q] = np.where(q < n_whole, _ZERO + rest % 10, 0)
        rest //= 10
    minus = np.flatnonzero(sign)
    codes[minus, column - n_whole[minus]] = _MINUS
    codes[empty] = 0
    return Cells(codes, lengths, ~empty, width - lengths)


def _put(cells: Cells, row: int, text: str) -> None:
    """Replace one cell by ``text``, left-aligned."""
    wide = max(ord(c) for c in text) >= 128 if text else False
    if len(text) > cells.codes.shape[1] or (wide and cells.codes.dtype == np.uint8):
        wider = np.zeros((len(cells.codes), max(len(text), cells.codes.shape[1])),
                         dtype=np.uint32 if wide else cells.codes.dtype)
        wider[:, : cells.codes.shape[1]] = cells.codes
        cells.codes = wider
    cells.codes[row] = 0
    cells.codes[row, : len(text)] = [ord(c) for c in text]
    cells.lengths[row] = len(text)
    cells.offsets[row] = 0
    cells.right[row] = text[:1].isdigit() or text[:1] == "-"


def iso_codes(ms: np.ndarray, quoted: bool = False) -> np.ndarray:
    """``YYYY-MM-DDTHH:MM:SS.mmmZ`` of milliseconds since 1970 (proleptic Gregorian, years 1..9999), in double
    quotes if ``quoted``."""
    days, ms_of_day = ms // 86_400_000, ms % 86_400_000
    q = int(quoted)
    codes = np.empty((len(ms), 24 + 2 * q), dtype=np.uint8)
    if not len(ms):
        return codes
    first, last = int(days.min()), int(days.max())
    if last - first < 4096:  # the usual case: a few days
        which = days - first
        day_numbers = range(first, last + 1)
    else:
        unique_days, which = np.unique(days, return_inverse=True)
        day_numbers = unique_days.tolist()
    codes[:, q : q + 11] = codes_of([_civil_date(d) for d in day_numbers])[which]  # "YYYY-MM-DDT"
    seconds = ms_of_day // 1000
    codes[:, q + 11 : q + 13] = _TWO[seconds // 3600]
    codes[:, q + 14 : q + 16] = _TWO[seconds // 60 % 60]
    codes[:, q + 17 : q + 19] = _TWO[seconds % 60]
    codes[:, q + 13] = codes[:, q + 16] = ord(":")
    codes[:, q + 19] = _POINT
    codes[:, q + 20 : q + 23] = _THREE[ms_of_day % 1000]
    codes[:, q + 23] = ord("Z")
    if quoted:
        codes[:, 0] = codes[:, -1] = ord('"')
    return codes


def _civil_date(days: int) -> str:
    """``YYYY-MM-DDT`` of a day count since 1970-01-01."""
    when = _EPOCH + timedelta(days=days)
    return f"{when.year:04d}-{when.month:02d}-{when.day:02d}T"
