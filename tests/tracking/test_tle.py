"""TLE line parsing, checksums, Alpha-5 and canonical formatting."""

from __future__ import annotations

from datetime import datetime, timezone

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from nfwserver.tracking.tle import (
    TleError,
    TleFields,
    decode_catalog_number,
    encode_catalog_number,
    format_tle,
    parse_tle,
    tle_checksum,
)
from tests.conftest import DATA

ISS1 = "1 25544U 98067A   26127.50000000  .00012345  00000+0  22342-3 0  9991"
ISS2 = "2 25544  51.6392 123.4567 0004567 123.4567 236.5432 15.49812345123456"


def _fix(line: str) -> str:
    return line[:68] + str(tle_checksum(line))


def test_checksum_counts_digits_and_minus_only() -> None:
    assert tle_checksum("1" + " " * 67) == 1
    assert tle_checksum("-" * 10 + " " * 58) == 0
    assert tle_checksum("-+.ABC9" + " " * 61) == 0  # 1 + 9 = 10
    assert tle_checksum("2" * 68) == 6  # 136


def test_every_line_of_the_active_catalog_has_a_valid_checksum_and_round_trips() -> None:
    lines = (DATA / "active.txt").read_text().splitlines()
    for i in range(0, len(lines), 3):
        l1, l2 = lines[i + 1].rstrip(), lines[i + 2].rstrip()
        assert format_tle(parse_tle(l1, l2)) == (l1, l2)


def test_alpha5() -> None:
    assert decode_catalog_number("A0000") == 100000
    assert decode_catalog_number("E8493") == 148493
    assert decode_catalog_number("Z9999") == 339999
    assert decode_catalog_number("J0001") == 180001  # I is skipped
    assert encode_catalog_number(148493) == "E8493"
    assert encode_catalog_number(99999) == "99999"
    with pytest.raises(TleError):
        decode_catalog_number("I0000")
    with pytest.raises(TleError):
        encode_catalog_number(340000)


def test_parsed_values_and_units() -> None:
    f = parse_tle(_fix(ISS1), _fix(ISS2))
    assert f.catalog_number == 25544
    assert f.international_designator == "98067A"
    assert f.epoch == datetime(2026, 5, 7, 12, tzinfo=timezone.utc)
    assert f.inclination_deg == pytest.approx(51.6392)
    assert f.eccentricity == pytest.approx(0.0004567)
    assert f.bstar == pytest.approx(0.22342e-3)
    assert f.mean_motion_dot == pytest.approx(0.00012345)
    assert f.mean_motion_rev_per_day == pytest.approx(15.49812345)
    assert f.rev_number == 12345
    assert f.element_number == 999


@pytest.mark.parametrize(
    ("line1", "line2", "reason"),
    [
        (ISS1[:68] + "0", _fix(ISS2), "checksum"),
        (_fix(ISS1), "3" + _fix(ISS2)[1:], "does not start"),
        (_fix(ISS1), _fix(ISS2.replace("25544", "25545")), "differ"),
        (_fix(ISS1)[:60], _fix(ISS2), "characters"),
        (_fix(ISS1) + "12", _fix(ISS2), "characters"),
        (_fix(ISS1), _fix(ISS2.replace(" 51.6392", "191.6392")), "inclination"),
        (_fix(ISS1), _fix(ISS2.replace("15.49812345", "25.49812345")), "mean motion"),
        (_fix(ISS1), _fix(ISS2.replace(" 0004567 ", " 00x4567 ")), "eccentricity"),
        (_fix(ISS1.replace("26127.5", "26400.5")), _fix(ISS2), "day of year"),
        (_fix(ISS1.replace("22342-3", "2234x-3")), _fix(ISS2), "BSTAR"),
        (_fix(ISS1).replace("A ", "\u00e9 "), _fix(ISS2), "non-ASCII"),
    ],
)
def test_malformed_lines_are_refused_with_a_reason(line1: str, line2: str, reason: str) -> None:
    with pytest.raises(TleError, match=reason):
        parse_tle(line1, line2)


_angles = st.floats(0, 359.9999, allow_nan=False)
#: Half the 1e-4 degree step of the TLE's angle columns, plus the binary error of an exact tie such as
#: 0.03125, which the formatter rounds half to even (to 0.0312): the tie is the largest honest error.
_HALF_STEP_DEG = 5e-5 + 1e-12


@given(
    catnr=st.integers(1, 339999),
    seconds=st.integers(0, 40 * 365 * 86400),
    incl=st.floats(0, 180, allow_nan=False),
    raan=_angles, argp=_angles, ma=_angles,
    ecc=st.floats(0, 0.9999999, allow_nan=False),
    mm=st.floats(0.9, 17.0, allow_nan=False),
    rev=st.integers(0, 99999),
    bstar=st.floats(-0.9, 0.9, allow_nan=False),
    ndot=st.floats(-0.9, 0.9, allow_nan=False),
)
@example(catnr=1, seconds=0, incl=0.03125, raan=0.03125, argp=0.0, ma=0.0, ecc=0.0, mm=1.0, rev=0, bstar=0.0,
         ndot=0.0)  # an exact tie, rounded half to even
def test_tle_round_trip(catnr, seconds, incl, raan, argp, ma, ecc, mm, rev, bstar, ndot) -> None:
    epoch = datetime(1990, 1, 1, tzinfo=timezone.utc).replace(microsecond=0)
    epoch = epoch.fromtimestamp(epoch.timestamp() + seconds, timezone.utc)
    fields = TleFields(catnr, "U", "98067A", epoch, ndot, 0.0, bstar, 0, 999, incl, raan, ecc, argp, ma, mm, rev)
    l1, l2 = format_tle(fields)
    assert len(l1) == len(l2) == 69
    back = parse_tle(l1, l2)
    assert back.catalog_number == catnr
    assert abs((back.epoch - epoch).total_seconds()) < 0.001
    assert back.inclination_deg == pytest.approx(incl, abs=_HALF_STEP_DEG)
    assert back.raan_deg == pytest.approx(raan, abs=_HALF_STEP_DEG)
    assert back.eccentricity == pytest.approx(ecc, abs=5e-8)
    assert back.mean_motion_rev_per_day == pytest.approx(mm, abs=5e-9)
    assert back.rev_number == rev
    assert back.bstar == pytest.approx(bstar, rel=1e-4, abs=1e-9)
    assert back.mean_motion_dot == pytest.approx(ndot, abs=5e-9)
    assert format_tle(back) == (l1, l2)
