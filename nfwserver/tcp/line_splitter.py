"""Splitting a TCP byte stream into command lines, with a hard limit on what is kept.

A line ends at CR, LF, CR LF or NUL (clients of Nova's TCP server send all of these).  An LF right
after a CR belongs to that CR, even when the two arrive in different reads, so CR LF ends one line,
not two.  A line longer than :data:`MAX_LINE_BYTES` is refused as soon as it grows past the limit:
the splitter reports it once (as ``None``) and throws the rest of that line away as it arrives, so
no more than the limit is ever held per client.
"""

from __future__ import annotations

import re

MAX_LINE_BYTES = 1024
_TERMINATOR = re.compile(rb"[\r\n\x00]")


class LineSplitter:
    """Feed it received bytes; it returns complete lines (bytes, without the terminator) in order,
    and ``None`` once for each line that grew longer than ``limit`` bytes."""

    def __init__(self, limit: int = MAX_LINE_BYTES) -> None:
        self.limit = limit
        self._partial = bytearray()
        self._discarding = False  # inside a refused over-long line, until its terminator
        self._after_cr = False  # the previous byte was a CR: a following LF is part of it

    @property
    def buffered(self) -> int:
        """Bytes of an unfinished line held now (never more than ``limit``)."""
        return len(self._partial)

    def feed(self, data: bytes) -> list[bytes | None]:
        out: list[bytes | None] = []
        i, n = 0, len(data)
        while i < n:
            if self._after_cr:
                self._after_cr = False
                if data[i] == 0x0A:
                    i += 1
                    continue
            m = _TERMINATOR.search(data, i)
            end = m.start() if m else n
            if not self._discarding:
                self._partial += data[i:end]
                if len(self._partial) > self.limit:
                    out.append(None)
                    self._partial.clear()
                    self._discarding = True
            if m is None:
                break
            if self._discarding:
                self._discarding = False
            else:
                out.append(bytes(self._partial))
                self._partial.clear()
            self._after_cr = data[end] == 0x0D
            i = end + 1
        return out
