"""Where the output of a windowless run goes: ``nfwserverw.exe`` (start at logon, the Start-menu entries).

A Windows program without a console starts with ``sys.stdout`` and ``sys.stderr`` set to None, so every
line the command prints would raise.  :func:`capture` gives such a run a bounded buffer instead (the last
:data:`KEEP_CHARS` characters: a station started at logon runs for weeks); :func:`report` shows it in a
message box when the command failed, so that "no station is running" or a refused configuration reaches
the user who clicked.  A successful run shows nothing.  On a console, both do nothing.
"""

from __future__ import annotations

import io
import sys

#: Characters of output kept for the message box.
KEEP_CHARS = 4000


class TailText(io.TextIOBase):
    """A text stream that keeps only its last ``limit`` characters."""

    def __init__(self, limit: int = KEEP_CHARS) -> None:
        super().__init__()
        self.limit = limit
        self._text = ""

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        self._text = (self._text + text)[-self.limit:]
        return len(text)

    def getvalue(self) -> str:
        return self._text


def capture() -> TailText | None:
    """Give missing standard streams a bounded buffer; the buffer, or None when both streams exist."""
    if sys.stdout is not None and sys.stderr is not None:
        return None
    tail = TailText()
    if sys.stdout is None:
        sys.stdout = tail
    if sys.stderr is None:
        sys.stderr = tail
    return tail


def report(tail: TailText | None, code: int) -> None:
    """After a windowless run: show what it printed when it failed (``code`` not 0)."""
    if tail is None or code == 0:
        return
    text = tail.getvalue().strip() or f"nfwserver exited with status {code}"
    if sys.platform == "win32":
        import ctypes

        mb_ok_iconwarning = 0x00000030
        ctypes.windll.user32.MessageBoxW(None, text, "nfwserver", mb_ok_iconwarning)
