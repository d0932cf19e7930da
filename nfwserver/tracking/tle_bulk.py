"""Many TLE pairs checked and read at once (numpy), for loading whole catalogs quickly.

:func:`read_canonical` takes the lines of many sets and returns, for each, whether it is in the
canonical fixed-column layout that CelesTrak and Space-Track publish (see
:mod:`nfwserver.tracking.tle` for the columns) with a correct checksum and plausible values; and,
for those, the values as arrays.  It accepts only sets that :func:`nfwserver.tracking.tle.parse_tle`
also accepts, and gives bit-for-bit the same values: fixed-point fields are read as an integer
mantissa divided by an exact power of ten (correctly rounded, like ``float()``), exponent fields
as ``sign * mantissa * 10.0 ** exponent`` with the same powers.  Every other set (unusual
spacing, a bad checksum, an implausible value) is left to ``parse_tle``, which accepts it or
names its problem; so this module only ever makes loading faster, never more lenient.

How: each line becomes a row of bytes.  One table lookup classifies every byte (digit, blank,
sign, point, other) and another says which classes each column may hold; runs of blank-padded
digits are checked for a digit before a blank.  All numeric fields of a line are then read by one
integer matrix product of its digit values with a table of column weights (powers of ten); the
integers, all below 2**53, become floats exactly.  (A float product would go to BLAS, whose
threads then keep spinning on the other cores.)  Lines are read in blocks of ``_ROWS``, which
bounds the temporary arrays.

Units are those of the format: degrees, rev/day, day of year, 1/earth radii.
"""

from __future__ import annotations

import numpy as np

_POW10 = np.array([10.0**e for e in range(-9, 10)])  # Python's powers, as parse_tle uses them
_ALPHA5 = np.full(256, -1, dtype=np.int64)  # value of an Alpha-5 leading letter, -1 for other bytes
_ALPHA5[np.frombuffer(b"ABCDEFGHJKLMNPQRSTUVWXYZ", dtype=np.uint8)] = np.arange(10, 34)
#: Pairs read per round: bounds the temporary arrays (about a megabyte each) whatever the catalog's size.
_ROWS = 2048

# Byte classes, and for each line the classes every column may hold ("*" any).
_OTHER, _DIGIT, _BLANK, _PLUS, _MINUS, _POINT = range(6)
_CLASS = np.full(256, _OTHER, dtype=np.uint8)
_CLASS[48:58] = _DIGIT
_CLASS[[32, 43, 45, 46]] = [_BLANK, _PLUS, _MINUS, _POINT]
_CLASS_BIT = (1 << _CLASS).astype(np.uint8)
_DIGIT_VALUE = np.where(_CLASS == _DIGIT, np.arange(256) - 48, 0).astype(np.int64)  # other bytes read 0
_CHECK_VALUE = (np.where(_CLASS == _DIGIT, np.arange(256) - 48, 0) + (np.arange(256) == 45)).astype(np.uint8)
_KEYS = {"d": (_DIGIT,), "b": (_BLANK,), "p": (_DIGIT, _BLANK), ".": (_POINT,), "s": (_BLANK, _PLUS, _MINUS),
         "e": (_PLUS, _MINUS), "*": tuple(range(6))}
# Column by column (0-based), what canonical lines hold: d digit, b blank, p blank or digit (blank padding),
# . point, s blank/plus/minus sign, e exponent sign, * not checked here (line number, catalog letter,
# classification, designator: tested apart or not needed for the values).
_LAYOUT1 = "*b*dddd" + "*" * 11 + "ddppd.dddddddd" + "*s.dddddddd" + "*sddddded" + "*sddddded" + "*p*ppppd"
_LAYOUT2 = "*b*****" + "*ppd.dddd" + "*ppd.dddd" + "*ddddddd" + "*ppd.dddd" + "*ppd.dddd" + "*pd.dddddddd" \
    + "pppppd"
#: Runs of blank-padded digits: no blank may follow a digit inside them.
_PADDED1, _PADDED2 = ((20, 23), (64, 68)), ((8, 11), (17, 20), (34, 37), (43, 46), (52, 54), (63, 68))


