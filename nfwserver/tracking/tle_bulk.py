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

Units are those of the format: degrees, rev/day, day of year, 1/earth radii.
"""

from __future__ import annotations

import numpy as np

_POW10 = np.array([10.0**e for e in range(-9, 10)])  # Python's powers, as parse_tle uses them
_ALPHA5 = np.full(256, -1, dtype=np.int64)  # value of an Alpha-5 leading letter, -1 for other bytes
_ALPHA5[np.frombuffer(b"ABCDEFGHJKLMNPQRSTUVWXYZ", dtype=np.uint8)] = np.arange(10, 34)


def _digits(a: np.ndarray, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
    """(all digits?, integer value) of columns ``lo:hi``."""
    d = a[:, lo:hi].astype(np.int64) - 48
    ok = np.asarray(((d >= 0) & (d <= 9)).all(axis=1))
    return ok, (d * 10 ** np.arange(hi - lo - 1, -1, -1, dtype=np.int64)).sum(axis=1)


def _padded(a: np.ndarray, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
    """(leading blanks then digits?, value) of columns ``lo:hi`` (all blanks reads 0)."""
    sub = a[:, lo:hi]
    digit = (sub >= 48) & (sub <= 57)
    blank = sub == 32
    ok = (digit | blank).all(axis=1) & ~(digit[:, :-1] & blank[:, 1:]).any(axis=1)
    d = np.where(digit, sub.astype(np.int64) - 48, 0)
    return ok, (d * 10 ** np.arange(hi - lo - 1, -1, -1, dtype=np.int64)).sum(axis=1)


def _fixed(a: np.ndarray, lo: int, point: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
    """(valid?, value) of a fixed-point field: blank-padded digits, ``.`` at ``point``, digits to ``hi``."""
    ok_i, whole = _padded(a, lo, point)
    ok_f, frac = _digits(a, point + 1, hi)
    places = hi - point - 1
    ok = ok_i & ok_f & (a[:, point] == 46) & (a[:, point - 1] != 32)
    return ok, (whole * 10**places + frac) / float(10**places)


def _exponent(a: np.ndarray, lo: int) -> tuple[np.ndarray, np.ndarray]:
    """(valid?, value) of an 8-column assumed-decimal exponent field ``±NNNNN±E``."""
    sign_c, exp_sign = a[:, lo], a[:, lo + 6]
    ok_m, mant = _digits(a, lo + 1, lo + 6)
    ok_e, exp = _digits(a, lo + 7, lo + 8)
    ok = ok_m & ok_e & np.isin(sign_c, (32, 43, 45)) & np.isin(exp_sign, (43, 45))
    e = np.where(exp_sign == 45, -exp, exp)
    sign = np.where(sign_c == 45, -1.0, 1.0)
    return ok, sign * (mant / 100000.0) * _POW10[np.clip(e, -9, 9) + 9]


def _checksum_ok(a: np.ndarray) -> np.ndarray:
    body = a[:, :68].astype(np.int64)
    value = np.where((body >= 48) & (body <= 57), body - 48, 0) + (body == 45)
    return (value.sum(axis=1) % 10) == (a[:, 68].astype(np.int64) - 48)


def _catalog(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(valid?, number) of the 5-column catalog field: decimal, or Alpha-5 (A=10 ... Z=33, no I or O)."""
    head = a[:, 2]
    ok_t, tail = _digits(a, 3, 7)
    digit = (head >= 48) & (head <= 57)
    number = np.where(digit, head.astype(np.int64) - 48, _ALPHA5[head]) * 10000 + tail
    return (digit | (_ALPHA5[head] >= 0)) & ok_t, number


def read_canonical(line1: list[str], line2: list[str]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """(accepted mask, values) for the pairs ``line1[i]``, ``line2[i]`` (right-stripped lines).

    Values (arrays over all pairs; meaningful where accepted): ``catalog_number``, ``year2``, ``day``, ``ndot``,
    ``nddot``, ``bstar``, ``inclination``, ``raan``, ``eccentricity``, ``arg_perigee``,
    ``mean_anomaly``, ``mean_motion``, ``rev_number``.
    """
    n = len(line1)
    shaped = np.array([len(x) == 69 and len(y) == 69 and x.isascii() and y.isascii()
                       for x, y in zip(line1, line2)], dtype=bool)
    idx = np.flatnonzero(shaped)
    good = np.zeros(n, dtype=bool)
    values: dict[str, np.ndarray] = {}
    if not len(idx):
        return good, values
    a = np.frombuffer("".join(line1[i] for i in idx).encode("ascii"), dtype=np.uint8).reshape(-1, 69)
    b = np.frombuffer("".join(line2[i] for i in idx).encode("ascii"), dtype=np.uint8).reshape(-1, 69)
    ok = (a[:, 0] == 49) & (b[:, 0] == 50) & (a[:, 1] == 32) & (b[:, 1] == 32)
    ok_c, catalog = _catalog(a)
    ok &= _checksum_ok(a) & _checksum_ok(b) & ok_c & (a[:, 2:7] == b[:, 2:7]).all(axis=1)
    ok_y, year2 = _digits(a, 18, 20)
    ok_d, day = _fixed(a, 20, 23, 32)
    ok_n, ndot_mag = _digits(a, 35, 43)
    ndot = np.where(a[:, 33] == 45, -1.0, 1.0) * (ndot_mag / 1e8)
    ok &= ok_y & ok_d & ok_n & np.isin(a[:, 33], (32, 43, 45)) & (a[:, 34] == 46)
    ok_dd, nddot = _exponent(a, 44)
    ok_bs, bstar = _exponent(a, 53)
    ok &= ok_dd & ok_bs & np.isin(a[:, 62], (32, 48, 49, 50, 51, 52, 53, 54, 55, 56, 57)) & _padded(a, 64, 68)[0]
    fields = {"inclination": _fixed(b, 8, 11, 16), "raan": _fixed(b, 17, 20, 25), "arg_perigee": _fixed(b, 34, 37, 42),
              "mean_anomaly": _fixed(b, 43, 46, 51), "mean_motion": _fixed(b, 52, 54, 63)}
    for valid, _ in fields.values():
        ok &= valid
    ok_e, ecc_int = _digits(b, 26, 33)
    ok_r, rev = _padded(b, 63, 68)
    ok &= ok_e & ok_r
    inc, raan, argp, ma, mm = (v for _, v in fields.values())
    ecc = ecc_int / 1e7
    # The same plausibility limits as tle.check_ranges (the epoch year always lies in 1957..2056).
    ok &= (inc >= 0.0) & (inc <= 180.0) & (ecc < 1.0) & (mm >= 1e-6) & (mm <= 20.0) & (day >= 1.0) & (day < 367.0)
    for angle in (raan, argp, ma):
        ok &= angle < 360.0 + 1e-9
    ok &= (np.abs(ndot) < 1.0) & (np.abs(nddot) < 1e9) & (np.abs(bstar) < 1e9)
    good[idx] = ok
    for name, col in (("catalog_number", catalog), ("year2", year2), ("day", day), ("ndot", ndot), ("nddot", nddot),
                      ("bstar", bstar),
                      ("inclination", inc), ("raan", raan), ("eccentricity", ecc), ("arg_perigee", argp),
                      ("mean_anomaly", ma), ("mean_motion", mm), ("rev_number", rev)):
        full = np.zeros(n, dtype=col.dtype)
        full[idx] = col
        values[name] = full
    return good, values
