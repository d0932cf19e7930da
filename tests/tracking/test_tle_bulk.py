"""Bulk TLE reading against the one-set parser: never more lenient, bit-for-bit the same values.

The oracle is :func:`nfwserver.tracking.tle.parse_tle` (the per-set parser, itself tested against
the format's own words in test_tle.py): every pair the bulk reader accepts must be accepted by
it with identical values, for real catalog lines and for thousands of mutated ones.
"""

from __future__ import annotations

import random
from pathlib import Path

from nfwserver.tracking.tle import TleError, encode_catalog_number, parse_tle, tle_checksum
from nfwserver.tracking.tle_bulk import read_canonical

LINES = (Path(__file__).resolve().parents[1] / "data" / "active.txt").read_text().splitlines()
PAIRS = [(LINES[i + 1], LINES[i + 2]) for i in range(0, 3 * 600, 3)]
FIELDS = {"inclination": "inclination_deg", "raan": "raan_deg", "eccentricity": "eccentricity",
          "arg_perigee": "arg_perigee_deg", "mean_anomaly": "mean_anomaly_deg",
          "mean_motion": "mean_motion_rev_per_day", "bstar": "bstar", "nddot": "mean_motion_ddot",
          "ndot": "mean_motion_dot", "rev_number": "rev_number", "catalog_number": "catalog_number"}


def _fix(line: str) -> str:
    return line[:68] + str(tle_checksum(line))


def _check(pairs: list[tuple[str, str]]) -> int:
    good, values = read_canonical([p[0] for p in pairs], [p[1] for p in pairs])
    for k, (one, two) in enumerate(pairs):
        if not good[k]:
            continue
        fields = parse_tle(one, two)  # raises if bulk reading was more lenient
        for bulk_name, attr in FIELDS.items():
            assert values[bulk_name][k] == getattr(fields, attr), (one, two, bulk_name)
        assert fields.epoch.year % 100 == values["year2"][k]
    return int(good.sum())


def test_every_canonical_catalog_set_is_read_in_bulk_with_identical_values() -> None:
    assert _check(PAIRS) == len(PAIRS)


def test_mutated_sets_are_never_accepted_more_leniently() -> None:
    rng = random.Random(17)
    pairs = []
    for _ in range(6000):
        one, two = rng.choice(PAIRS)
        which = rng.randrange(2)
        line = [one, two][which]
        pos = rng.randrange(69)
        line = line[:pos] + rng.choice("0123456789 -+.AZIO:e") + line[pos + 1:]
        if rng.random() < 0.8:
            line = _fix(line)
        pairs.append((line, two) if which == 0 else (one, line))
    accepted = _check(pairs)
    rejected_by_parser = 0
    for one, two in pairs:
        try:
            parse_tle(one, two)
        except TleError:
            rejected_by_parser += 1
    # Both outcomes occur often; bulk acceptance never exceeds what the parser accepts (checked above).
    assert rejected_by_parser > 1000 and accepted > 1000 and accepted + rejected_by_parser <= len(pairs)


def test_alpha5_numbers_and_exponent_forms() -> None:
    one, two = PAIRS[0]
    cat = encode_catalog_number(123456)
    one, two = _fix(one[:2] + cat + one[7:]), _fix(two[:2] + cat + two[7:])
    variants = [(one, two)]
    for bstar in ("-12345-6", "+12345+1", " 00000-0", " 99999-9"):
        variants.append((_fix(one[:53] + bstar + one[61:]), two))
    assert _check(variants) == len(variants)
    assert read_canonical([one], [two])[1]["catalog_number"][0] == 123456


def test_working_memory_is_bounded_whatever_the_catalog_size() -> None:
    """Pairs are read in blocks: memory grows with the number of pairs only by the results (13 columns of
    8 bytes), the joined text (twice 69 bytes a line, as str and as bytes) and small per-pair flags,
    under 500 bytes a pair.  (Reading all pairs at once held several 69-column integer arrays, 1.9 kB
    a pair.)"""
    import tracemalloc

    all_lines = LINES[: 3 * (len(LINES) // 3)]
    one, two = all_lines[1::3], all_lines[2::3]
    peaks = []
    for repeat in (1, 5):
        tracemalloc.start()
        good, _ = read_canonical(one * repeat, two * repeat)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        assert good.all()
    per_pair = (peaks[1] - peaks[0]) / (4 * len(one))
    assert per_pair < 500, per_pair
