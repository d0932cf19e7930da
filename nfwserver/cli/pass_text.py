"""The rows of ``nfwserver passes`` for a few passes, written cell by cell in pure Python (no numpy).

:mod:`nfwserver.cli.bulk_output` writes whole columns with numpy, which a catalog's tens of thousands of rows
need; a few satellites' dozen rows do not, and importing numpy would cost more than the rest of the command.
This module writes the same text (see :mod:`nfwserver.cli.bulk_output` for the three formats and
:mod:`nfwserver.cli.output_columns` for each cell: numbers as ``f"{value:.{decimals}f}"`` with at least six
decimals in CSV and JSON, times as :func:`~nfwserver.cli.tracking_options.format_time` of
``start + timedelta(seconds=s)``, a table cell right-aligned when it starts with a digit or ``-``), and the
80-column table of :func:`nfwserver.cli.pass_table.compact_columns`.

Rows are :data:`nfwserver.tracking.few_passes.Row` tuples: times in seconds after ``start`` (None unknown).
"""

from __future__ import annotations

import csv
import io
import json
import time
from collections.abc import Mapping, Sequence
from datetime import datetime, timedelta, timezone
from typing import TextIO

from nfwserver.cli.tracking_options import format_time
from nfwserver.tracking.few_passes import Row

#: A cell: its text in each style, None for an empty cell (``null`` in JSON).
Cell = tuple[str, str, str] | None
CSV_DECIMALS = 6
NAME_WIDTH = 12  #: as :data:`nfwserver.cli.pass_table.NAME_WIDTH`


def zone_label(local: bool, when: datetime) -> str:
    """``UTC``, or the local zone's abbreviation at ``when`` (``CEST``)."""
    if not local:
        return "UTC"
    return time.strftime("%Z", time.localtime(when.astimezone(timezone.utc).timestamp())) or "local"


def _number(value: float | None, decimals: int) -> Cell:
    if value is None:
        return None
    wide = f"{value:.{max(decimals, CSV_DECIMALS)}f}"
    return f"{value:.{decimals}f}", wide, wide


def _time(when: datetime | None) -> Cell:
    if when is None:
        return None
    text = format_time(when)
    return text, text, f'"{text}"'


def _text(value: str) -> Cell:
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerow([value, ""])
    return value, out.getvalue()[:-2], json.dumps(value) if value else "null"


def _flag(value: bool) -> Cell:
    return ("Y", "Y", "true") if value else ("N", "N", "false")


def _at(start: datetime, seconds: float | None) -> datetime | None:
    return None if seconds is None else start + timedelta(seconds=seconds)


def _wide_rows(rows: Sequence[Row], start: datetime, names: Mapping[int, str]) -> list[list[Cell]]:
    out = []
    for number, aos_s, tca_s, los_s, max_el, aos_az, los_az in rows:
        aos, los = _at(start, aos_s), _at(start, los_s)
        duration = (los - aos).total_seconds() if aos is not None and los is not None else None
        out.append([(str(number),) * 3, _text(names[number]), _time(aos), _time(_at(start, tca_s)), _time(los),
                    _number(max_el, 1), _number(aos_az, 1), _number(los_az, 1), _number(duration, 0),
                    _flag(aos_s is None or aos_s < 0.0)])
    return out


def _clock(start: datetime, seconds: float | None, local: bool, with_date: bool) -> Cell:
    """``MM-DD HH:MM:SS`` or ``HH:MM:SS`` of ``start + seconds``, in the local zone when ``local``."""
    when = _at(start, seconds)
    if when is None:
        return None
    if local:
        quarter = int(when.timestamp() // 900) * 900  # zones change on quarter hours
        when += timedelta(seconds=time.localtime(quarter).tm_gmtoff)
    text = format_time(when)
    text = text[5:10] + " " + text[11:19] if with_date else text[11:19]
    return text, text, text


def _compact_rows(rows: Sequence[Row], start: datetime, names: Mapping[int, str], local: bool
                  ) -> list[list[Cell]]:
    out = []
    for number, aos_s, tca_s, los_s, max_el, aos_az, los_az in rows:
        minutes = None if aos_s is None or los_s is None else (los_s - aos_s) / 60.0
        out.append([(str(number),) * 3, _text(names[number][:NAME_WIDTH]), _clock(start, aos_s, local, True),
                    _clock(start, tca_s, local, False), _clock(start, los_s, local, False), _number(max_el, 1),
                    _number(aos_az, 0), _number(los_az, 0), _number(minutes, 1)])
    return out


def _table(header: Sequence[str], cells: list[list[Cell]], out: TextIO) -> None:
    texts = [["" if cell is None else cell[0] for cell in row] for row in cells]
    widths = [max([len(name), *(len(row[i]) for row in texts)]) for i, name in enumerate(header)]
    lines = ["  ".join(name.ljust(w) for name, w in zip(header, widths)).rstrip()]
    for row in texts:
        lines.append("  ".join(text.rjust(w) if text[:1].isdigit() or text[:1] == "-" else text.ljust(w)
                               for text, w in zip(row, widths)).rstrip())
    out.write("\n".join(lines) + "\n")


def write_pass_text(rows: Sequence[Row], start: datetime, names: Mapping[int, str], columns: Sequence[str],
                    fmt: str, out: TextIO, compact: bool = False, zone: str = "UTC", local: bool = False) -> None:
    """Write ``rows`` as ``passes`` writes them: ``columns`` (PASS_COLUMNS) in ``fmt`` (``table``, ``csv``,
    ``json``), or with ``compact`` the 80-column table (times in the ``local`` zone, named ``zone``; ``names``
    are then DDE names)."""
    if compact:
        header = ["sat", "name", f"aos ({zone})", "tca", "los", "max", "rise", "set", "min"]
        _table(header, _compact_rows(rows, start, names, local), out)
        return
    cells = _wide_rows(rows, start, names)
    if fmt == "table":
        _table(columns, cells, out)
    elif fmt == "csv":
        head = io.StringIO()
        csv.writer(head, lineterminator="\n").writerow(columns)
        out.write(head.getvalue() + "".join(",".join("" if c is None else c[1] for c in row) + "\n" for row in cells))
    else:
        keys = [json.dumps(name) + ": " for name in columns]
        objects = ["{" + ", ".join(k + ("null" if c is None else c[2]) for k, c in zip(keys, row)) + "}"
                   for row in cells]
        out.write("[\n" + ",\n".join(objects) + "\n]\n" if objects else "[]\n")
