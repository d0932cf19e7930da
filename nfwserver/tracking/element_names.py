"""Satellite names from element files, made safe once, where they enter the server.

A name read from an element file, an OMM record or an AMSAT set is untrusted text.  It reaches
terminals (``passes``, the console), the PREDICT UDP replies (one field per line) and the DDE
string, so it is cleaned before an :class:`~nfwserver.tracking.elements.ElementSet` is built and
never again afterwards:

- every control, format, surrogate, private-use or unassigned character (Unicode categories
  ``C*``) and the line/paragraph separators (``Zl``, ``Zp``) becomes a blank: ESC sequences lose
  their ESC, a newline cannot split a line or a PREDICT reply;
- runs of white space become one blank; leading and trailing blanks go;
- the result is cut to :data:`MAX_NAME_LENGTH` characters (:func:`nfwserver.tracking.elements.load_elements`
  reads name lines up to twice that length, so a long name line still names its set, cut).
"""

from __future__ import annotations

import re
import unicodedata

#: Longest name kept (characters).  TLE name lines are 24 characters; OMM names rarely exceed 30.
MAX_NAME_LENGTH = 40

_BLANKS = re.compile(r"\s+")


def _unsafe(ch: str) -> bool:
    return unicodedata.category(ch)[0] == "C" or unicodedata.category(ch) in ("Zl", "Zp")


def sanitize_element_name(text: str) -> str:
    """``text`` with unsafe characters blanked, white space collapsed, at most 40 characters."""
    if text.isascii() and text.isprintable() and len(text) <= MAX_NAME_LENGTH and "  " not in text:
        return text.strip()  # the common case, fast
    cleaned = "".join(" " if _unsafe(ch) else ch for ch in text[: 4 * MAX_NAME_LENGTH])
    return _BLANKS.sub(" ", cleaned).strip()[:MAX_NAME_LENGTH].rstrip()
