"""Argument-list helpers shared by the command modules."""

from __future__ import annotations

import re

#: Every command: (name, module under ``nfwserver.cli``, help line), in ``--help`` order.  A module
#: registering several commands is imported once, when any of them runs.
COMMANDS: tuple[tuple[str, str, str], ...] = (
    ("run", "run_command", "run the server (console on a terminal, or --headless)"),
    ("simulate", "simulate_command", "show what a DDE client receives, on virtual time"),
    ("ephemeris", "tracking_commands", "position table of one satellite"),
    ("passes", "tracking_commands", "AOS/TCA/LOS of satellites over a window"),
    ("visible", "tracking_commands", "satellites above the horizon table at an instant"),
    ("elements", "elements_command", "update or list the stored element catalog"),
    ("config", "config_command", "configuration file: path, init, show"),
)

#: Top-level options that take no value (so the word after them is not their argument).
_FLAGS = {"-v", "--verbose", "-vv", "-vvv", "--version", "-h", "--help"}


def command_word(argv: list[str] | tuple[str, ...] | object) -> str | None:
    """The command named in ``argv`` (the first word that is not a top-level option), or None."""
    for word in argv:  # type: ignore[attr-defined]
        if word in _FLAGS or (word.startswith("-v") and set(word[1:]) == {"v"}):
            continue
        return None if word.startswith("-") else word
    return None


# A value that starts with '-' followed by a digit or '.', e.g. "-33.87,151.21,40" or "-0.3".
_NEGATIVE_VALUE = re.compile(r"^-[0-9.]")


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
