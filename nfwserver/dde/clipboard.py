"""Clipboard formats used on the DDE link and the conversion of text to and from their bytes.

DDE moves data as bytes tagged with a clipboard format.  Nova's clients use ``CF_TEXT``: ANSI text
(Windows code page 1252 here) ending in one NUL byte.  Some newer clients ask for
``CF_UNICODETEXT``: UTF-16-LE ending in a two-byte NUL.  Incoming data is decoded leniently: the
text ends at the first NUL (DDE buffers are often longer than the string), and undecodable bytes
become U+FFFD instead of raising.
"""

from __future__ import annotations

CF_TEXT = 1
CF_UNICODETEXT = 13

#: Formats the server can serve and accept, in order of preference.
TEXT_FORMATS = (CF_TEXT, CF_UNICODETEXT)

ANSI_CODEPAGE = "cp1252"


def format_name(fmt: int) -> str:
    """A readable name for a clipboard format number, e.g. ``"CF_TEXT"`` or ``"fmt 49161"``."""
    return {CF_TEXT: "CF_TEXT", CF_UNICODETEXT: "CF_UNICODETEXT"}.get(fmt, f"fmt {fmt}")


def encode_text(text: str, fmt: int = CF_TEXT) -> bytes:
    """Encode ``text`` as the NUL-terminated bytes of clipboard format ``fmt``.

    Characters that code page 1252 cannot hold become ``?`` in ``CF_TEXT``.
    Raises :class:`ValueError` for a format that is not a text format.
    """
    if fmt == CF_TEXT:
        return text.encode(ANSI_CODEPAGE, errors="replace") + b"\x00"
    if fmt == CF_UNICODETEXT:
        return text.encode("utf-16-le") + b"\x00\x00"
    raise ValueError(f"not a text clipboard format: {format_name(fmt)}")


def decode_text(data: bytes, fmt: int = CF_TEXT) -> str:
    """Decode DDE data of clipboard format ``fmt`` to text, stopping at the first NUL.

    Never raises for bad bytes (they become U+FFFD); raises :class:`ValueError` only for a format
    that is not a text format.
    """
    if fmt == CF_TEXT:
        end = data.find(b"\x00")
        raw = data if end < 0 else data[:end]
        return raw.decode(ANSI_CODEPAGE, errors="replace")
    if fmt == CF_UNICODETEXT:
        if len(data) % 2:
            data = data[:-1]
        end = 0
        while end < len(data) and data[end : end + 2] != b"\x00\x00":
            end += 2
        return data[:end].decode("utf-16-le", errors="replace")
    raise ValueError(f"not a text clipboard format: {format_name(fmt)}")
