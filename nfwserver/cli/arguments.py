"""Argument-list helpers and ``type=`` callables shared by the command modules.

A bad argument *value* is a usage error (exit 2, as the README says): every callable here raises
:class:`argparse.ArgumentTypeError` with one sentence, which argparse prints after the usage line.
"""

from __future__ import annotations

import argparse
import math
import re
from collections.abc import Callable, Iterable
from datetime import datetime, timedelta, timezone
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # imported by observer_value when it runs: every command parses with this module
    from nfwserver.tracking.observer import Observer

#: Every command: (name, module under ``nfwserver.cli``, help line), in ``--help`` order.  A module
#: registering several commands is imported once, when any of them runs.
COMMANDS: tuple[tuple[str, str, str], ...] = (
    ("run", "run_command", "run the server (console on a terminal, or --headless)"),
    ("simulate", "simulate_command", "show what a DDE client receives, on virtual time"),
    ("ephemeris", "tracking_commands", "position table of one satellite"),
    ("passes", "tracking_commands", "AOS/TCA/LOS of satellites over a window"),
    ("schedule", "schedule_command", "the autotrack schedule: which passes the station would work by itself"),
    ("visible", "tracking_commands", "satellites above the horizon table at an instant"),
    ("elements", "elements_command", "update or list the stored element catalog"),
    ("config", "config_command", "configuration file: path, init, show, set, edit"),
    ("poke", "control_command", "send a Nova command to the running station (TCP)"),
    ("status", "control_command", "one line of the running station's state (TCP)"),
    ("watch", "watch_command", "live view of the running station (TCP)"),
    ("stop", "station_commands", "stop the running station cleanly and wait until it has stopped"),
    ("dashboard", "station_commands", "open the running station's web dashboard in the browser"),
)

#: Top-level options that take no value (so the word after them is not their argument).
_FLAGS = {"-v", "--verbose", "-vv", "-vvv", "--version", "-h", "--help"}


def command_word(argv: Iterable[str]) -> str | None:
    """The command named in ``argv`` (the first word that is not a top-level option), or None."""
    for word in argv:
        if word in _FLAGS or (word.startswith("-v") and set(word[1:]) == {"v"}):
            continue
        return None if word.startswith("-") else word
    return None


# A value that starts with '-' followed by a digit or '.', e.g. "-33.87,151.21,40" or "-0.3".
_NEGATIVE_VALUE = re.compile(r"^-[0-9.]")
# One relative-time term: "+2h", "-30m", "+90s", "+1d", "+1.5h"; terms may follow each other ("+1h30m").
_RELATIVE = re.compile(r"^([+-])((?:\d+(?:\.\d*)?[smhd])+)$", re.ASCII)
_RELATIVE_TERM = re.compile(r"(\d+(?:\.\d*)?)([smhd])", re.ASCII)
_UNIT_S = {"s": 1.0, "m": 60.0, "h": 3600.0, "d": 86400.0}
#: Relative times reach at most this far (a larger value is almost certainly a typo).
MAX_RELATIVE = timedelta(days=3660)


def join_negative_values(argv: list[str]) -> list[str]:
    """Glue ``--opt -33.8,151.2`` into ``--opt=-33.8,151.2`` so argparse takes it as a value.

    argparse treats any word that starts with ``-`` and is not a plain negative number as an
    option, so a coordinate list such as ``-33.87,151.21,40`` would be rejected.  Only words that
    follow a long option without ``=`` and look like a negative number (``-`` then a digit or
    ``.``) are joined.
    """
    out: list[str] = []
    i = 0
    while i < len(argv):
        word = argv[i]
        if (
            word.startswith("--")
            and "=" not in word
            and i + 1 < len(argv)
            and _NEGATIVE_VALUE.match(argv[i + 1])
        ):
            out.append(f"{word}={argv[i + 1]}")
            i += 2
            continue
        out.append(word)
        i += 1
    return out


def parse_time_text(text: str, now: datetime | None = None) -> datetime:
    """An aware UTC time from ``now``, a relative time or ISO-8601 (UTC when no zone is given).

    Relative times count from ``now`` (default: the system clock): ``+2h``, ``-30m``, ``+90s``,
    ``+1d``, ``+1h30m``.  Raises :class:`ValueError` with one sentence.
    """
    raw = text.strip()
    base = now if now is not None else datetime.now(timezone.utc)
    if raw.lower() == "now":
        return base
    match = _RELATIVE.match(raw.lower())
    if match:
        seconds = sum(float(n) * _UNIT_S[u] for n, u in _RELATIVE_TERM.findall(match.group(2)))
        if seconds > MAX_RELATIVE.total_seconds():
            raise ValueError(f"{text!r} reaches more than {MAX_RELATIVE.days} days away")
        return base + timedelta(seconds=seconds if match.group(1) == "+" else -seconds)
    try:
        when = datetime.fromisoformat(raw[:-1] + "+00:00" if raw.endswith(("Z", "z")) else raw)
    except ValueError:
        raise ValueError(f"{text!r} is not a time: give 'now', a relative time such as +2h or -30m, "
                         f"or ISO-8601 such as 2026-05-08T12:00:00Z") from None
    return when.replace(tzinfo=timezone.utc) if when.tzinfo is None else when.astimezone(timezone.utc)


def time_value(text: str) -> datetime:
    """``type=`` for ``--start``/``--at``: see :func:`parse_time_text`."""
    try:
        return parse_time_text(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def observer_value(text: str) -> Observer:
    """``type=`` for ``--observer``: ``LAT,LON[,ALT_M]`` or a Maidenhead locator."""
    from nfwserver.tracking.observer import parse_observer

    try:
        return parse_observer(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def number_in(low: float, high: float, *, low_open: bool = False, unit: str = "",
              integer: bool = False) -> Callable[[str], float]:
    """``type=`` factory: a finite number in ``[low, high]`` (``(low, high]`` with ``low_open``)."""
    kind = "a whole number" if integer else "a number"

    def show(v: float) -> str:
        return f"{v:g}" if abs(v) < 1e6 else f"{v:,.0f}"

    lower = f"greater than {show(low)}" if low_open else f"at least {show(low)}"
    suffix = f" {unit}" if unit else ""

    def convert(text: str) -> float:
        try:
            value = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {kind}") from None
        if not math.isfinite(value) or (value <= low if low_open else value < low) or value > high:
            raise argparse.ArgumentTypeError(f"{text}{suffix} is out of range: must be {lower} and at most "
                                             f"{show(high)}{suffix}")
        return value

    convert.__name__ = "number"
    return convert


def satellite_value(text: str) -> str:
    """``type=`` for ``--sat``: a catalog number or a name (looked up in the catalog later)."""
    value = text.strip()
    if not value or not value.isprintable():
        raise argparse.ArgumentTypeError(f"{text!r} is not a catalog number or satellite name")
    return value


def element_source_value(text: str) -> str:
    """``type=`` for an element source: a file name or an http(s) URL; other schemes are refused."""
    scheme, sep, _ = text.partition("://")
    if sep and scheme.isalpha() and scheme.lower() not in ("http", "https"):
        raise argparse.ArgumentTypeError(f"{text!r}: unsupported scheme {scheme.lower()}:// "
                                         "(element sources are files or http(s) URLs)")
    return text
