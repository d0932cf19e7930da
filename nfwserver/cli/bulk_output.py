"""Tables, CSV and JSON written a block of rows at a time from whole columns (numpy), not cell by cell.

A :class:`RowWriter` writes columns (:mod:`nfwserver.cli.output_columns`) in one of three formats:

- ``table``: columns aligned, separated by two blanks, a cell right-aligned when it starts with a digit or
  ``-`` (numbers, times) and left-aligned otherwise, trailing blanks removed;
- ``csv``: a header row, then rows as Python's ``csv`` module writes them (``lineterminator="\\n"``);
- ``json``: an array of objects, one a line, keyed by column name.

A block's rows are built as matrices of code points, one per column, laid side by side; the zeros that pad
them are dropped and the rest decoded as one string.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from typing import TextIO

import numpy as np

from nfwserver.cli.forked_rows import write_in_order
from nfwserver.cli.output_columns import SPACE, Cells, Column, codes_of

#: Rows formatted at a time (bounds the temporary matrices: a few MiB).
BLOCK_ROWS = 2048


def _justify(cells: Cells, width: int) -> np.ndarray:
    """The cells padded with blanks to ``width``: right-aligned where ``cells.right``, else left-aligned."""
    codes = cells.codes
    out = np.zeros((len(codes), width), dtype=codes.dtype)
    # Each row's content moves right by its shift; rows sharing a shift move together (a column has few;
    # a set, not np.unique, which would import numpy.ma).
    shift = np.where(cells.right, width - cells.lengths, 0) - cells.offsets
    first = int(shift[0]) if len(shift) else 0
    groups = [(first, slice(None))] if (shift == first).all() else [
        (value, np.flatnonzero(shift == value)) for value in sorted(set(shift.tolist()))]
    for value, rows in groups:
        lo, hi = max(0, -value), min(codes.shape[1], width - value)  # source columns that stay inside
        out[rows, lo + value : hi + value] = codes[rows, lo:hi]
    out[out == 0] = SPACE
    return out


def _text_of(pieces: list[np.ndarray]) -> str:
    """The rows of code points laid side by side, zeros dropped, as one string."""
    block = np.concatenate(pieces, axis=1)
    codes = block[block != 0]
    if codes.dtype == np.uint8:
        return str(codes.tobytes().decode("ascii"))
    return str(codes.astype("<u4").tobytes().decode("utf-32-le"))


def _column(text: str, rows: int) -> np.ndarray:
    return np.broadcast_to(codes_of([text]), (rows, max(1, len(text))))


class RowWriter:
    """Writes rows given as columns, a block at a time: CSV and JSON as they come, a table (which must know
    every width first) when closed, its blocks' text made by ``processes`` processes (forked: POSIX; see
    :mod:`nfwserver.cli.forked_rows`).  Call :meth:`close` once after the last block."""

    def __init__(self, names: Sequence[str], fmt: str, out: TextIO, processes: int = 1) -> None:
        self.names, self.fmt, self.out, self.processes = list(names), fmt, out, processes
        self.rows = 0  #: rows written (or held, for a table)
        self._held: list[Sequence[Column]] = []
        if fmt == "csv":
            header = io.StringIO()
            csv.writer(header, lineterminator="\n").writerow(self.names)
            out.write(header.getvalue())
        self._keys = [json.dumps(name) + ": " for name in self.names]

    def write(self, columns: Sequence[Column]) -> None:
        """Write (or, for a table, hold) the rows of ``columns``, one per name, all of one length."""
        n = len(columns[0]) if columns else 0
        if not n:
            return
        if self.fmt == "table":
            self._held.append(columns)
            self.rows += n
        else:
            for rows in _blocks(n):  # a block at a time: a few MiB of text
                self.put(self._block(columns, rows), rows.stop - rows.start)

    def text(self, columns: Sequence[Column]) -> str:
        """The CSV or JSON text of the rows of ``columns`` (one per name, all of one length), as :meth:`write`
        writes it (see :meth:`put`).  It depends on these rows alone: other processes can make it."""
        return "".join(self._block(columns, rows) for rows in _blocks(len(columns[0]) if columns else 0))

    def put(self, text: str, rows: int) -> None:
        """Write ``text``, the :meth:`text` of ``rows`` rows, after the rows written so far (CSV or JSON)."""
        if self.fmt == "json" and self.rows == 0 and rows:
            text = "[\n" + text[2:]  # the output's first row opens the array
        self.out.write(text)
        self.rows += rows

    def close(self) -> None:
        """End the output: the closing bracket of JSON, the whole of a table."""
        if self.fmt == "json":
            self.out.write("\n]\n" if self.rows else "[]\n")
        elif self.fmt == "table":
            self._table()

    def _block(self, columns: Sequence[Column], rows: slice) -> str:
        if self.fmt == "table":  # a table's text needs every width first: close() writes it
            raise ValueError("a table's rows have no text of their own before the table is closed")
        return self._csv(columns, rows) if self.fmt == "csv" else self._json(columns, rows)

    def _csv(self, columns: Sequence[Column], rows: slice) -> str:
        k = rows.stop - rows.start
        pieces: list[np.ndarray] = []
        for i, column in enumerate(columns):
            pieces += [column.cells(rows, "csv").codes, _column("," if i < len(columns) - 1 else "\n", k)]
        return _text_of(pieces)

    def _json(self, columns: Sequence[Column], rows: slice) -> str:
        k = rows.stop - rows.start
        pieces = [_column(",\n{", k)]
        for i, column in enumerate(columns):
            pieces += [_column((", " if i else "") + self._keys[i], k), column.cells(rows, "json").codes]
        pieces.append(_column("}", k))
        return _text_of(pieces)  # each row after ",\n"

    def _table(self) -> None:
        widths = [len(name) for name in self.names]
        for columns in self._held:
            for rows in _blocks(len(columns[0])):
                widths = [max(w, column.longest(rows, "table")) for w, column in zip(widths, columns)]
        self.out.write("  ".join(name.ljust(w) for name, w in zip(self.names, widths)).rstrip() + "\n")
        blocks = [(columns, rows) for columns in self._held for rows in _blocks(len(columns[0]))]

        def make(k: int) -> tuple[str, int]:
            columns, rows = blocks[k]
            return self._table_rows(columns, rows, widths), rows.stop - rows.start

        write_in_order(len(blocks), make, lambda text, _: self.out.write(text), self.processes)
        self._held.clear()

    @staticmethod
    def _table_rows(columns: Sequence[Column], rows: slice, widths: list[int]) -> str:
        k = rows.stop - rows.start
        pieces = []
        end = np.zeros(k, dtype=np.intp)  # where each line's last non-blank character ends
        at = 0
        for i, column in enumerate(columns):
            if i:
                pieces.append(_column("  ", k))
                at += 2
            cells = column.cells(rows, "table")
            pieces.append(_justify(cells, widths[i]))
            filled = cells.lengths > 0  # cell contents never end in a blank (names are stripped)
            end = np.where(filled, at + np.where(cells.right, widths[i], cells.lengths), end)
            at += widths[i]
        line = np.concatenate(pieces, axis=1)
        line[np.arange(line.shape[1])[None, :] >= end[:, None]] = 0  # rstrip
        return _text_of([line, _column("\n", k)])


def _blocks(n: int) -> list[slice]:
    return [slice(b, min(b + BLOCK_ROWS, n)) for b in range(0, n, BLOCK_ROWS)]


def write_rows(columns: Sequence[Column], fmt: str, out: TextIO, processes: int = 1) -> None:
    """Write ``columns`` (all of one length) to ``out`` as a ``table``, ``csv`` or ``json`` (a table's text made
    by ``processes`` processes)."""
    writer = RowWriter([c.name for c in columns], fmt, out, processes)
    writer.write(columns)
    writer.close()
