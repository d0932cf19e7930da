"""The KCT driver's Morse annunciator (service calls 10h, 11h, 12h) as a stream of events.

The original sent text and two warbles on the PC speaker.  Here each piece becomes an
:class:`Announcement` that the driver logs and hands to its listeners (the console, the event log),
so an operator sees what the driver would have sounded.

Function 10h, in the document's words: "The text string must consist of ascii characters with a
null (00h) terminator.  Unrecognised characters will be replaced with a space.  Multiple spaces will
be replaced with a single space.  A 0FFh byte will generate the rising warble used for AOS
notification.  A 0FEh byte will generate the dropping warble used for LOS notification."

Our reading of the points the document leaves open:

- *Recognised* means "has a Morse code": the letters A-Z (lower case is sent as upper case, Morse
  having no case), the digits, and the ITU punctuation ``. , : ? ' - / ( ) " = + @``.  Everything
  else -- control characters, other punctuation, bytes 80h-FDh -- becomes a space.
- The first NUL ends the string; text after it is not sent.
- A warble splits the text: ``"AO-13\\xffUP"`` is the text ``AO-13``, the rising warble, the text
  ``UP``.  A piece that is only a space sends nothing audible, so it produces no event; a single
  leading or trailing space of a piece is likewise not kept.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime

log = logging.getLogger(__name__)

AOS_WARBLE = 0xFF  #: byte that sounds the rising (AOS) warble
LOS_WARBLE = 0xFE  #: byte that sounds the dropping (LOS) warble
MORSE_PUNCTUATION = frozenset(".,:?'-/()\"=+@")
#: How many announcements the driver keeps for display.
HISTORY = 200


@dataclass(frozen=True)
class Announcement:
    """One thing the annunciator sent.

    ``kind`` is ``"AOS"`` / ``"LOS"`` (a warble: from a 0FFh / 0FEh byte of function 10h, then
    ``text`` is empty; or from a first / last table entry of a pass, then ``text`` is the satellite
    identifier), ``"text"`` (Morse text) or ``"alarm"`` (a driver condition such as a stalled rotor).
    """

    time: datetime
    kind: str
    text: str


def describe(item: Announcement) -> str:
    """One line for logs and the console: ``AOS warble``, ``LOS warble (AO-13)``, ``Morse: CQ``, ``ALARM: ...``."""
    if item.kind in ("AOS", "LOS"):
        return f"{item.kind} warble" + (f" ({item.text})" if item.text else "")
    return f"{'Morse' if item.kind == 'text' else item.kind.upper()}: {item.text}"


def _recognised(code: int) -> bool:
    ch = chr(code)
    return ch.isascii() and (ch.isalnum() or ch in MORSE_PUNCTUATION)


def parse_morse_request(data: bytes | str) -> list[tuple[str, str]]:
    """Function 10h's string as (kind, text) pieces, per the rules in the module docstring.

    ``data`` is the ASCIIZ string as bytes, or as text whose characters are taken as byte values
    (``"\\xff"`` is the byte 0FFh; characters beyond 0FFh are unrecognised).
    """
    if isinstance(data, str):  # a character beyond 0FFh is no byte at all: mark it unrecognised (01h)
        data = bytes(ord(c) if ord(c) <= 0xFF else 0x01 for c in data)
    raw = bytes(data).split(b"\x00", 1)[0]
    pieces: list[tuple[str, str]] = []
    chars: list[str] = []

    def flush() -> None:
        text = re.sub(" {2,}", " ", "".join(chars)).strip(" ")
        if text:
            pieces.append(("text", text))
        chars.clear()

    for code in raw:
        if code in (AOS_WARBLE, LOS_WARBLE):
            flush()
            pieces.append(("AOS" if code == AOS_WARBLE else "LOS", ""))
        elif _recognised(code):
            chars.append(chr(code).upper())
        else:
            chars.append(" ")
    flush()
    return pieces


class Annunciator:
    """Enablement (function 11h) and the announcement history and listeners."""

    def __init__(self, now: Callable[[], datetime]) -> None:
        self._now = now
        self.enabled = True
        self.history: list[Announcement] = []
        self.listeners: list[Callable[[Announcement], None]] = []

    def emit(self, kind: str, text: str) -> Announcement:
        """Record, log and hand out one announcement (whatever the enablement; callers check it)."""
        item = Announcement(self._now(), kind, text)
        self.history.append(item)
        del self.history[:-HISTORY]
        if kind == "alarm":
            log.warning("rotor driver: %s", text)
        else:
            log.info("annunciator: %s", describe(item))
        for listener in list(self.listeners):
            try:
                listener(item)
            except Exception:
                log.exception("announcement listener failed")
        return item

    def send(self, data: bytes | str) -> list[Announcement]:
        """Function 10h: send a string (nothing when the annunciator is disabled)."""
        if not self.enabled:
            return []
        return [self.emit(kind, text) for kind, text in parse_morse_request(data)]
