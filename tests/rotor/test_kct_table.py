"""KCT time/target records: byte layout checked against hand-built bytes, and round trips."""

from __future__ import annotations

import struct
from datetime import datetime, timezone

import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.rotor.kct_table import NormalEntry, RepetitiveEntry, TableEntryError, decode_entry


def test_normal_record_layout_by_hand() -> None:
    entry = NormalEntry(datetime(1988, 6, 21, 13, 45, 7, tzinfo=timezone.utc), -5, 359, "AO-13", 145_812_345,
                        first_of_pass=True)
    expected = bytes([0xC4, 0x07,  # year 1988, low byte first
                      6, 21,  # month, day
                      13 | 0x80,  # hour with the first-of-pass flag
                      45, 7,  # minute (no last-of-pass flag), second
                      0xFB, 0xFF,  # elevation -5, signed
                      0x67, 0x01,  # azimuth 359
                      ]) + b"AO-13   " + bytes([0x79, 0xEB, 0xB0, 0x08])  # 145,812,345 = 0x08B0EB79, LSB first
    assert len(expected) == 23
    assert entry.encode() == expected
    assert decode_entry(expected) == entry


def test_last_of_pass_flag_sits_on_the_minute() -> None:
    entry = NormalEntry(datetime(2026, 5, 8, 0, 59, 59, tzinfo=timezone.utc), 269, 0, "ISS", last_of_pass=True)
    data = entry.encode()
    assert data[5] == 59 | 0x80 and data[4] == 0
    assert struct.unpack_from("<h", data, 7)[0] == 269


def test_repetitive_record_layout_by_hand() -> None:
    entry = RepetitiveEntry(1439, 270, "GEO WEST")
    expected = b"\xff\xff" + bytes([0x9F, 0x05, 0x0E, 0x01]) + b"GEO WEST  " + bytes(7)
    assert entry.encode() == expected
    assert decode_entry(expected) == entry


@pytest.mark.parametrize(
    "data",
    [bytes(22), bytes(24), bytes([0xC4, 0x07, 13, 1, 0, 0, 0, 0, 0, 0, 0]) + bytes(12),
     NormalEntry(datetime(2000, 1, 1, tzinfo=timezone.utc), 0, 0, "X").encode()[:7] + struct.pack("<hH", 300, 0)
     + bytes(12)],
)
def test_malformed_records_are_refused(data: bytes) -> None:
    with pytest.raises(TableEntryError):
        decode_entry(data)


@given(
    st.datetimes(min_value=datetime(1980, 1, 1), max_value=datetime(2100, 1, 1)),
    st.integers(-90, 269), st.integers(0, 359), st.text(alphabet="ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-", max_size=8),
    st.integers(0, 2**32 - 1), st.booleans(), st.booleans(),
)
def test_round_trip(when, el, az, ident, beacon, first, last) -> None:
    entry = NormalEntry(when.replace(microsecond=0, tzinfo=timezone.utc), el, az, ident, beacon, first, last)
    assert decode_entry(entry.encode()) == entry
