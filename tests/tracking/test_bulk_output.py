"""The bulk table/CSV/JSON writer and its columns give, cell for cell, the text of per-cell Python formatting."""

from __future__ import annotations

import csv
import io
import json
import math
import sys
from datetime import datetime, timedelta, timezone

import numpy as np
import pytest

from nfwserver.cli import bulk_output
from nfwserver.cli import output_columns as bo
from nfwserver.cli.forked_rows import write_in_order
from nfwserver.cli.tracking_options import format_time

_EPOCH = datetime(1970, 1, 1, tzinfo=timezone.utc)


def _awkward_numbers(rng: np.random.Generator) -> np.ndarray:
    """Ordinary values and the ones that trip formatting: ties, values next to ties, signed zeros, tiny negatives,
    large magnitudes, non-finite values."""
    ties = np.array([k + 0.5 for k in range(-5, 6)] + [0.125, 0.375, 2.675, 1.0005, 0.0000005, 1e-7, -1e-7])
    near = np.concatenate([np.nextafter(ties, np.inf), np.nextafter(ties, -np.inf)])
    special = np.array([0.0, -0.0, 1e-300, -1e-300, 1e15, -1e15, 2.0**52, 2.0**53 + 2, 1e22, np.nan, np.inf, -np.inf,
                        359.99999999, 359.9999995, 89.95, -89.95, 0.05, 0.15, 0.25, 0.35])
    return np.concatenate([rng.uniform(-400, 400, 3000), rng.uniform(-1, 1, 1000), rng.uniform(0, 2e5, 1000),
                           np.round(rng.uniform(-100, 100, 1000), 1) + 0.05, ties, near, special])


@pytest.mark.parametrize("decimals", [0, 1, 2, 4, 6])
@pytest.mark.parametrize("style", ["table", "csv"])
def test_numbers_are_formatted_as_python_formats_them(decimals: int, style: str) -> None:
    values = _awkward_numbers(np.random.default_rng(decimals))
    empty = np.zeros(len(values), dtype=bool)
    empty[::7] = True
    column = bo.Number("x", values, decimals, empty)
    buf = io.StringIO()
    bulk_output.write_rows([column], style, buf)
    lines = buf.getvalue().split("\n")
    got = lines[1:-1]
    d = decimals if style == "table" else max(decimals, 6)
    want = ["" if e else f"{v:.{d}f}" for v, e in zip(values.tolist(), empty.tolist())]
    if style == "table":
        width = max(1, *map(len, want))
        want = [(w.rjust(width) if w[:1].isdigit() or w[:1] == "-" else w.ljust(width)).rstrip() for w in want]
    assert got == want


def test_times_are_format_time_of_the_instant() -> None:
    rng = np.random.default_rng(3)
    instants = np.concatenate([rng.integers(-2**40, 2**40, 5000) * 64, [0, -1, 999, 1000, -999, -1000,
                                                                    86_400_000_000 - 1, 951_782_400_000_000,
                                                                    253_402_300_799_000_000, -62_135_596_800_000_000]])
    column = bo.Time("t", _EPOCH, instants / 1e6)
    buf = io.StringIO()
    bulk_output.write_rows([column], "csv", buf)
    want = [format_time(_EPOCH + timedelta(seconds=s)) for s in (instants / 1e6).tolist()]
    assert buf.getvalue().split("\n")[1:-1] == want


def test_table_csv_and_json_of_mixed_columns() -> None:
    names = ["ISS (ZARYA)", "SOYUZ, R/B", 'QUOTE "Q"', "2023-001A", "-DASH", "ÄÖÜ ЛЕТ 衛星", "X"]
    index = np.array([0, 1, 2, 3, 4, 5, 6, 5, 0])
    numbers = np.array([12.345, -0.04, 7.0, 359.95, np.nan, 0.5, 1e5, -3.25, 2.5])
    empty = np.array([False, False, True, False, True, False, False, False, False])
    instants = np.array([0, 1_700_000_000_123_456, 0, 951_782_400_999_999, 0, 5, 6, 7, 8])
    columns = [bo.Integer("id", np.array([5, 25544, 7, 100000, 3, 44, 1, 2, 3])), bo.Text("name", names, index),
               bo.Time("when", _EPOCH, instants / 1e6, empty), bo.Number("deg", numbers, 1, empty),
               bo.Flag("up", np.array([True, False, True, False, True, False, True, False, True]))]
    rows = []
    for i in range(9):
        e = bool(empty[i])
        rows.append([str([5, 25544, 7, 100000, 3, 44, 1, 2, 3][i]), names[index[i]],
                     "" if e else format_time(_EPOCH + timedelta(seconds=instants[i] / 1e6)),
                     None if e else float(numbers[i]), "Y" if i % 2 == 0 else "N"])
    header = ["id", "name", "when", "deg", "up"]
    # csv: as the csv module writes it
    want = io.StringIO()
    writer = csv.writer(want, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([[r[0], r[1], r[2], "" if r[3] is None else f"{r[3]:.6f}", r[4]] for r in rows])
    got = io.StringIO()
    bulk_output.write_rows(columns, "csv", got)
    assert got.getvalue() == want.getvalue()
    # table: the old aligned writer
    cells = [[r[0], r[1], r[2], "" if r[3] is None else f"{r[3]:.1f}", r[4]] for r in rows]
    widths = [max(len(c), *(len(r[i]) for r in cells)) for i, c in enumerate(header)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(header, widths)).rstrip()]
    lines += ["  ".join(v.rjust(w) if v[:1].isdigit() or v[:1] == "-" else v.ljust(w)
                        for v, w in zip(r, widths)).rstrip() for r in cells]
    got = io.StringIO()
    bulk_output.write_rows(columns, "table", got)
    assert got.getvalue() == "\n".join(lines) + "\n"
    # json: an array of objects with typed values
    got = io.StringIO()
    bulk_output.write_rows(columns, "json", got)
    doc = json.loads(got.getvalue())
    assert [d["name"] for d in doc] == [names[i] for i in index]
    assert doc[0] == {"id": 5, "name": "ISS (ZARYA)", "when": "1970-01-01T00:00:00.000Z", "deg": 12.345,
                      "up": True}
    assert doc[2]["when"] is None and doc[2]["deg"] is None and doc[1]["deg"] == -0.04
    assert got.getvalue().count("\n") == 9 + 2
    assert math.isclose(doc[7]["deg"], -3.25)


