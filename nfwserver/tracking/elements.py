"""Loading orbital element sets from text in any of the formats stations meet.

Accepted, in any mixture within one file: NORAD TLEs with or without a name line (2-line and
3-line forms; CelesTrak's ``0 NAME`` name lines too), AMSAT verbose sets
(:mod:`nfwserver.tracking.amsat`), and CCSDS OMM as CelesTrak's JSON (a whole file) or CSV (a
header row, then one row per set).  Lines belonging to none of them are skipped silently, except
lines that look like a broken TLE line, which are reported.  A file that opens with ``[`` or ``{``
but is not valid JSON (a TLE file with a ``[group]`` heading, say) is read as text.

Every set becomes an :class:`ElementSet` whose SGP4 model is initialised from canonical TLE lines,
so a satellite propagates identically whichever format it came in.  Nothing in here raises for
bad content: each rejected set is a :class:`Rejection` with its line number and one-sentence
reason.  Names are sanitised once, here (:mod:`nfwserver.tracking.element_names`); values a TLE
cannot hold (non-finite numbers, epochs outside 1957..2056) are rejected
(:func:`nfwserver.tracking.tle.check_ranges`), so every accepted set can be stored and read back.
"""

from __future__ import annotations

import codecs
import csv
import gc
import json
import os
import sys
from collections.abc import Callable
from datetime import datetime, timedelta
from pathlib import Path
from typing import Any

from nfwserver.tracking import amsat, omm
from nfwserver.tracking.element_names import MAX_NAME_LENGTH, sanitize_element_name
from nfwserver.tracking.element_set import (
    MAX_CSV_ROW,
    TLE_LIKE,
    ElementSet,
    ElementSetDraft,
    LoadResult,
    Rejection,
    is_csv_header,
)
from nfwserver.tracking.tle import TleError, epoch_from_tle, parse_tle

__all__ = ["MAX_CSV_ROW", "ElementSet", "LoadResult", "Rejection", "load_element_file", "load_elements"]
#: Longest line read as a name line (characters); the name is then cut to MAX_NAME_LENGTH.
_MAX_NAME = 2 * MAX_NAME_LENGTH


def _clean_name(line: str) -> str:
    name = line.strip()
    if name.startswith("0 "):
        name = name[2:].strip()
    return name


def _could_be_name(line: str) -> bool:
    text = line.strip()
    if not 0 < len(text) <= _MAX_NAME + 2 or TLE_LIKE.match(text):
        return False
    return text.isprintable() or bool(sanitize_element_name(text))


def load_elements(data: str | bytes, source: str = "<text>") -> LoadResult:
    """Load every element set in ``data``; never raises for bad content (see module docstring)."""
    result = LoadResult()
    if isinstance(data, bytes):
        head = data[:4096].decode("utf-8", errors="replace").lstrip("\ufeff \t\r\n")
        if head.startswith(("[", "{")) or not head:
            data = data.decode("utf-8", errors="replace")
        else:
            _load_text(_split_lines(data), source, result)
            return result
    stripped = data.lstrip("\ufeff \t\r\n")
    if stripped.startswith(("[", "{")):
        problem = _load_json(stripped, source, result)
        if problem is None:
            return result
        _load_text(_split_lines(data), source, result)
        if not result.sets and not result.rejected:
            result.rejected.append(problem)
        return result
    _load_text(_split_lines(data), source, result)
    return result


#: Text is decoded and split in pieces of this many bytes: each piece is one call that holds the interpreter
#: lock (about 2 ms), where a whole 64 MiB file split at once would hold it for about 150 ms.
_PIECE = 2**20


def _split_lines(data: str | bytes) -> list[str]:
    """The lines of ``data`` (bytes: UTF-8, bad bytes replaced), split at CR LF, CR or LF."""
    decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")
    lines: list[str] = []
    carry = ""
    for start in range(0, max(len(data), 1), _PIECE):
        piece = data[start:start + _PIECE]
        last = start + _PIECE >= len(data)
        text = carry + (decoder.decode(piece, final=last) if isinstance(piece, bytes) else piece)
        carry = ""
        if text.endswith("\r") and not last:  # its LF may open the next piece
            text, carry = text[:-1], "\r"
        parts = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        if not last:
            carry = parts.pop() + carry
        lines.extend(parts)
    return lines


def _load_text(lines: list[str], source: str, result: LoadResult) -> None:
    gc_was_on = gc.isenabled()
    gc.disable()  # tens of thousands of new objects, no cycles: collections would only cost time
    try:
        if not _load_three_line_file(lines, source, result):
            _load_lines(lines, source, result)
    finally:
        if gc_was_on:
            gc.enable()


