"""The satellite picker (F2): search as you type, by name or catalog number.

A modal screen holding a search line and a list.  The list shows at most :data:`MAX_SHOWN`
matches, so typing stays quick however large the catalog (15,000 objects from a full CelesTrak
file): the catalog is indexed once when the picker opens, and each keystroke filters that index.
The current satellite is listed first and highlighted when the picker opens.  Enter picks the
highlighted satellite, Esc closes without a change.  Labels are plain text: names are shown as typed.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import Input, OptionList, Static
from textual.widgets.option_list import Option

from nfwserver.tracking.catalog import Satellite

#: Rows the list holds at once; more matches are counted, not listed.
MAX_SHOWN = 200


@dataclass(frozen=True)
class Entry:
    catalog_number: int
    dde_name: str
    name: str
    key: str  #: casefolded DDE name and name, for matching

    @property
    def label(self) -> Text:
        return Text(f"{self.dde_name[:12]:12} {self.catalog_number:>6}  {self.name}")


def build_index(satellites: Iterable[Satellite]) -> list[Entry]:
    """One entry per satellite, in catalog order."""
    return [Entry(s.catalog_number, s.dde_name, s.name, f"{s.dde_name}\n{s.name}".casefold()) for s in satellites]


def search(index: Sequence[Entry], query: str, first: Sequence[int] = (), limit: int = MAX_SHOWN
           ) -> tuple[list[Entry], int]:
    """(entries to show, number of matches).

    An empty query lists ``first`` (the current satellite, then favourites) and then the catalog.
    Otherwise: catalog numbers starting with the digits typed, and names containing the text;
    an exact number or a name starting with the text comes first.
    """
    text = query.strip().casefold()
    if not text:
        by_number = {e.catalog_number: e for e in index}
        head = [by_number[n] for n in dict.fromkeys(first) if n in by_number]
        seen = {e.catalog_number for e in head}
        rest = (e for e in index if e.catalog_number not in seen)
        shown = head[:limit]
        for entry in rest:
            if len(shown) >= limit:
                break
            shown.append(entry)
        return shown, len(index)
    exact: list[Any] = []
    prefix: list[Any] = []
    other: list[Any] = []
    digits = text.isascii() and text.isdigit()
    for e in index:
        if digits and str(e.catalog_number).startswith(text):
            (exact if e.catalog_number == int(text) else prefix).append(e)
        elif text in e.key:
            (prefix if e.key.startswith(text) or f"\n{text}" in e.key else other).append(e)
    matches = exact + prefix + other
    return matches[:limit], len(matches)


class SatellitePicker(ModalScreen[int | None]):
    """Dismissed with the chosen catalog number, or None on Esc."""

    DEFAULT_CSS = """
    SatellitePicker { align: center middle; }
    #picker-box { width: 90%; max-width: 80; height: 80%; border: round $warning; background: $surface; }
    #picker-list { height: 1fr; }
    #picker-count { height: 1; color: $text-muted; }
    """
    BINDINGS = [Binding("escape", "close", "Close", priority=True),
                Binding("down", "move(1)", show=False, priority=True),
                Binding("up", "move(-1)", show=False, priority=True),
                Binding("pagedown", "move(10)", show=False, priority=True),
                Binding("pageup", "move(-10)", show=False, priority=True)]

    def __init__(self, satellites: Iterable[Satellite], current: int | None, favourites: Sequence[int] = ()) -> None:
        super().__init__()
        self.index = build_index(satellites)
        self.first = [n for n in (current, *favourites) if n is not None]
        self.current = current

    def compose(self) -> ComposeResult:
        with Vertical(id="picker-box"):
            yield Input(placeholder="type a name or catalog number; Enter picks, Esc closes", id="picker-search")
            yield Static(id="picker-count")
            yield OptionList(id="picker-list")

    def on_mount(self) -> None:
        self.query_one("#picker-box").border_title = "Satellites"
        self._show("")
        self.query_one("#picker-search", Input).focus()

    def _show(self, query: str) -> None:
        shown, total = search(self.index, query, self.first)
        options = self.query_one("#picker-list", OptionList)
        options.clear_options()
        options.add_options([Option(e.label, id=str(e.catalog_number)) for e in shown])
        if shown:
            options.highlighted = 0
        what = "satellites" if not query.strip() else "matches"
        more = f", first {len(shown)} listed: type more to narrow" if total > len(shown) else ""
        self.query_one("#picker-count", Static).update(Text(f"{total} {what}{more}"))

    def on_input_changed(self, message: Input.Changed) -> None:
        self._show(message.value)

    def on_input_submitted(self, message: Input.Submitted) -> None:
        message.stop()
        options = self.query_one("#picker-list", OptionList)
        option = options.highlighted_option
        self.dismiss(int(option.id) if option is not None and option.id else None)

    def on_option_list_option_selected(self, message: OptionList.OptionSelected) -> None:
        message.stop()
        self.dismiss(int(message.option.id) if message.option.id else None)

    def action_move(self, step: int) -> None:
        options = self.query_one("#picker-list", OptionList)
        if options.option_count:
            current = options.highlighted if options.highlighted is not None else 0
            options.highlighted = min(max(current + step, 0), options.option_count - 1)

    def action_close(self) -> None:
        self.dismiss(None)
