"""The ``STATUS`` line of Nova's TCP face, written and read here only.

One line of ``key=value`` pairs separated by single blanks.  Neither keys nor values hold a blank or a control
character (each becomes ``_``); a missing value (None) is ``-``, a switch is ``on``/``off``.  The station
writes it (:func:`format_status`, :class:`nfwserver.tcp.protocol.NovaTcpProtocol`); ``nfwserver status``,
``nfwserver watch`` and the tests read it (:func:`parse_status`).
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["format_status", "parse_status", "status_value"]


def status_value(value: object) -> str:
    """``value`` as one STATUS word: no blanks or control characters, ``-`` when there is none."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if value is None:
        return "-"
    text = "".join(ch if ch.isprintable() and not ch.isspace() else "_" for ch in str(value))
    return text or "-"


def format_status(fields: Mapping[str, object]) -> str:
    """The STATUS line of ``fields``, in their order."""
    return " ".join(f"{status_value(key)}={status_value(value)}" for key, value in fields.items())


def parse_status(line: str) -> dict[str, str]:
    """The pairs of a STATUS line, in order, values as sent (words without ``=`` are not pairs and are left out;
    ``value`` may hold further ``=``)."""
    return dict(word.split("=", 1) for word in line.split() if "=" in word)
