"""NORAD two-line element (TLE) lines: checksum, Alpha-5 catalog numbers, parsing and formatting.

Column layout (1-based, inclusive), as published by NORAD/CelesTrak:

Line 1: 1 line number; 3-7 catalog number; 8 classification; 10-17 international designator;
19-32 epoch (2-digit year, day of year with fraction); 34-43 first derivative of mean motion / 2
(rev/day^2); 45-52 second derivative / 6 (rev/day^3, assumed-decimal exponent form); 54-61 BSTAR
(1/earth radii, same form); 63 ephemeris type; 65-68 element set number; 69 checksum.

Line 2: 1 line number; 3-7 catalog number; 9-16 inclination (deg); 18-25 right ascension of the
ascending node (deg); 27-33 eccentricity (decimal point assumed); 35-42 argument of perigee (deg);
44-51 mean anomaly (deg); 53-63 mean motion (rev/day); 64-68 revolution number at epoch; 69 checksum.

The checksum is the sum of the line's first 68 characters, digits counting their value and
``-`` counting 1, modulo 10.  Alpha-5 numbers replace the first digit of a catalog number above
99,999 by a letter (A=10 ... Z=33, skipping I and O).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone

_ALPHA5 = "ABCDEFGHJKLMNPQRSTUVWXYZ"  # 10..33
_EXP_FIELD = re.compile(r"^([ +-]?)(\d{1,5})([+-])(\d)$")
MAX_CATALOG_NUMBER = 339_999


class TleError(ValueError):
    """A TLE line or set that cannot be accepted; the message is one clear sentence."""


def tle_checksum(line: str) -> int:
    """Mod-10 checksum of the first 68 characters of ``line``: the sum of its digits, minus signs
    counting 1 (one ``str.count`` per digit value instead of a loop over characters)."""
    head = line[:68]
    total = head.count("-")
    for digit, text in _DIGITS:
        total += digit * head.count(text)
    return total % 10


_DIGITS = tuple((d, str(d)) for d in range(1, 10))


def decode_catalog_number(field: str) -> int:
    """Catalog number from a 5-character field, decimal or Alpha-5."""
    field = field.strip()
    if not field:
        raise TleError("the catalog number is blank")
    if field.isdigit():
        return int(field)
    head, tail = field[0].upper(), field[1:]
    if head in _ALPHA5 and len(tail) == 4 and tail.isdigit():
        return (10 + _ALPHA5.index(head)) * 10000 + int(tail)
    raise TleError(f"catalog number {field!r} is neither decimal nor Alpha-5")


def encode_catalog_number(number: int) -> str:
    """Five-character catalog number field (Alpha-5 above 99,999)."""
    if not 0 <= number <= MAX_CATALOG_NUMBER:
        raise TleError(f"catalog number {number} is outside 0..{MAX_CATALOG_NUMBER}")
    if number < 100000:
        return f"{number:05d}"
    return _ALPHA5[number // 10000 - 10] + f"{number % 10000:04d}"


def exponent_field(text: str, what: str) -> float:
    """Value of an assumed-decimal exponent field like `` 12345-3`` (= 0.12345e-3)."""
    text = text.strip()
    if not text:
        return 0.0
    m = _EXP_FIELD.match(text)
    if not m:
        raise TleError(f"{what} field {text!r} is not in the form ±NNNNN±E")
    sign = -1.0 if m.group(1) == "-" else 1.0
    mantissa = int(m.group(2)) / 10 ** len(m.group(2))
    exponent = int(m.group(4)) * (-1 if m.group(3) == "-" else 1)
    return float(sign * mantissa * 10.0**exponent)


def _format_exp(value: float) -> str:
    """Eight-character assumed-decimal exponent field for ``value``."""
    if value == 0.0:
        return " 00000+0"
    sign = "-" if value < 0 else " "
    mag = abs(value)
    exponent = math.floor(math.log10(mag)) + 1
    mantissa = round(mag / 10.0**exponent * 1e5)
    if mantissa >= 100000:
        mantissa //= 10
        exponent += 1
    if not -9 <= exponent <= 9:
        if exponent < -9:
            return " 00000+0"
        raise TleError(f"value {value} is too large for an exponent field")
    return f"{sign}{mantissa:05d}{'-' if exponent < 0 else '+'}{abs(exponent)}"


def _float(text: str, what: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise TleError(f"{what} {text.strip()!r} is not a number") from None
    if not math.isfinite(value):
        raise TleError(f"{what} {text.strip()!r} is not finite")
    return value


def epoch_from_tle(year2: int, day_of_year: float) -> datetime:
    """UTC epoch from the TLE's 2-digit year (57-99 = 1900s) and fractional day of year (1 = Jan 1 0h)."""
    year = 1900 + year2 if year2 >= 57 else 2000 + year2
    return datetime(year, 1, 1, tzinfo=timezone.utc) + timedelta(days=day_of_year - 1.0)


