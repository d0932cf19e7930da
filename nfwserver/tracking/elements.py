"""Loading orbital element sets from text in any of the formats stations meet.

Accepted, in any mixture within one file: NORAD TLEs with or without a name line (2-line and
3-line forms; CelesTrak's ``0 NAME`` name lines too), AMSAT verbose sets
(:mod:`nfwserver.tracking.amsat`), and CCSDS OMM as CelesTrak's JSON (a whole file) or CSV (a
header row, then one row per set).  Lines belonging to none of them are skipped silently, except
lines that look like a broken TLE line, which are reported.

Every set becomes an :class:`ElementSet` whose SGP4 model is initialised from canonical TLE lines,
so a satellite propagates identically whichever format it came in.  Nothing in here raises for
bad content: each rejected set is a :class:`Rejection` with its line number and one-sentence
reason.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

from sgp4.api import WGS72, Satrec

from nfwserver.tracking import amsat, omm
from nfwserver.tracking.tle import TleError, TleFields, format_tle, parse_tle


@dataclass(frozen=True, slots=True)
class ElementSet:
    """One satellite's mean elements at an epoch, with its initialised SGP4 model (slots: catalogs
    hold tens of thousands)."""

    name: str  #: name as given ("ISS (ZARYA)"), stripped; "" when the set had none
    catalog_number: int
    international_designator: str
    epoch: datetime  #: aware UTC
    inclination_deg: float
    raan_deg: float
    eccentricity: float
    arg_perigee_deg: float
    mean_anomaly_deg: float
    mean_motion_rev_per_day: float
    bstar: float  #: 1/earth radii
    rev_number: int  #: revolution number at epoch
    line1: str  #: canonical TLE line 1 (generated for AMSAT and OMM input)
    line2: str
    satrec: Satrec = field(compare=False, repr=False)
    source: str = ""
    line_number: int = 0  #: 1-based line where the set started in ``source``

    @classmethod
    def from_fields(cls, name: str, fields: TleFields, source: str = "", line_number: int = 0,
                    lines: tuple[str, str] | None = None) -> ElementSet:
        """Build from parsed values; ``lines`` are the original TLE lines when there were any."""
        line1, line2 = lines if lines is not None else format_tle(fields)
        satrec = Satrec.twoline2rv(line1, line2, WGS72)
        return cls(
            name=name, catalog_number=fields.catalog_number,
            international_designator=fields.international_designator, epoch=fields.epoch,
            inclination_deg=fields.inclination_deg, raan_deg=fields.raan_deg, eccentricity=fields.eccentricity,
            arg_perigee_deg=fields.arg_perigee_deg, mean_anomaly_deg=fields.mean_anomaly_deg,
            mean_motion_rev_per_day=fields.mean_motion_rev_per_day, bstar=fields.bstar,
            rev_number=fields.rev_number, line1=line1, line2=line2, satrec=satrec, source=source,
            line_number=line_number,
        )

    def tle_text(self) -> str:
        """The set as three lines (name, line 1, line 2), newline-terminated."""
        return f"{self.name or self.catalog_number}\n{self.line1}\n{self.line2}\n"


@dataclass(frozen=True)
class Rejection:
    """A set that was not loaded: where it started and why."""

    source: str
    line_number: int
    reason: str

    def __str__(self) -> str:
        return f"{self.source} line {self.line_number}: {self.reason}"


@dataclass
class LoadResult:
    """What a load found: the accepted sets (file order) and the rejections."""

    sets: list[ElementSet] = field(default_factory=list)
    rejected: list[Rejection] = field(default_factory=list)


# A line that claims to be a TLE line: line number, blank, 5-character catalog field.
_TLE_LIKE = re.compile(r"^[12] [0-9A-Z ]{4}[0-9]")
_MAX_NAME = 40


def _clean_name(line: str) -> str:
    name = line.strip()
    if name.startswith("0 "):
        name = name[2:].strip()
    return name


def _could_be_name(line: str) -> bool:
    text = line.strip()
    return 0 < len(text) <= _MAX_NAME + 2 and not _TLE_LIKE.match(text) and text.isprintable()


def load_elements(data: str | bytes, source: str = "<text>") -> LoadResult:
    """Load every element set in ``data``; never raises for bad content (see module docstring)."""
    result = LoadResult()
    if isinstance(data, bytes):
        data = data.decode("utf-8", errors="replace")
    stripped = data.lstrip("\ufeff \t\r\n")
    if stripped.startswith(("[", "{")):
        _load_json(stripped, source, result)
        return result
    lines = data.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    i = 0
    n = len(lines)
    while i < n:
        line = lines[i].rstrip()
        if _TLE_LIKE.match(line):
            i = _take_tle(lines, i, source, result)
            continue
        if amsat.is_satellite_line(line):
            i = _take_amsat(lines, i, source, result)
            continue
        if "NORAD_CAT_ID" in line and "MEAN_MOTION" in line and "," in line:
            i = _take_csv(lines, i, source, result)
            continue
        i += 1
    return result


def _take_tle(lines: list[str], i: int, source: str, result: LoadResult) -> int:
    line1 = lines[i].rstrip()
    name = ""
    start = i + 1
    if i > 0 and _could_be_name(lines[i - 1]) and not lines[i - 1].startswith("2 "):
        name = _clean_name(lines[i - 1])
        start = i
    if not line1.startswith("1 "):
        result.rejected.append(Rejection(source, i + 1, "TLE line 2 without a preceding line 1"))
        return i + 1
    if i + 1 >= len(lines) or not lines[i + 1].startswith("2"):
        result.rejected.append(Rejection(source, i + 1, "TLE line 1 without a following line 2"))
        return i + 1
    line2 = lines[i + 1].rstrip()
    try:
        fields = parse_tle(line1, line2)
        result.sets.append(
            ElementSet.from_fields(name, fields, source, start, lines=(line1.rstrip(), line2.rstrip()))
        )
    except TleError as exc:
        result.rejected.append(Rejection(source, start, f"{name + ': ' if name else ''}{exc}"))
    except (ValueError, RuntimeError) as exc:  # sgp4 refusing values that passed our checks
        result.rejected.append(Rejection(source, start, f"SGP4 cannot initialise these elements ({exc})"))
    return i + 2


def _take_amsat(lines: list[str], i: int, source: str, result: LoadResult) -> int:
    name = lines[i].partition(":")[2].strip()
    start = i
    body = []
    i += 1
    while i < len(lines):
        line = lines[i].rstrip()
        if amsat.is_satellite_line(line) or _TLE_LIKE.match(line):
            break
        if not line.strip():
            # A blank line right after "Satellite:" (the ARRL layout) does not end the set.
            if any(":" in b for b in body):
                break
        else:
            body.append(line)
        i += 1
    try:
        fields = amsat.parse_amsat_block(amsat.AmsatBlock(name, start + 1, body))
        result.sets.append(ElementSet.from_fields(name, fields, source, start + 1))
    except TleError as exc:
        result.rejected.append(Rejection(source, start + 1, str(exc)))
    return i


def _take_csv(lines: list[str], i: int, source: str, result: LoadResult) -> int:
    start = i
    header = lines[i]
    columns = header.count(",")
    block = [header]
    i += 1
    while i < len(lines) and lines[i].strip() and lines[i].count(",") >= columns:
        block.append(lines[i])
        i += 1
    reader = csv.DictReader(io.StringIO("\n".join(block)))
    for offset, row in enumerate(reader, start=2):
        _add_omm(row, source, start + offset, result)
    return i


def _load_json(text: str, source: str, result: LoadResult) -> None:
    try:
        doc = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        line = getattr(exc, "lineno", 1)
        result.rejected.append(Rejection(source, line, f"not valid JSON ({getattr(exc, 'msg', exc)})"))
        return
    records = doc if isinstance(doc, list) else [doc]
    for index, record in enumerate(records, start=1):
        if not isinstance(record, dict):
            result.rejected.append(Rejection(source, 1, f"JSON entry {index} is not an OMM object"))
            continue
        _add_omm(record, source, index, result, what=f"JSON entry {index}")


def _add_omm(record: dict, source: str, line: int, result: LoadResult, what: str = "") -> None:
    try:
        name, fields = omm.omm_fields(record)
        result.sets.append(ElementSet.from_fields(name, fields, source, line))
    except TleError as exc:
        prefix = f"{what}: " if what else ""
        result.rejected.append(Rejection(source, line, prefix + str(exc)))


def load_element_file(path: str | os.PathLike) -> LoadResult:
    """Load a file; an unreadable file gives one :class:`Rejection` (line 0), never an exception."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        return LoadResult(rejected=[Rejection(str(path), 0, f"cannot read the file ({exc.strerror or exc})")])
    return load_elements(data, source=str(path))