def _forbidden(layout: str) -> np.ndarray:
    """Per column, the bits (``1 << class``) of the byte classes it may not hold."""
    assert len(layout) == 69, layout
    return np.array([0x3F & ~sum(1 << c for c in _KEYS[key]) for key in layout], dtype=np.uint8)


def _pad_pairs(runs: tuple[tuple[int, int], ...]) -> np.ndarray:
    inside = np.zeros(68, dtype=bool)  # pair (i, i + 1) lies inside a padded run
    for lo, hi in runs:
        inside[lo : hi - 1] = True
    return inside


def _weights(fields: dict[str, tuple[tuple[int, int], ...]]) -> np.ndarray:
    """Column weights reading each field's digit columns (points skipped) as one integer."""
    table = np.zeros((69, len(fields)), dtype=np.int64)
    for k, spans in enumerate(fields.values()):
        cols = [c for lo, hi in spans for c in range(lo, hi)]
        table[cols, k] = 10 ** np.arange(len(cols) - 1, -1, -1, dtype=np.int64)
    return table


# Integer fields: (start, stop) column spans, read as one number with the point left out.
_FIELDS1 = {"tail": ((3, 7),), "year2": ((18, 20),), "day": ((20, 23), (24, 32)), "ndot": ((35, 43),),
            "nddot": ((45, 50),), "bstar": ((54, 59),)}
_FIELDS2 = {"inclination": ((8, 11), (12, 16)), "raan": ((17, 20), (21, 25)), "eccentricity": ((26, 33),),
            "arg_perigee": ((34, 37), (38, 42)), "mean_anomaly": ((43, 46), (47, 51)),
            "mean_motion": ((52, 54), (55, 63)), "rev_number": ((63, 68),)}
#: Divisors of the integer fields (powers of ten: a correctly rounded division, like ``float()``).
_SCALE = {"day": 1e8, "ndot": 1e8, "inclination": 1e4, "raan": 1e4, "eccentricity": 1e7, "arg_perigee": 1e4,
          "mean_anomaly": 1e4, "mean_motion": 1e8}
_LINES = ((_forbidden(_LAYOUT1), _pad_pairs(_PADDED1), _weights(_FIELDS1), tuple(_FIELDS1)),
          (_forbidden(_LAYOUT2), _pad_pairs(_PADDED2), _weights(_FIELDS2), tuple(_FIELDS2)))
_COLUMNS = ("catalog_number", "year2", "day", "ndot", "nddot", "bstar", "inclination", "raan", "eccentricity",
            "arg_perigee", "mean_anomaly", "mean_motion", "rev_number")
_INTEGER_COLUMNS = ("catalog_number", "year2", "rev_number")


