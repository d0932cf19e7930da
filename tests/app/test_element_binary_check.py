"""The element reader's binary check follows its rule as written: NUL bytes in the first 64 KiB, or more than one
character in twenty of them (decoded as UTF-8) undecodable, a control character other than tab, line feed,
carriage return and form feed, or DEL."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from nfwserver.app.element_sources import _looks_binary
from tests.conftest import DATA

TLE = (DATA / "active.txt").read_bytes()[:3000]


def _rule(data: bytes) -> bool:
    head = data[:65536]
    if 0 in head:
        return True
    text = head.decode("utf-8", errors="replace")
    odd = [c for c in text if c == "\ufffd" or c == "\x7f" or (ord(c) < 32 and c not in "\t\n\r\f")]
    return len(odd) > len(text) // 20


@given(st.binary(max_size=400))
def test_any_bytes(data: bytes) -> None:
    assert _looks_binary(data) == _rule(data)


@given(st.lists(st.tuples(st.integers(0, len(TLE) - 1), st.integers(1, 255)), max_size=300))
def test_element_text_with_bytes_replaced(changes: list[tuple[int, int]]) -> None:
    data = bytearray(TLE)
    for at, value in changes:
        data[at] = value
    assert _looks_binary(bytes(data)) == _rule(bytes(data))


def test_clean_element_text_is_text_and_a_tenth_of_control_characters_is_not() -> None:
    assert not _looks_binary(TLE)
    assert _looks_binary(TLE[:2000] + b"\x01" * 200)
