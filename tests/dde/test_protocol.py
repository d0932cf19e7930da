"""Formatting of the Nova string and the poke grammar."""

from __future__ import annotations

import re

import pytest
from hypothesis import given
from hypothesis import strategies as st

from nfwserver.commands.parsing import Parsed, parse_request
from nfwserver.commands.table import Face, escape_for_log
from nfwserver.core.nova_protocol import (
    format_azimuth,
    format_elevation,
    format_nova,
    format_range_rate,
)

NOVA = re.compile(r"^\S{1,12} AZ:\d{1,3}\.\d EL:-?\d{1,2}\.\d RR:-?\d+\.\d{10} AH:[YN]$")


def test_the_spec_sample() -> None:
    assert format_nova("Mir", 116.4, -21.0, -1.4396996895, False) == "Mir AZ:116.4 EL:-21.0 RR:-1.4396996895 AH:N"


@pytest.mark.parametrize(
    ("az", "text"),
    [(0.0, "0.0"), (359.94, "359.9"), (359.96, "0.0"), (359.999, "0.0"), (360.0, "0.0"), (12.35, "12.3")],
)
def test_azimuth_wraps_and_never_prints_360(az: float, text: str) -> None:
    assert format_azimuth(az) == text


def test_no_negative_zero() -> None:
    assert format_elevation(-0.04) == "0.0"
    assert format_elevation(-0.05001) == "-0.1"
    assert format_range_rate(-1e-12) == "0.0000000000"
    assert format_range_rate(-1e-10) == "-0.0000000001"


def test_names_are_cut_and_blank_free() -> None:
    assert format_nova("A VERY LONG NAME INDEED", 1, 2, 3, True).split()[0] == "AVERYLONGNAM"


@given(st.text(max_size=20), st.floats(0, 360), st.floats(-90, 90), st.floats(-12, 12), st.booleans())
def test_every_string_matches_the_grammar(name, az, el, rr, ah) -> None:
    assert NOVA.match(format_nova(name, az, el, rr, ah))


def _read(parsed: tuple[Parsed, ...]) -> list[tuple[str, object]]:
    return [(p.command.word, p.value) for p in parsed]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("TUNE ON", [("TUNE", True)]),
        ("TUNE OFF\x00", [("TUNE", False)]),
        ("track on\r\n", [("TRACK", True)]),
        ("  TRACK   OFF  ", [("TRACK", False)]),
        ("SAT=25544", [("SAT", 25544)]),
        ("SAT = 7530\x00\x00", [("SAT", 7530)]),
        ("ANTAZ=123.45", [("ANTAZ", 123.45)]),
        ("ANTEL=-0", [("ANTEL", 0.0)]),
        ("doppler on", [("DOPPLER", True)]),
        ("TUNE ON\r\nSAT=25544\r\n", [("TUNE", True), ("SAT", 25544)]),
    ],
)
def test_pokes(text: str, expected: list[tuple[str, object]]) -> None:
    request = parse_request(text, Face.DDE)  # as Nova's DDE service reads a poke
    assert request.error is None
    assert _read(request.commands) == expected


_NOT_NOVA = "not a Nova command (TUNE ON|OFF, TRACK ON|OFF, SAT=n, ANTAZ=deg, ANTEL=deg, DOPPLER ON|OFF, AUTO ON|OFF)"


@pytest.mark.parametrize(("text", "reason"), [
    ("", "empty poke"), ("\x00", "empty poke"), ("TUNE", "TUNE needs ON or OFF"),
    ("TUNE MAYBE", "TUNE needs ON or OFF"), ("SAT=", "SAT needs a catalog number, got ''"),
    ("SAT=ISS", "SAT needs a catalog number, got 'ISS'"), ("SAT=-5", "SAT needs a catalog number, got '-5'"),
    ("SAT=1234567", "SAT needs a catalog number, got '1234567'"),
    ("ANTAZ=nan", "ANTAZ needs a number of degrees, got 'nan'"),
    ("ANTAZ=1e309", "ANTAZ needs a number of degrees, got '1e309'"),
    ("ANTAZ=inf", "ANTAZ needs a number of degrees, got 'inf'"),
    ("ANTEL=95x", "ANTEL needs a number of degrees, got '95x'"),
    ("ANTEL=200", "ANTEL 200.0 is outside -90..180 degrees"), ("ANTAZ=800", "ANTAZ 800.0 is outside -360..720 degrees"),
    ("HELLO", _NOT_NOVA), ("X" * 5000, "poke of 5000 characters is too long"), ("TUNE ON\r\nBOGUS", _NOT_NOVA),
])
def test_bad_pokes_are_refused_with_a_reason(text: str, reason: str) -> None:
    # The reason is what the console, the event log and a TCP client see: it names what was wrong.
    request = parse_request(text, Face.DDE)
    assert not request.commands
    assert str(request.error) == reason


@given(st.text(max_size=300))
def test_any_text_either_parses_or_is_refused_with_a_reason(text: str) -> None:
    request = parse_request(text, Face.DDE)
    assert bool(request.commands) != (request.error is not None)
    assert all(p.command.faces & Face.DDE for p in request.commands)


def test_log_escaping_keeps_one_line() -> None:
    assert escape_for_log("SAT=1\r\nINFO forged line") == "SAT=1\\r\\nINFO forged line"
    assert "\n" not in escape_for_log("a\nb" * 100)