def _read_line(rows: np.ndarray, which: int) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(layout and checksum right?, integer value of every field) of a block of line-``which + 1`` rows."""
    forbidden, pad_pairs, weights, names = _LINES[which]
    bits = _CLASS_BIT[rows]
    ok = ~(bits & forbidden).any(axis=1)
    ok &= ~((bits[:, :-1] == 1 << _DIGIT) & (bits[:, 1:] == 1 << _BLANK) & pad_pairs).any(axis=1)
    ok &= rows[:, 0] == 49 + which
    ok &= (_CHECK_VALUE[rows[:, :68]].sum(axis=1, dtype=np.int32) % 10) == rows[:, 68].astype(np.int32) - 48
    numbers = _DIGIT_VALUE[rows] @ weights  # integer product: numpy's own loop, no BLAS threads
    return ok, dict(zip(names, numbers.T.astype(np.float64)))


def _exponent(rows: np.ndarray, lo: int, mantissa: np.ndarray) -> np.ndarray:
    """Value of the assumed-decimal exponent field ``±NNNNN±E`` at column ``lo`` (mantissa already read)."""
    exp = rows[:, lo + 7].astype(np.int64) - 48
    e = np.where(rows[:, lo + 6] == 45, -exp, exp)
    values: np.ndarray = np.where(rows[:, lo] == 45, -1.0, 1.0) * (mantissa / 100000.0) * _POW10[np.clip(e, -9, 9) + 9]
    return values


def _read_block(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(accepted?, values) of one block of pairs: line 1 rows ``a``, line 2 rows ``b`` (bytes)."""
    ok1, one = _read_line(a, 0)
    ok2, two = _read_line(b, 1)
    head = a[:, 2]  # catalog number: a digit or an Alpha-5 letter (A=10 ... Z=33, no I or O), then 4 digits
    lead = np.where((head >= 48) & (head <= 57), head.astype(np.int64) - 48, _ALPHA5[head])
    ok = ok1 & ok2 & (lead >= 0) & (a[:, 2:7] == b[:, 2:7]).all(axis=1)
    values = {name: two[name] / _SCALE[name] for name in _FIELDS2 if name in _SCALE}
    values.update(day=one["day"] / 1e8, nddot=_exponent(a, 44, one["nddot"]), bstar=_exponent(a, 53, one["bstar"]),
                  ndot=np.where(a[:, 33] == 45, -1.0, 1.0) * (one["ndot"] / 1e8),
                  catalog_number=lead * 10000 + one["tail"].astype(np.int64),
                  year2=one["year2"].astype(np.int64), rev_number=two["rev_number"].astype(np.int64))
    inc, ecc, mm, day = values["inclination"], values["eccentricity"], values["mean_motion"], values["day"]
    # The same plausibility limits as tle.check_ranges (the epoch year always lies in 1957..2056).
    ok &= (inc >= 0.0) & (inc <= 180.0) & (ecc < 1.0) & (mm >= 1e-6) & (mm <= 20.0) & (day >= 1.0) & (day < 367.0)
    for angle in ("raan", "arg_perigee", "mean_anomaly"):
        ok &= values[angle] < 360.0 + 1e-9
    ok &= (np.abs(values["ndot"]) < 1.0) & (np.abs(values["nddot"]) < 1e9) & (np.abs(values["bstar"]) < 1e9)
    return ok, values


def read_canonical(line1: list[str], line2: list[str]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(accepted mask, values) for the pairs ``line1[i]``, ``line2[i]`` (right-stripped lines).

    Values (arrays over all pairs; meaningful where accepted): ``catalog_number``, ``year2``, ``day``, ``ndot``,
    ``nddot``, ``bstar``, ``inclination``, ``raan``, ``eccentricity``, ``arg_perigee``,
    ``mean_anomaly``, ``mean_motion``, ``rev_number``.
    """
    n = len(line1)
    good = np.zeros(n, dtype=bool)
    values: dict[str, np.ndarray] = {}
    text1, text2 = "".join(line1), "".join(line2)
    if len(text1) == len(text2) == 69 * n and text1.isascii() and text2.isascii() \
            and all([len(x) == 69 for x in line1]) and all([len(y) == 69 for y in line2]):
        idx = np.arange(n)  # the usual case: every pair has the canonical length
    else:
        idx = np.flatnonzero([len(x) == 69 and len(y) == 69 and x.isascii() and y.isascii()
                              for x, y in zip(line1, line2)])
        text1, text2 = "".join([line1[i] for i in idx]), "".join([line2[i] for i in idx])
    if not len(idx):
        return good, values
    all1 = np.frombuffer(text1.encode("ascii"), dtype=np.uint8).reshape(-1, 69)
    all2 = np.frombuffer(text2.encode("ascii"), dtype=np.uint8).reshape(-1, 69)
    for name in _COLUMNS:
        values[name] = np.zeros(n, dtype=np.int64 if name in _INTEGER_COLUMNS else np.float64)
    for r0 in range(0, len(idx), _ROWS):
        rows = idx[r0 : r0 + _ROWS]
        ok, block = _read_block(all1[r0 : r0 + _ROWS], all2[r0 : r0 + _ROWS])
        good[rows] = ok
        for name in _COLUMNS:
            values[name][rows] = block[name]
    return good, values