def epoch_to_tle(epoch: datetime) -> tuple[int, float]:
    """(2-digit year, fractional day of year) of a UTC epoch, inverse of :func:`epoch_from_tle`."""
    epoch = epoch.astimezone(timezone.utc)
    start = datetime(epoch.year, 1, 1, tzinfo=timezone.utc)
    return epoch.year % 100, 1.0 + (epoch - start).total_seconds() / 86400.0


@dataclass(frozen=True)
class TleFields:
    """The values of one TLE, in the units of the format (degrees, rev/day, ...)."""

    catalog_number: int
    classification: str
    international_designator: str
    epoch: datetime
    mean_motion_dot: float  #: first derivative / 2, rev/day^2
    mean_motion_ddot: float  #: second derivative / 6, rev/day^3
    bstar: float  #: 1/earth radii
    ephemeris_type: int
    element_number: int
    inclination_deg: float
    raan_deg: float
    eccentricity: float
    arg_perigee_deg: float
    mean_anomaly_deg: float
    mean_motion_rev_per_day: float
    rev_number: int


def check_ranges(f: TleFields) -> None:
    """Raise :class:`TleError` when a value is outside its physically plausible range."""
    checks = (
        (0.0 <= f.inclination_deg <= 180.0, f"inclination {f.inclination_deg} deg is outside 0..180"),
        (0.0 <= f.raan_deg < 360.0 + 1e-9, f"right ascension of the node {f.raan_deg} deg is outside 0..360"),
        (0.0 <= f.eccentricity < 1.0, f"eccentricity {f.eccentricity} is outside 0..1"),
        (0.0 <= f.arg_perigee_deg < 360.0 + 1e-9, f"argument of perigee {f.arg_perigee_deg} deg is outside 0..360"),
        (0.0 <= f.mean_anomaly_deg < 360.0 + 1e-9, f"mean anomaly {f.mean_anomaly_deg} deg is outside 0..360"),
        (1e-6 <= f.mean_motion_rev_per_day <= 20.0,
         f"mean motion {f.mean_motion_rev_per_day} rev/day is outside 1e-6..20"),
        (f.rev_number >= 0, f"revolution number {f.rev_number} is negative"),
        # Values a TLE can hold (non-finite ones fail every comparison): anything else could not be
        # stored and read back.
        (abs(f.mean_motion_dot) < 1.0, f"first derivative of mean motion {f.mean_motion_dot} is outside ±1"),
        (abs(f.mean_motion_ddot) < 1e9, f"second derivative of mean motion {f.mean_motion_ddot} is outside ±1e9"),
        (abs(f.bstar) < 1e9, f"BSTAR {f.bstar} is outside ±1e9"),
        (1957 <= f.epoch.year <= 2056, f"epoch {f.epoch:%Y-%m-%d} is outside the TLE's years 1957..2056"),
    )
    for ok, message in checks:
        if not ok:
            raise TleError(message)


