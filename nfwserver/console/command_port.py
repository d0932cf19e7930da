"""What the console's own commands act on: its display (``Z``) and its answer to ``HELP`` (a screen of its own).

The console hands every command to the station core (:meth:`nfwserver.core.station_core.StationCore.execute`),
which runs the entry's action from the command table; the actions of the console's commands call back here.
The TCP session's other commands (``SUMMARY``, ``STATUS``, ``WATCH``, ``QUIT``) are not the console's: the
table does not let the console send them, so reaching them here is a bug in the table.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from nfwserver.commands.help_text import help_lines
from nfwserver.commands.table import Face

__all__ = ["ConsolePort"]


class ConsolePort:
    """The console's session and display, for the core's command actions."""

    def __init__(self, show_help: Callable[[Sequence[str]], None], toggle_zone: Callable[[], None]) -> None:
        self._show_help = show_help
        self._toggle_zone = toggle_zone

    def help(self) -> None:
        self._show_help(help_lines(Face.CONSOLE))

    def toggle_zone(self) -> None:
        self._toggle_zone()

    def _not_the_consoles(self) -> None:
        raise AssertionError("a TCP session's command reached the console, which the command table does not let "
                             "send it")

    summary = status = watch = quit = _not_the_consoles