def _load_three_line_file(lines: list[str], source: str, result: LoadResult) -> bool:
    """Load a file made only of (name, line 1, line 2) triples, CelesTrak's usual form, in bulk.

    Returns False, having loaded nothing, when the file is anything else; :func:`_load_lines`
    then reads it line by line.  The tests below are the ones that line-by-line reading applies
    to such a file, so both ways give the same sets and rejections.
    """
    while lines and not lines[-1].strip():
        lines = lines[:-1]
    if not lines or len(lines) % 3:
        return False
    names, ones, twos = lines[0::3], [x.rstrip() for x in lines[1::3]], lines[2::3]
    match = TLE_LIKE.match
    if not (all([x.startswith("1 ") and match(x) for x in ones]) and all([x.startswith("2") for x in twos])
            and all([_could_be_name(x) and not x.startswith("2 ") for x in names])):
        return False
    all_names = "\n".join(names)  # AMSAT and CSV headers need a colon or a column name: rare, tested one by one
    if (":" in all_names and any([amsat.is_satellite_line(x) for x in names])) or (
            "NORAD_CAT_ID" in all_names and any([is_csv_header(x) for x in names])):
        return False
    pending: list[Any] = [(sanitize_element_name(_clean_name(name)), 3 * k + 1, one, two.rstrip())
                     for k, (name, one, two) in enumerate(zip(names, ones, twos))]
    _build_tles(pending, source, result)
    return True


def _load_lines(lines: list[str], source: str, result: LoadResult) -> None:
    i = 0
    n = len(lines)
    pending: list[Any] = []  # TLE pairs (and their structural rejections) not yet built, in file order
    while i < n:
        line = lines[i].rstrip()
        if TLE_LIKE.match(line):
            i = _take_tle(lines, i, source, pending)
            continue
        if amsat.is_satellite_line(line):
            _build_tles(pending, source, result)
            i = _take_amsat(lines, i, source, result)
            continue
        if is_csv_header(line):
            _build_tles(pending, source, result)
            i = _take_csv(lines, i, source, result)
            continue
        i += 1
    _build_tles(pending, source, result)


#: What building a set from hostile values can raise besides TleError (sgp4, float/int conversion).
_BAD_VALUE = (ValueError, ArithmeticError, TypeError, RuntimeError)


def _accept(result: LoadResult, source: str, line: int, prefix: str, build: Callable[[], ElementSet]) -> None:
    """Append ``build()`` to the sets, or a :class:`Rejection` with its reason: one bad set never stops a load."""
    try:
        result.sets.append(build())
    except TleError as exc:
        result.rejected.append(Rejection(source, line, f"{prefix}{exc}"))
    except _BAD_VALUE as exc:  # sgp4 refusing values that passed our checks, or an unforeseen conversion
        result.rejected.append(Rejection(source, line, f"{prefix}these elements cannot be used ({exc})"))


def _take_tle(lines: list[str], i: int, source: str, pending: list[Any]) -> int:
    """Queue the TLE pair at ``lines[i]`` (with its name line) or its structural rejection."""
    line1 = lines[i].rstrip()
    name = ""
    start = i + 1
    if i > 0 and _could_be_name(lines[i - 1]) and not lines[i - 1].startswith("2 "):
        name = sanitize_element_name(_clean_name(lines[i - 1]))
        start = i
    if not line1.startswith("1 "):
        pending.append(Rejection(source, i + 1, "TLE line 2 without a preceding line 1"))
        return i + 1
    if i + 1 >= len(lines) or not lines[i + 1].startswith("2"):
        pending.append(Rejection(source, i + 1, "TLE line 1 without a following line 2"))
        return i + 1
    pending.append((name, start, line1, lines[i + 1].rstrip()))
    return i + 2


def _build_tles(pending: list[Any], source: str, result: LoadResult) -> None:
    """Build the queued TLE sets: canonical ones checked and read in bulk (:mod:`~nfwserver.tracking.tle_bulk`),
    the rest one by one by :func:`~nfwserver.tracking.tle.parse_tle`, which names what is wrong.  1024 at a
    time: the temporary values of a block are freed before the next (a catalog's would take ~8 MiB)."""
    years: dict[int, datetime] = {}
    for b0 in range(0, len(pending), 1024):
        _build_block(pending[b0 : b0 + 1024], source, result, years)
    pending.clear()