def parse_tle(line1: str, line2: str) -> TleFields:
    """Parse and check a pair of TLE lines (trailing blanks and CR allowed).

    Raises :class:`TleError` naming the first problem: wrong length, non-ASCII, wrong line
    number, bad checksum, mismatched catalog numbers, unreadable or implausible values.
    """
    lines = []
    for number, raw in ((1, line1), (2, line2)):
        line = raw.rstrip("\r\n ")
        if not line.isascii():
            raise TleError(f"line {number} contains non-ASCII characters")
        if len(line) != 69:
            raise TleError(f"line {number} has {len(line)} characters, expected 69")
        if line[0] != str(number) or line[1] != " ":
            raise TleError(f"line {number} does not start with '{number} '")
        if not line[68].isdigit():
            raise TleError(f"line {number} has no checksum digit in column 69")
        expected = tle_checksum(line)
        if int(line[68]) != expected:
            raise TleError(f"line {number} checksum is {line[68]}, computed {expected}")
        lines.append(line)
    l1, l2 = lines
    cat1 = decode_catalog_number(l1[2:7])
    cat2 = decode_catalog_number(l2[2:7])
    if cat1 != cat2:
        raise TleError(f"catalog numbers differ between line 1 ({cat1}) and line 2 ({cat2})")
    year_text = l1[18:20]
    if not year_text.strip().isdigit():
        raise TleError(f"epoch year {year_text!r} is not a number")
    day = _float(l1[20:32], "epoch day")
    if not 1.0 <= day < 367.0:
        raise TleError(f"epoch day of year {day} is outside 1..366")
    ecc_text = l2[26:33].strip()
    if not ecc_text.isdigit():
        raise TleError(f"eccentricity field {l2[26:33]!r} is not digits")
    try:
        element_number = int(l1[64:68].strip() or 0)
        ephemeris_type = int(l1[62].strip() or 0)
        rev_text = l2[63:68].strip()
        rev_number = int(rev_text) if rev_text else 0
    except ValueError:
        raise TleError("element set number, ephemeris type or revolution number is not an integer") from None
    fields = TleFields(
        catalog_number=cat1,
        classification=l1[7] if l1[7] != " " else "U",
        international_designator=l1[9:17].strip(),
        epoch=epoch_from_tle(int(year_text), day),
        mean_motion_dot=_float(l1[33:43], "first derivative of mean motion"),
        mean_motion_ddot=exponent_field(l1[44:52], "second derivative of mean motion"),
        bstar=exponent_field(l1[53:61], "BSTAR"),
        ephemeris_type=ephemeris_type,
        element_number=element_number,
        inclination_deg=_float(l2[8:16], "inclination"),
        raan_deg=_float(l2[17:25], "right ascension of the node"),
        eccentricity=int(ecc_text) / 10 ** len(ecc_text),
        arg_perigee_deg=_float(l2[34:42], "argument of perigee"),
        mean_anomaly_deg=_float(l2[43:51], "mean anomaly"),
        mean_motion_rev_per_day=_float(l2[52:63], "mean motion"),
        rev_number=rev_number,
    )
    check_ranges(fields)
    return fields


def _with_checksum(body: str) -> str:
    assert len(body) == 68, body
    return body + str(tle_checksum(body))


def format_tle(f: TleFields) -> tuple[str, str]:
    """The two canonical 69-character lines of ``f``, with checksums."""
    check_ranges(f)
    year2, day = epoch_to_tle(f.epoch)
    day_text = f"{day:012.8f}"
    if day_text.startswith("367") or float(day_text) >= 367.0:
        raise TleError("epoch day does not fit the TLE field")
    ndot_value = round(f.mean_motion_dot, 8) + 0.0  # + 0.0 turns -0.0 into 0.0
    ndot = ("-" if ndot_value < 0 else " ") + f"{abs(ndot_value):.8f}".lstrip("0")
    if len(ndot) > 10:
        raise TleError(f"first derivative of mean motion {f.mean_motion_dot} does not fit the TLE field")
    cat = encode_catalog_number(f.catalog_number)
    l1 = (
        f"1 {cat}{(f.classification or 'U')[0]} {f.international_designator[:8]:<8} "
        f"{year2:02d}{day_text} {ndot:>10} {_format_exp(f.mean_motion_ddot)} {_format_exp(f.bstar)} "
        f"{f.ephemeris_type % 10:1d} {f.element_number % 10000:4d}"
    )
    ecc = f"{round(f.eccentricity * 1e7):07d}"
    if len(ecc) > 7:
        raise TleError(f"eccentricity {f.eccentricity} does not fit the TLE field")
    l2 = (
        f"2 {cat} {f.inclination_deg:8.4f} {f.raan_deg % 360.0:8.4f} {ecc} "
        f"{f.arg_perigee_deg % 360.0:8.4f} {f.mean_anomaly_deg % 360.0:8.4f} "
        f"{f.mean_motion_rev_per_day:11.8f}{f.rev_number % 100000:5d}"
    )
    return _with_checksum(l1), _with_checksum(l2)
