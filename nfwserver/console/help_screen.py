"""The console's answer to ``HELP``: the commands in a screen of their own, the whole terminal's width.

Written into the F3 pane, the help was cut at that pane's 40 columns on an 80x24 terminal.  Here each
command is one row of a two-column table whose description wraps under itself; at 80x24 the console's
whole list fits without scrolling (longer lists scroll with the arrow and page keys).  Esc, Enter or
``q`` closes it, and the command line has the focus again.  Text is literal (never markup).
"""

from __future__ import annotations

from collections.abc import Sequence

from rich.table import Table
from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Static

__all__ = ["HelpScreen"]

#: The command column's width (characters): the longest synopsis, ``SAT=<catalog number>``, fits.
COMMAND_WIDTH = 21


def help_table(lines: Sequence[str]) -> Table:
    """``lines`` as help_text gives them (the synopsis, two spaces or more, the description) in two columns."""
    table = Table.grid(padding=(0, 1))
    table.add_column(width=COMMAND_WIDTH, no_wrap=True, style="bold")
    table.add_column(ratio=1)
    for line in lines:
        command, _, description = line.partition("  ")
        table.add_row(Text(command.strip()), Text(description.strip()))
    return table


class HelpScreen(ModalScreen[None]):
    """The commands the console takes; dismissed by Esc, Enter or ``q``."""

    DEFAULT_CSS = """
    HelpScreen { align: center middle; }
    #help-box { width: 100%; max-width: 120; height: auto; max-height: 100%; border: round $accent;
                background: $surface; padding: 0 1; }
    """
    BINDINGS = [Binding("escape", "close", "Close", priority=True),
                Binding("enter", "close", show=False, priority=True),
                Binding("q", "close", show=False, priority=True)]

    def __init__(self, lines: Sequence[str]) -> None:
        super().__init__()
        self.lines = tuple(lines)

    def compose(self) -> ComposeResult:
        with VerticalScroll(id="help-box"):
            yield Static(help_table(self.lines), id="help-text")

    def on_mount(self) -> None:
        box = self.query_one("#help-box")
        box.border_title = "Commands"
        box.border_subtitle = "Esc closes"
        box.focus()

    def action_close(self) -> None:
        self.dismiss(None)
