"""What ``nfwserver passes`` shows: the passes chosen by its filters, as an 80-column table by default.

The default table has one row per pass, in at most 80 columns::

      sat  name          aos             tca       los       max  rise  set   min
    25544  ISS           05-08 12:01:02  12:06:30  12:11:58  67.3   312  118  10.9

``aos`` is month-day and time, ``tca``/``los`` the time of day (UTC, or the local zone with ``--local``,
named in the header); ``max`` the highest elevation (degrees), ``rise``/``set`` the azimuths at AOS and LOS
(degrees, true north), ``min`` the length in minutes.  ``--wide`` gives every column, as CSV and JSON do.
"""

from __future__ import annotations

import fnmatch
import re
import time
from collections.abc import Iterable, Sequence
from datetime import datetime

import numpy as np

from nfwserver.cli.output_columns import Cells, Column, Integer, Number, Text, Time, epoch_us_after, iso_codes
from nfwserver.cli.pass_text import zone_label

__all__ = ["ClockTime", "compact_columns", "local_offsets_us", "matching_names", "zone_label"]

NAME_WIDTH = 12  #: the name column of the 80-column table (a DDE name is at most 12 characters)


class ClockTime(Time):
    """Instants as ``MM-DD HH:MM:SS`` (``with_date``) or ``HH:MM:SS``, shifted by ``offset_us`` (the local
    zone's offset at each instant; zeros for UTC)."""

    def __init__(self, name: str, start: datetime, seconds: np.ndarray, offset_us: np.ndarray,
                 with_date: bool, empty: np.ndarray | None = None) -> None:
        super().__init__(name, start, seconds, empty)
        self.offset_us, self.with_date = offset_us, with_date

    def cells(self, rows: slice, style: str) -> Cells:
        empty = self.empty[rows]
        codes = iso_codes((self.epoch_us(rows) + self.offset_us[rows]) // 1000)
        codes = codes[:, 5:19].copy() if self.with_date else codes[:, 11:19].copy()
        if self.with_date:
            codes[:, 5] = ord(" ")
        codes[empty] = 0
        return Cells(codes, np.where(empty, 0, codes.shape[1]), ~empty)

    def longest(self, rows: slice, style: str) -> int:
        return 0 if self.empty[rows].all() else (14 if self.with_date else 8)


def local_offsets_us(start: datetime, seconds: np.ndarray) -> np.ndarray:
    """The local zone's UTC offset (microseconds) at each instant ``start + seconds`` (NaN: at ``start``)."""
    epoch_s = epoch_us_after(start, seconds) // 1_000_000
    quarters, where = np.unique(epoch_s // 900, return_inverse=True)  # zones change on quarter hours
    offsets = [time.localtime(int(q) * 900).tm_gmtoff * 1_000_000 for q in quarters.tolist()]
    return np.asarray(offsets, dtype=np.int64)[where] if len(offsets) else np.zeros(0, dtype=np.int64)


def compact_columns(start: datetime, cols: dict[str, np.ndarray], names: Sequence[str], which: np.ndarray,
                    local: bool) -> list[Column]:
    """The 80-column table's columns for the passes ``cols`` (PassList columns, times in seconds after
    ``start``); ``names[which[row]]`` is each row's satellite name."""
    aos_unknown, los_unknown = np.isnan(cols["aos_s"]), np.isnan(cols["los_s"])
    zeros = np.zeros(len(cols["aos_s"]), dtype=np.int64)

    def offsets(key: str) -> np.ndarray:
        return local_offsets_us(start, cols[key]) if local else zeros

    duration_min = (np.nan_to_num(cols["los_s"]) - np.nan_to_num(cols["aos_s"])) / 60.0
    zone = zone_label(local, start)
    return [Integer("sat", cols["catalog_number"]),
            Text("name", [name[:NAME_WIDTH] for name in names], which),
            ClockTime(f"aos ({zone})", start, cols["aos_s"], offsets("aos_s"), True, aos_unknown),
            ClockTime("tca", start, cols["tca_s"], offsets("tca_s"), False),
            ClockTime("los", start, cols["los_s"], offsets("los_s"), False, los_unknown),
            Number("max", cols["max_elevation_deg"], 1),
            Number("rise", cols["aos_azimuth_deg"], 0, aos_unknown),
            Number("set", cols["los_azimuth_deg"], 0, los_unknown),
            Number("min", duration_min, 1, aos_unknown | los_unknown)]


def matching_names(patterns: Iterable[str], satellites: Iterable[tuple[int, str, str]]) -> list[int]:
    """Catalog numbers of the satellites (catalog number, DDE name, element name) whose either name matches
    one of the shell-style ``patterns`` (``NOAA*``, ``SO-5?``), case-insensitively, in catalog order."""
    compiled = [fnmatch.translate(p.upper()) for p in patterns]
    if not compiled:
        return []
    regex = re.compile("|".join(f"(?:{c})" for c in compiled))
    return [n for n, dde, name in satellites if regex.match(dde.upper()) or regex.match(name.upper())]
