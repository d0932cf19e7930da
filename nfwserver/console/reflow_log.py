"""A log pane that wraps its lines again when its width changes.

Textual's :class:`~textual.widgets.RichLog` wraps a line once, with the width it believes the pane
has when the line is written; a line written before the layout settles (the first-run notes) or a
terminal resized afterwards would then be cut at the pane's edge.  :class:`ReflowLog` keeps the lines
it was given (bounded by ``max_lines``), wraps each to the pane's current text width, and writes them
all again after its width changes.  The scrollbar's gutter is reserved, so its appearance does not
change the width.
"""

from __future__ import annotations

import collections

from rich.text import Text
from textual.events import Resize
from textual.widgets import RichLog


class ReflowLog(RichLog):
    """A wrapping, plain-text :class:`RichLog` whose lines follow the pane's width."""

    DEFAULT_CSS = "ReflowLog { scrollbar-gutter: stable; }"

    def __init__(self, *, max_lines: int = 500, id: str | None = None) -> None:  # noqa: A002 - Textual's name
        super().__init__(max_lines=max_lines, wrap=True, markup=False, id=id)
        self.entries: collections.deque[Text] = collections.deque(maxlen=max_lines)
        self._wrapped_at = 0

    def _text_width(self) -> int:
        return self.scrollable_content_region.width

    def add(self, line: Text) -> None:
        """Append ``line`` (kept for re-wrapping)."""
        self.entries.append(line)
        width = self._text_width()
        self.write(line, width=width if width > 0 and self._wrapped_at else None)

    def on_resize(self, event: Resize) -> None:
        self.call_after_refresh(self._reflow)

    def _reflow(self) -> None:
        width = self._text_width()
        if width <= 0 or width == self._wrapped_at:
            return
        self._wrapped_at = width
        self.clear()
        for line in self.entries:
            self.write(line, width=width)
