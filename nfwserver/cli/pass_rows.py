"""The catalog ``passes`` command's every-column rows (CSV, JSON, ``--wide`` table) from PassList columns.

A large search's passes are written from a :class:`~nfwserver.tracking.pass_spill.SpilledPasses` a slab at a
time (:func:`write_spilled`), so that a whole catalog's week is never held in memory whole; the rows are those
of the whole list written at once, byte for byte (each row's cells depend on that row alone).
"""

from __future__ import annotations

from collections.abc import Mapping
from datetime import datetime
from typing import TYPE_CHECKING, TextIO

import numpy as np

from nfwserver.cli.bulk_output import BLOCK_ROWS, RowWriter
from nfwserver.cli.forked_rows import write_in_order
from nfwserver.cli.output_columns import Column, Duration, Flag, Integer, Number, Text, Time

if TYPE_CHECKING:
    from nfwserver.tracking.pass_spill import SpilledPasses

#: Passes written from a spilled search at a time (a slab: one block of text, so that the text waiting in a
#: process is one block's, whichever process makes it).
SLAB_ROWS = BLOCK_ROWS


def above(cols: dict[str, np.ndarray], min_el: float) -> dict[str, np.ndarray]:
    """The rows of ``cols`` whose maximum elevation reaches ``min_el`` (deg; 0: every row)."""
    if min_el == 0.0:
        return cols
    keep = cols["max_elevation_deg"] >= min_el
    return {key: value[keep] for key, value in cols.items()}


def name_column(numbers: np.ndarray, names: Mapping[int, str]) -> Text:
    """The names of ``numbers`` (catalog numbers, ascending) as the rows' ``name`` column takes them."""
    return Text("name", [names[n] for n in numbers.tolist()])


def wide_columns(start: datetime, cols: dict[str, np.ndarray], numbers: np.ndarray, names: Text) -> list[Column]:
    """The every-column rows of the passes ``cols`` (PassList columns, times after ``start``); ``numbers``:
    every catalog number with a pass, ascending, ``names`` theirs (a column of one name each, in that order)."""
    which = np.searchsorted(numbers, cols["catalog_number"])
    aos_unknown, los_unknown = np.isnan(cols["aos_s"]), np.isnan(cols["los_s"])
    aos, los = Time("aos_utc", start, cols["aos_s"], aos_unknown), Time("los_utc", start, cols["los_s"], los_unknown)
    return [Integer("catalog_number", cols["catalog_number"]), names.picked(which),
            aos, Time("tca_utc", start, cols["tca_s"]), los,
            Number("max_elevation_deg", cols["max_elevation_deg"], 1),
            Number("aos_azimuth_deg", cols["aos_azimuth_deg"], 1, aos_unknown),
            Number("los_azimuth_deg", cols["los_azimuth_deg"], 1, los_unknown), Duration("duration_s", aos, los, 0),
            Flag("in_progress", aos_unknown | (cols["aos_s"] < 0.0))]


def write_spilled(passes: SpilledPasses, start: datetime, min_el: float, names: Mapping[int, str],
                  column_names: list[str], fmt: str, out: TextIO, processes: int = 1) -> None:
    """Write ``passes`` (``names``: the name of each catalog number with a pass) as ``fmt`` (CSV or JSON), those
    reaching ``min_el`` deg, a slab of :data:`SLAB_ROWS` at a time; with ``processes`` > 1, forked processes make
    some slabs' text (:mod:`nfwserver.cli.forked_rows`)."""
    numbers = np.array(sorted(names), dtype=np.int64)
    shown = name_column(numbers, names)
    writer = RowWriter(column_names, fmt, out)
    with passes.sort_into_slabs(SLAB_ROWS) as slabs:
        def make(k: int) -> tuple[str, int]:
            cols = above(slabs.slab(k).columns, min_el)
            return writer.text(wide_columns(start, cols, numbers, shown)), len(cols["tca_s"])

        write_in_order(len(slabs), make, writer.put, processes)
    writer.close()
