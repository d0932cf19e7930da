"""Passes kept in a temporary file (tracking/pass_spill.py): read back in slabs, they are the in-memory list's rows
in its order, and ``passes`` writes from them the bytes of the whole list written at once."""

from __future__ import annotations

import io
import json
import math
from datetime import datetime, timedelta, timezone

import numpy as np
import pytest

import nfwserver.cli.pass_rows as pass_rows
from nfwserver.cli import main
from nfwserver.cli.bulk_output import write_rows
from nfwserver.cli.forked_rows import write_in_order
from nfwserver.cli.pass_reports import PASS_COLUMNS
from nfwserver.tracking.elements import load_element_file
from nfwserver.tracking.observer import Observer
from nfwserver.tracking.pass_records import COLUMNS, PassColumns, PassList
from nfwserver.tracking.pass_spill import SpilledPasses
from nfwserver.tracking.passes import find_passes
from tests.conftest import DATA

START = datetime(2026, 5, 8, tzinfo=timezone.utc)


def _parts(seed: int, count: int) -> list[dict[str, np.ndarray]]:
    """Random passes in parts, with ties of first time (and of first time and catalog number) and unknown ends."""
    rng = np.random.default_rng(seed)
    parts = []
    for _ in range(count):
        k = int(rng.integers(0, 40))
        first = rng.choice(np.arange(-600.0, 3600.0, 300.0), k)  # few values: many ties
        part = {"catalog_number": rng.integers(1, 6, k).astype(np.int64), "aos_s": first.copy(),
                "tca_s": first + 120.0, "los_s": first + 600.0 + rng.random(k),
                "max_elevation_deg": rng.random(k) * 90.0, "aos_azimuth_deg": rng.random(k) * 360.0,
                "los_azimuth_deg": rng.random(k) * 360.0}
        unknown = rng.random(k) < 0.2
        part["aos_s"][unknown] = math.nan
        part["los_s"][unknown & (rng.random(k) < 0.5)] = math.nan
        parts.append(part)
    return parts


def _in_memory(parts: list[dict[str, np.ndarray]]) -> PassList:
    gathered = PassColumns(16)
    for part in parts:
        gathered.add(part)
    return gathered.pass_list(START, 3600.0)


