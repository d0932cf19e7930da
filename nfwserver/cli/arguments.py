"""Argument-list helpers shared by the command modules."""

from __future__ import annotations

import re

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
