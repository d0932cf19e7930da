"""The ``STATUS`` line of Nova's TCP face, written and read here only.

One line of ``key=value`` pairs separated by single blanks.  A value that is prose (a fault's reason: it holds
blanks) is written in double quotes, with ``\"`` and ``\\`` inside, so it reads as written
(``rotor_fault="rigctld: connection refused"``); a control character in a value becomes a blank, one in a key
``_``.  A missing value (None) is ``-``, a switch is ``on``/``off``.  The station writes it
(:func:`format_status`, :class:`nfwserver.tcp.protocol.NovaTcpProtocol`); ``nfwserver status``, ``nfwserver
watch`` and the tests read it (:func:`parse_status`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping

__all__ = ["format_status", "parse_status", "status_value"]


#: One pair: a key, ``=``, and a quoted value or a word; or a word that is no pair (skipped).
_PAIR = re.compile(r'([^\s=]+)=("(?:[^"\\]|\\.)*"|\S*)|\S+')


def _key(key: object) -> str:
    return "".join(ch if ch.isprintable() and not ch.isspace() else "_" for ch in str(key)) or "-"


def status_value(value: object) -> str:
    """``value`` as one STATUS value: a word, or quoted prose; ``-`` when there is none."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if value is None:
        return "-"
    text = " ".join("".join(ch if ch.isprintable() and not ch.isspace() else " " for ch in str(value)).split())
    if not text:
        return "-"
    if " " in text or '"' in text:
        return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return text


def format_status(fields: Mapping[str, object]) -> str:
    """The STATUS line of ``fields``, in their order."""
    return " ".join(f"{_key(key)}={status_value(value)}" for key, value in fields.items())


def parse_status(line: str) -> dict[str, str]:
    """The pairs of a STATUS line, in order, quoted values unquoted (words without ``=`` are not pairs and are left
    out; a value may hold further ``=``)."""
    pairs: dict[str, str] = {}
    for match in _PAIR.finditer(line):
        key, value = match.group(1), match.group(2)
        if key is None:
            continue
        if value.startswith('"') and value.endswith('"') and len(value) >= 2:
            value = re.sub(r"\\(.)", r"\1", value[1:-1])
        pairs[key] = value
    return pairs