@pytest.mark.skipif(sys.platform == "win32", reason="fork")
@pytest.mark.parametrize("processes", [1, 3])
def test_a_long_table_made_by_several_processes_is_the_aligned_table(monkeypatch, processes: int) -> None:
    """Its widths are those of every row; its blocks' text may be made by forked processes (cli/forked_rows.py)."""
    asked: list[int] = []

    def recorded(count, make, put, processes) -> None:  # the real writer, with the processes it was asked for
        asked.append(processes)
        write_in_order(count, make, put, processes)

    monkeypatch.setattr(bulk_output, "write_in_order", recorded)
    n = 3 * bulk_output.BLOCK_ROWS + 17
    rng = np.random.default_rng(3)
    ids, values = rng.integers(1, 10**6, n), rng.normal(0.0, 100.0, n)
    names = ["A", "LONGER NAME", "ÄÖÜ"]
    which = rng.integers(0, 3, n)
    cells = [[str(i), names[w], f"{v:.1f}"] for i, w, v in zip(ids.tolist(), which.tolist(), values.tolist())]
    header = ["id", "name", "value"]
    widths = [max(len(c), *(len(r[i]) for r in cells)) for i, c in enumerate(header)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(header, widths)).rstrip()]
    lines += ["  ".join(v.rjust(w) if v[:1].isdigit() or v[:1] == "-" else v.ljust(w)
                        for v, w in zip(r, widths)).rstrip() for r in cells]
    got = io.StringIO()
    bulk_output.write_rows([bo.Integer("id", ids), bo.Text("name", names, which), bo.Number("value", values, 1)],
                           "table", got, processes)
    assert got.getvalue() == "\n".join(lines) + "\n"
    assert asked == [processes]


@pytest.mark.parametrize("style", ["table", "csv", "json"])
def test_a_block_whose_numbers_are_all_empty(style: str) -> None:
    """(A slab of passes all up for the whole window has no AOS azimuth: this raised IndexError.)"""
    buf = io.StringIO()
    bulk_output.write_rows([bo.Integer("a", np.array([1, 2])), bo.Number("b", np.array([np.nan, 3.0]), 1,
                                                                         np.array([True, True]))], style, buf)
    assert buf.getvalue() == {"table": "a  b\n1\n2\n", "csv": "a,b\n1,\n2,\n",
                              "json": '[\n{"a": 1, "b": null},\n{"a": 2, "b": null}\n]\n'}[style]


@pytest.mark.parametrize("style", ["table", "csv", "json"])
def test_no_rows(style: str) -> None:
    buf = io.StringIO()
    bulk_output.write_rows([bo.Integer("a", np.array([], dtype=np.int64)), bo.Text("b", [])], style, buf)
    assert buf.getvalue() == {"table": "a  b\n", "csv": "a,b\n", "json": "[]\n"}[style]


def test_offsets_become_microseconds_as_timedelta_rounds_them() -> None:
    rng = np.random.default_rng(7)
    start = datetime(2026, 5, 8, 13, 2, 3, 456789, tzinfo=timezone.utc)
    halves = np.array([k + 0.5 for k in range(-6, 7)]) * 1e-6
    seconds = np.concatenate([rng.uniform(-3e5, 3e5, 20000), rng.uniform(-1, 1, 2000), halves, halves + 1.0,
                              halves - 7.0, np.nextafter(halves, 1.0), np.nextafter(halves, -1.0),
                              [0.0, -0.0, 1e-7, -1e-7, 0.4999999e-6, 86400.0, -86400.0, 259199.9999995]])
    got = bo.epoch_us_after(start, seconds)
    want = [(start + timedelta(seconds=s) - _EPOCH) // timedelta(microseconds=1) for s in seconds.tolist()]
    assert got.tolist() == want