def _build_block(pending: list[Any], source: str, result: LoadResult, years: dict[int, datetime]) -> None:
    pairs = [p for p in pending if not isinstance(p, Rejection)]
    rows: Any = iter(())
    good_list = [False] * len(pairs)
    if len(pairs) >= _BULK_MIN or "numpy" in sys.modules:  # else no numpy to import (a command for one satellite)
        from nfwserver.tracking.tle_bulk import read_canonical

        good, values = read_canonical([p[2] for p in pairs], [p[3] for p in pairs])
        rows = zip(*(values[c].tolist() for c in _BULK_COLUMNS)) if values else iter(())
        good_list = good.tolist()
    k = 0
    for item in pending:
        if isinstance(item, Rejection):
            result.rejected.append(item)
            continue
        name, start, line1, line2 = item
        row = next(rows, None)
        if good_list[k] and row is not None:
            # Checked like parse_tle would, so twoline2rv accepts it when the model is first used.
            year2, day, cat = row
            base = years.get(year2)
            if base is None:
                base = years[year2] = epoch_from_tle(year2, 1.0)
            element_set = ElementSetDraft(name, cat, base + timedelta(days=day - 1.0), line1, line2, source, start)
            element_set.__class__ = ElementSet
            result.sets.append(element_set)
            k += 1
            continue
        k += 1

        def build(name: str = name, line1: str = line1, line2: str = line2, start: int = start) -> ElementSet:
            return ElementSet.from_fields(name, parse_tle(line1, line2), source, start, lines=(line1, line2))

        _accept(result, source, start, f"{name}: " if name else "", build)


#: Columns of tle_bulk.read_canonical a set keeps as values (the others are read from its lines when asked).
_BULK_COLUMNS = ("year2", "day", "catalog_number")
#: Fewest TLE pairs of a block read in bulk (numpy, 12 us a set) unless numpy is loaded already; fewer are read by
#: parse_tle (67 us a set), which gives the same values: below this, importing numpy (60-90 ms) costs more.
_BULK_MIN = 768


def _take_amsat(lines: list[str], i: int, source: str, result: LoadResult) -> int:
    name = sanitize_element_name(lines[i].partition(":")[2])
    start = i
    body: list[str] = []
    i += 1
    while i < len(lines):
        line = lines[i].rstrip()
        if amsat.is_satellite_line(line) or TLE_LIKE.match(line):
            break
        if not line.strip():
            # A blank line right after "Satellite:" (the ARRL layout) does not end the set.
            if any(":" in b for b in body):
                break
        else:
            body.append(line)
        i += 1

    def build() -> ElementSet:
        fields = amsat.parse_amsat_block(amsat.AmsatBlock(name, start + 1, body))
        return ElementSet.from_fields(name, fields, source, start + 1)

    _accept(result, source, start + 1, "", build)
    return i


def _take_csv(lines: list[str], i: int, source: str, result: LoadResult) -> int:
    """One CSV block: the header at ``lines[i]``, then rows, each parsed alone (one line per row)."""
    header = next(csv.reader([lines[i]]))
    i += 1
    while i < len(lines) and lines[i].strip() and lines[i].count(",") >= len(header) - 1:
        row_text, number = lines[i], i + 1
        i += 1
        if len(row_text) > MAX_CSV_ROW:
            result.rejected.append(Rejection(source, number, f"CSV row of {len(row_text)} characters is longer "
                                                             f"than {MAX_CSV_ROW}"))
            continue
        try:
            values = next(csv.reader([row_text]))
        except (csv.Error, StopIteration) as exc:
            result.rejected.append(Rejection(source, number, f"CSV row cannot be read ({exc})"))
            continue
        _add_omm(dict(zip(header, values)), source, number, result)
    return i


def _json_int(text: str) -> int | str:
    """JSON integers as ints, except absurdly long ones, kept as text so only their record is refused."""
    return int(text) if len(text) <= 30 else text


def _load_json(text: str, source: str, result: LoadResult) -> Rejection | None:
    """Load a JSON document; returns the problem instead when ``text`` is not JSON at all."""
    try:
        doc = json.loads(text, parse_int=_json_int)
    except (ValueError, RecursionError) as exc:
        line = getattr(exc, "lineno", 1)
        return Rejection(source, line, f"not valid JSON ({getattr(exc, 'msg', exc)})")
    records = doc if isinstance(doc, list) else [doc]
    for index, record in enumerate(records, start=1):  # entries are named by number, not by a line (line 0)
        if not isinstance(record, dict):
            result.rejected.append(Rejection(source, 0, f"JSON entry {index} is not an OMM object"))
            continue
        _add_omm(record, source, 0, result, what=f"JSON entry {index}")
    return None


def _add_omm(record: dict[str, Any], source: str, line: int, result: LoadResult, what: str = "") -> None:
    def build() -> ElementSet:
        name, fields = omm.omm_fields(record)
        return ElementSet.from_fields(name, fields, source, line)

    _accept(result, source, line, f"{what}: " if what else "", build)


def load_element_file(path: str | os.PathLike[str]) -> LoadResult:
    """Load a file; an unreadable file gives one :class:`Rejection` of the whole file (line 0, shown without a
    line), never an exception."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        reason = (exc.strerror or str(exc)).lower()
        return LoadResult(rejected=[Rejection(str(path), 0, f"cannot read the file ({reason})")])
    return load_elements(data, source=str(path))
