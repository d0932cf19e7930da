"""AMSAT "verbose" element sets, as InstantTrack reads them.

A set starts at a line containing ``Satellite:`` and ends at a blank line (or the next
``Satellite:`` line).  Every other line is searched for a keyword and a number; the order is free
and unknown lines (period, beacon, commentary) are ignored.  Example::

    Satellite: AO-10
    Catalog number: 14129
    Epoch time:      88248.53312992
    Element set:     353
    Inclination:       27.1605 deg
    RA of node:       306.2255 deg
    Eccentricity:    0.6029797
    Arg of perigee:   333.9978 deg
    Mean anomaly:       5.4273 deg
    Mean motion:    2.05877131 rev/day
    Decay rate:        4.4e-07 rev/day sq
    Epoch rev:            3933

The epoch is ``YYDDD.DDDDDDDD`` (also ``YY DDD.DDD`` or a four-digit year); the decay rate is the
first derivative of mean motion divided by two (rev/day^2), the same quantity as the TLE's field.
A ``Checksum:`` line may end the set; its algorithm is not published, so it is recognised and
not verified.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from datetime import datetime

from nfwserver.tracking.tle import TleError, TleFields, check_ranges, epoch_from_tle

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", re.ASCII)

# (field, keywords): the first keyword contained in the lower-cased label decides the field.
_KEYWORDS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("checksum", ("checksum",)),
    ("rev", ("epoch rev", "k0", "rev at epoch", "orbit number")),
    ("epoch", ("epoch time", "epoch", "t0")),
    ("element_set", ("element set",)),
    ("designator", ("nasa designation", "international designator", "intl designator", "cospar")),
    ("catalog", ("catalog number", "object number", "norad", "cat. no", "catalog no", "satellite number")),
    ("inclination", ("inclination", "i0")),
    ("raan", ("ra of node", "raan", "right ascension", "o0")),
    ("eccentricity", ("eccentricity", "e0")),
    ("argp", ("arg of perigee", "arg perigee", "argument of perigee", "w0")),
    ("mean_anomaly", ("mean anomaly", "m0")),
    ("mean_motion", ("mean motion", "n0")),
    ("decay", ("decay", "n1")),
    ("bstar", ("bstar", "drag")),
)

_REQUIRED = ("catalog", "epoch", "inclination", "raan", "eccentricity", "argp", "mean_anomaly", "mean_motion")


@dataclass
class AmsatBlock:
    """The raw lines of one verbose set and where it started (1-based line number)."""

    name: str
    line_number: int
    lines: list[str]


def is_satellite_line(line: str) -> bool:
    """True for the line that opens a verbose set (``Satellite: NAME``)."""
    label, sep, _ = line.partition(":")
    return bool(sep) and label.strip().lower() == "satellite"


def _field_of(label: str) -> str | None:
    label = label.strip().lower()
    for field, keys in _KEYWORDS:
        for key in keys:
            if len(key) <= 2:
                if re.search(rf"(^|[\s,]){re.escape(key)}$", label):
                    return field
            elif key in label:
                return field
    return None


def _epoch(text: str) -> datetime:
    parts = text.split()
    if len(parts) >= 2 and parts[0].isascii() and parts[0].isdigit() and _NUMBER.fullmatch(parts[1]):
        year, day = int(parts[0]), float(parts[1])
    else:
        m = re.fullmatch(r"(\d{2}|\d{4})(\d{3}(?:\.\d*)?)", parts[0] if parts else "", re.ASCII)
        if not m:
            raise TleError(f"epoch {text!r} is not in the form YYDDD.DDDDDDDD")
        year, day = int(m.group(1)), float(m.group(2))
    if year >= 1900:
        year %= 100
    if not 1.0 <= day < 367.0:
        raise TleError(f"epoch day of year {day} is outside 1..366")
    return epoch_from_tle(year, day)


def parse_amsat_block(block: AmsatBlock) -> TleFields:
    """Values of one verbose set; raises :class:`TleError` for missing or implausible values."""
    values: dict[str, str] = {}
    for raw in block.lines:
        label, sep, rest = raw.partition(":")
        if not sep:
            continue
        field = _field_of(label)
        if field is None or field in values:
            continue
        rest = rest.strip()
        if field == "designator":
            values[field] = rest.split()[0] if rest else ""
            continue
        if field == "epoch":
            values[field] = rest
            continue
        m = _NUMBER.search(rest)
        if m:
            values[field] = m.group(0)
    missing = [f for f in _REQUIRED if f not in values]
    if missing:
        raise TleError(f"AMSAT set {block.name!r} lacks {', '.join(m.replace('_', ' ') for m in missing)}")
    try:
        catalog = int(float(values["catalog"]))
        fields = TleFields(
            catalog_number=catalog,
            classification="U",
            international_designator=_designator(values.get("designator", "")),
            epoch=_epoch(values["epoch"]),
            mean_motion_dot=float(values.get("decay", 0.0)),
            mean_motion_ddot=0.0,
            bstar=float(values.get("bstar", 0.0)),
            ephemeris_type=0,
            element_number=int(float(values.get("element_set", 0))) % 10000,
            inclination_deg=float(values["inclination"]),
            raan_deg=float(values["raan"]),
            eccentricity=float(values["eccentricity"]),
            arg_perigee_deg=float(values["argp"]),
            mean_anomaly_deg=float(values["mean_anomaly"]),
            mean_motion_rev_per_day=float(values["mean_motion"]),
            rev_number=int(float(values.get("rev", 0))),
        )
    except (ValueError, OverflowError) as exc:
        raise TleError(f"AMSAT set {block.name!r} has an unreadable value ({exc})") from None
    if not 0 < catalog <= 339_999:
        raise TleError(f"catalog number {catalog} is outside 1..339999")
    check_ranges(fields)
    return fields


def _designator(text: str) -> str:
    """``1983-058B`` -> ``83058B`` (the TLE's form); already-short forms pass through."""
    m = re.fullmatch(r"(\d{2})?(\d{2})-?(\d{3})([A-Z]{0,3})", text.strip().upper(), re.ASCII)
    if not m:
        return ""
    return f"{m.group(2)}{m.group(3)}{m.group(4)}"