def _same(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> None:
    for name, _ in COLUMNS:
        assert a[name].dtype == b[name].dtype
        assert np.array_equal(a[name], b[name], equal_nan=True), name


@pytest.mark.parametrize("slab", [1, 7, 1000])
def test_slabs_hold_the_in_memory_lists_rows_in_its_order(slab: int) -> None:
    parts = _parts(1, 30)
    expected = _in_memory(parts)
    spilled = SpilledPasses(START, 3600.0)
    for part in parts:
        spilled.add({name: values.copy() for name, values in part.items()})
    spilled.seal([7, 3])
    try:
        assert len(spilled) == len(expected) > 300
        assert spilled.catalog_numbers() == expected.catalog_numbers()
        cols = expected.columns
        up = np.isnan(cols["aos_s"]) & np.isnan(cols["los_s"])
        assert spilled.always_up() == cols["catalog_number"][up].tolist() != []
        high = up & (cols["max_elevation_deg"] >= 45.0)
        assert spilled.always_up(45.0) == cols["catalog_number"][high].tolist()
        with spilled.sort_into_slabs(slab) as sorted_slabs:
            slabs = list(sorted_slabs)
        assert [len(s) for s in slabs[:-1]] == [slab] * (len(slabs) - 1)
        assert slabs[0].skipped == (3, 7)
        _same({name: np.concatenate([s.columns[name] for s in slabs]) for name, _ in COLUMNS}, cols)
    finally:
        spilled.close()


def test_workers_files_joined_read_as_one_list() -> None:
    """Forked workers each fill a file the parent made and hand back their keys; joined in their order, the rows
    are those of PassList.concat of the workers' lists."""
    shares = [_parts(2, 10), _parts(3, 0), _parts(4, 12)]
    files, keys = [], []
    for share in shares:
        spilled = SpilledPasses(START, 3600.0, spill=io.BytesIO())
        for part in share:
            spilled.add({name: values.copy() for name, values in part.items()})
        spilled.seal()
        files.append(spilled._files[0][0] if spilled._files else io.BytesIO())
        keys.append((spilled.keys(), [len(share)]))
    joined = SpilledPasses.joined(START, 3600.0, files, keys)
    expected = PassList.concat(START, 3600.0, [_in_memory(share) for share in shares])
    assert joined.skipped == (0, 10, 12)
    cols = expected.columns
    assert joined.always_up() == cols["catalog_number"][np.isnan(cols["aos_s"]) & np.isnan(cols["los_s"])].tolist()
    with joined.sort_into_slabs(50) as sorted_slabs:
        slabs = list(sorted_slabs)
    _same({name: np.concatenate([s.columns[name] for s in slabs]) for name, _ in COLUMNS}, cols)


@pytest.mark.parametrize("fmt", ["csv", "json"])
def test_passes_written_a_slab_at_a_time_are_the_whole_lists_bytes(capsys, monkeypatch, tmp_path, fmt: str
                                                                    ) -> None:
    """The catalog writer, slabs of 97 passes, against the list found in memory and written at once."""
    elements = tmp_path / "some.txt"
    elements.write_text("\n".join((DATA / "active.txt").read_text().splitlines()[: 3 * 300]) + "\n")
    monkeypatch.setattr(pass_rows, "SLAB_ROWS", 97)
    assert main(["passes", "--elements", str(elements), "--all", "--observer", "52.2,0.12,20", "--start",
                 "2026-05-08T00:00:00Z", "--hours", "24", "--format", fmt, "--workers", "1"]) == 0
    written = capsys.readouterr().out
    sets = load_element_file(elements).sets
    found = find_passes(sets, Observer(52.2, 0.12, 20.0), START, START + timedelta(hours=24))
    numbers = np.array(found.catalog_numbers(), dtype=np.int64)
    names = {s.catalog_number: s.name for s in sets}
    whole = io.StringIO()
    write_rows(pass_rows.wide_columns(START, found.columns, numbers, pass_rows.name_column(numbers, names)), fmt,
               whole)
    assert len(found) > 5 * 97
    assert written == whole.getvalue()


def test_an_empty_search_writes_an_empty_array_and_closes_twice() -> None:
    empty = SpilledPasses(START, 3600.0).seal()
    out = io.StringIO()
    pass_rows.write_spilled(empty, START, 0.0, {}, PASS_COLUMNS, "json", out)
    assert out.getvalue() == "[]\n" and empty.always_up() == []
    with empty.sort_into_slabs() as none:
        assert len(none) == 0 and list(none) == []
    empty.close()
    empty.close()


class _Writes(io.StringIO):
    """A stream that remembers how many rows each write held."""

    def __init__(self) -> None:
        super().__init__()
        self.rows: list[int] = []

    def write(self, text: str) -> int:
        self.rows.append(text.count("\n"))
        return super().write(text)


@pytest.mark.parametrize("min_el", [0.0, 60.0])
@pytest.mark.parametrize("fmt", ["csv", "json"])
def test_one_or_more_processes_write_the_same_text_a_block_at_a_time(monkeypatch, fmt: str, min_el: float) -> None:
    """Whichever process makes a slab's text, a write holds one block (BLOCK_ROWS rows): a week's text is never
    held whole.  With ``min_el``, slabs lose rows (some all of them: JSON's first row is then a later slab's)."""
    asked: list[int] = []

    def recorded(count, make, put, processes) -> None:  # the real writer, with the processes it was asked for
        asked.append(processes)
        write_in_order(count, make, put, processes)

    monkeypatch.setattr(pass_rows, "write_in_order", recorded)
    monkeypatch.setattr(pass_rows, "SLAB_ROWS", 97)  # many slabs, some emptied by min_el
    outs = []
    for processes in (1, 2, 3):
        spilled = SpilledPasses(START, 3600.0)
        for part in _parts(5, 600):
            part["max_elevation_deg"][part["tca_s"] < 1500.0] = 10.0  # the earliest passes: below min_el
            spilled.add(part)
        spilled.seal()
        out = _Writes()
        try:
            pass_rows.write_spilled(spilled, START, min_el, {n: f"SAT {n}" for n in range(1, 6)}, PASS_COLUMNS, fmt,
                                    out, processes)
        finally:
            spilled.close()
        outs.append(out)
    assert asked == [1, 2, 3]
    assert outs[0].getvalue() == outs[1].getvalue() == outs[2].getvalue()
    if fmt == "json":
        json.loads(outs[0].getvalue())
    assert sum(outs[0].rows) > 2 * 97
    if min_el:
        assert outs[0].rows[1:4] == [0, 0, 0]  # after the header, the first slabs wrote nothing
    assert max(max(out.rows) for out in outs) <= 97 + 2  # (with JSON's opening line, or CSV's header)


def test_reading_a_slab_leaves_the_files_position_alone() -> None:
    """A forked process reads slabs from the file its parent reads: each read is at its own place (pread)."""
    spilled = SpilledPasses(START, 3600.0)
    for part in _parts(6, 50):
        spilled.add(part)
    with spilled.seal().sort_into_slabs(40) as slabs:
        file = slabs._file
        file.seek(123)
        first = slabs.slab(0).columns
        assert file.tell() == 123
        assert slabs.slab(1).columns["tca_s"][0] >= first["tca_s"][0] - 1e9  # a slab, read at its place
        assert file.tell() == 123
