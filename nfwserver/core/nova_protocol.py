"""The Nova for Windows DDE string and poke grammar.

Outgoing string (one per publish tick, after ``TUNE ON``)::

    SatName AZ:<az> EL:<el> RR:<rr> AH:<Y|N>

- ``SatName``: at most 12 characters, no spaces (clients take the first word as the name).
- ``AZ``: degrees, one decimal, unsigned, 0.0-359.9 (a value that rounds to 360.0 prints 0.0).
- ``EL``: degrees, one decimal, signed only when negative; never ``-0.0``.
- ``RR``: range rate in km/s, positive receding, ten decimals; never ``-0.0000000000``.
- ``AH``: ``Y`` when the elevation is above the horizon table at that azimuth, else ``N``.

Incoming pokes (any item of the topic): ``TUNE ON``, ``TUNE OFF``, ``TRACK ON``, ``TRACK OFF``,
``SAT=<catalog number>``, ``ANTAZ=<deg>``, ``ANTEL=<deg>``.  Trailing NULs, CR/LF and blanks are
stripped; keywords are accepted in any case and with blanks around ``=``; several commands may
arrive in one poke, one per line.  Anything else is refused with a reason.
"""

from __future__ import annotations

import enum
import math
import re
from dataclasses import dataclass

MAX_NAME_LENGTH = 12
#: Longest poke text we look at; longer input is refused without being parsed.
MAX_POKE_LENGTH = 256


def format_azimuth(az_deg: float) -> str:
    """``AZ`` field: one decimal in 0.0..359.9."""
    text = f"{az_deg % 360.0:.1f}"
    return "0.0" if text == "360.0" else text


def format_elevation(el_deg: float) -> str:
    """``EL`` field: one decimal, signed when negative, never ``-0.0``."""
    text = f"{el_deg:.1f}"
    return "0.0" if text == "-0.0" else text


def format_range_rate(rr_km_s: float) -> str:
    """``RR`` field: km/s with ten decimals, never negative zero."""
    text = f"{rr_km_s:.10f}"
    return text[1:] if text.startswith("-") and not text.strip("-0.") else text


def format_nova(name: str, az_deg: float, el_deg: float, rr_km_s: float, above_horizon: bool) -> str:
    """The whole Nova string; ``name`` is cleaned to at most 12 characters without blanks."""
    clean = "".join(ch for ch in name if ch.isprintable() and not ch.isspace())[:MAX_NAME_LENGTH] or "SAT"
    return (
        f"{clean} AZ:{format_azimuth(az_deg)} EL:{format_elevation(el_deg)} "
        f"RR:{format_range_rate(rr_km_s)} AH:{'Y' if above_horizon else 'N'}"
    )


class PokeKind(enum.Enum):
    TUNE = "TUNE"
    TRACK = "TRACK"
    SAT = "SAT"
    ANTAZ = "ANTAZ"
    ANTEL = "ANTEL"


@dataclass(frozen=True)
class Poke:
    """One parsed poke command.  ``value`` is a bool (TUNE/TRACK), int (SAT) or float (ANTAZ/ANTEL)."""

    kind: PokeKind
    value: bool | int | float

    def __str__(self) -> str:
        if self.kind in (PokeKind.TUNE, PokeKind.TRACK):
            return f"{self.kind.value} {'ON' if self.value else 'OFF'}"
        return f"{self.kind.value}={self.value}"


class PokeError(ValueError):
    """A poke that is not part of the grammar; the message says why in one sentence.

    ``bad_argument`` is True for a known command with a bad argument (OrbitDRV's "bad subfunction"),
    False for something that is not a command at all ("bad function").
    """

    def __init__(self, message: str, bad_argument: bool = False) -> None:
        super().__init__(message)
        self.bad_argument = bad_argument


_ON_OFF = re.compile(r"^(TUNE|TRACK)\s+(ON|OFF)$", re.IGNORECASE)
_ASSIGN = re.compile(r"^(SAT|ANTAZ|ANTEL)\s*=\s*(\S*)$", re.IGNORECASE)
_KNOWN_WORD = re.compile(r"^(TUNE|TRACK|SAT|ANTAZ|ANTEL)\b", re.IGNORECASE)
_USAGE = {"TUNE": "ON or OFF", "TRACK": "ON or OFF", "SAT": "=<catalog number>", "ANTAZ": "=<degrees>",
          "ANTEL": "=<degrees>"}
_NUMBER = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)$", re.ASCII)


def clean_poke_text(text: str) -> str:
    """Strip the NULs, CR/LF and blanks that clients leave around a poke."""
    return text.strip("\x00\r\n\t ")


def escape_for_log(text: str, limit: int = 120) -> str:
    """A one-line, printable rendering of untrusted text (so CR/LF cannot forge log lines)."""
    out = text[:limit].encode("unicode_escape", errors="backslashreplace").decode("ascii")
    return out + ("..." if len(text) > limit else "")


def parse_poke_line(line: str) -> Poke:
    """Parse one command (already split from its neighbours); raises :class:`PokeError`."""
    text = clean_poke_text(line)
    if not text:
        raise PokeError("empty poke")
    if len(text) > MAX_POKE_LENGTH:
        raise PokeError(f"poke of {len(text)} characters is too long")
    m = _ON_OFF.match(text)
    if m:
        return Poke(PokeKind(m.group(1).upper()), m.group(2).upper() == "ON")
    m = _ASSIGN.match(text)
    if not m:
        known = _KNOWN_WORD.match(text)
        if known:
            raise PokeError(f"{known.group(1).upper()} needs {_USAGE[known.group(1).upper()]}", bad_argument=True)
        raise PokeError("not a Nova command (TUNE ON|OFF, TRACK ON|OFF, SAT=n, ANTAZ=deg, ANTEL=deg)")
    kind, value = PokeKind(m.group(1).upper()), m.group(2)
    if kind is PokeKind.SAT:
        if not (value.isascii() and value.isdigit()) or not 1 <= len(value) <= 6:
            raise PokeError(f"SAT needs a catalog number, got '{escape_for_log(value, 20)}'", bad_argument=True)
        return Poke(kind, int(value))
    if not _NUMBER.match(value):
        raise PokeError(f"{kind.value} needs a number of degrees, got '{escape_for_log(value, 20)}'", bad_argument=True)
    number = float(value)
    if not math.isfinite(number):
        raise PokeError(f"{kind.value} value is not finite", bad_argument=True)
    if kind is PokeKind.ANTAZ and not -360.0 <= number <= 720.0:
        raise PokeError(f"ANTAZ {number} is outside -360..720 degrees", bad_argument=True)
    if kind is PokeKind.ANTEL and not -90.0 <= number <= 180.0:
        raise PokeError(f"ANTEL {number} is outside -90..180 degrees", bad_argument=True)
    return Poke(kind, number + 0.0)


def parse_poke(text: str) -> list[Poke]:
    """Parse a poke that may hold several commands (one per line); raises :class:`PokeError`.

    All commands must parse for any to be returned, so a half-understood poke changes nothing.
    """
    if len(text) > 4 * MAX_POKE_LENGTH:
        raise PokeError(f"poke of {len(text)} characters is too long")
    lines = [p for p in re.split(r"[\r\n\x00]+", text) if clean_poke_text(p)]
    if not lines:
        raise PokeError("empty poke")
    return [parse_poke_line(line) for line in lines]
