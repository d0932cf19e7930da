"""The Textual console of ``nfwserver run``.

Shows what Nova's diagnostic screens showed and more: the live session state (satellite, tune and
track, clients), InstantTrack's realtime values for the selected satellite (look angles, range,
sub-satellite point and locator, orbit number, phase, mode, sunlit, and Doppler and path loss at the
satellite's own downlink channel), the antenna, rotor (flip state, suspension) and radio, the outgoing
strings (F1) and the incoming strings with the conversation that sent them (F3), the passes of the
favourites with a sky plot.  The input line at the bottom takes the commands the table lets the console
send (a client's, plus the console's own: ``HELP`` lists them); the keys (F2's picker, F4, Ctrl+T, Ctrl+D,
Ctrl+F) act through the same table entries, handing the core the entry and its argument with no text.

Threads: events arrive on the server's threads and are queued, then drained on the UI thread by a
timer, so a flood of strings at 50 Hz never blocks the publisher.  Pass searches and the sky track
run on a worker thread (:mod:`nfwserver.console.pass_view`); key handling never waits for them.
Every name is shown as literal text (never parsed as markup).

On a narrow terminal (< 110 columns) one log pane is shown at a time (F1/F3 choose), F1's beside no pass
list, so that each Nova string takes one row; on a short one (< 34 lines) the sky plot is left out.  The
console works from 80x24, where no line of the header wraps; HELP opens a screen of its own.
"""

from __future__ import annotations

import collections
import logging
import threading
from collections.abc import Callable, Mapping, Sequence
from datetime import datetime, tzinfo
from functools import partial
from typing import Any

from rich.text import Text
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.css.query import NoMatches
from textual.widgets import Footer, Input, RichLog, Static

from nfwserver.commands.help_text import input_hint
from nfwserver.commands.parsing import Request
from nfwserver.commands.table import (
    DOPPLER_SWITCH,
    FEED_SWITCH,
    FLIP_MODE,
    SATELLITE_CHOICE,
    ZONE_TOGGLE,
    Command,
    Face,
    escape_for_log,
)
from nfwserver.console.command_port import ConsolePort
from nfwserver.console.help_screen import HelpScreen
from nfwserver.console.pass_view import LEGEND, STALE_DAYS, PassSearch, next_pass_text, pass_table, search_passes
from nfwserver.console.picker import SatellitePicker
from nfwserver.console.reflow_log import ReflowLog
from nfwserver.console.skyplot import render_sky
from nfwserver.console.state_view import (
    antenna_lines,
    elements_line,
    fit,
    guarded,
    outputs_line,
    radio_line,
    realtime,
    realtime_lines,
    rotor_line,
    satellite_line,
    status_line,
)
from nfwserver.console.time_display import TimeDisplay
from nfwserver.core.events import Direction, Event
from nfwserver.core.faces import CountsClients, WritesLines
from nfwserver.core.station_core import CommandResult, StationCore
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.rotor.coupling import FLIP_MODES, RotorCoupling

log = logging.getLogger(__name__)

NARROW_COLUMNS = 110
SHORT_LINES = 34


class NfwConsole(App[None]):
    """The console; give it the running station's core and adapters."""

    TITLE = "nfwserver"
    CSS = """
    #state { height: auto; border: round $accent; padding: 0 1; }
    #logs { height: 1fr; }
    .pane { width: 1fr; border: round $primary; }
    .hidden { display: none; }
    #side { width: 38; border: round $primary; padding: 0 1; }
    #poke { border: none; height: 1; padding: 0 1; }
    """
    ENABLE_COMMAND_PALETTE = False  # every action has a key in the footer; ^p would cost its width
    #: footer labels kept short so that every key shows on an 80-column terminal
    BINDINGS = [
        Binding("f1", "show_outgoing", "Out", priority=True),
        Binding("f2", "pick_satellite", "Sats", priority=True),
        Binding("f3", "show_incoming", "In", priority=True),
        Binding("f4", "toggle_zone", "Zone", priority=True),
        Binding("ctrl+t", "toggle_feed", "Tune", priority=True),
        Binding("ctrl+d", "toggle_doppler", "Doppler", priority=True),
        Binding("ctrl+f", "cycle_flip", "Flip", priority=True),
        Binding("ctrl+q", "quit", "Quit", priority=True),
        Binding("pageup", "scroll_log(-1)", "Page up", show=False, priority=True),
        Binding("pagedown", "scroll_log(1)", "Page down", show=False, priority=True),
        Binding("z", "toggle_zone", "UTC/local", show=False),
    ]

    def __init__(self, core: StationCore, transport_note: str = "", hint: str = "",
                 radio: RadioCoupling | None = None, rotor: RotorCoupling | None = None,
                 favourites: tuple[int, ...] = (), clients: Callable[[], tuple[int, int]] | None = None, *,
                 tcp: CountsClients | None = None, easycomm: WritesLines | None = None, config_file: str = "",
                 schedules: Mapping[int, str] | None = None, local_zone: tzinfo | None = None,
                 stale_days: float = STALE_DAYS) -> None:
        super().__init__()
        self.core = core
        self.transport_note = transport_note
        self.hint = hint
        self.radio = radio
        self.rotor = rotor
        self.favourites = favourites
        self.clients = clients or (lambda: (0, 0))
        self.tcp = tcp
        self.easycomm = easycomm
        self.config_file = config_file
        self.schedules = dict(schedules or {})
        self.times = TimeDisplay(local_zone)
        self.stale_days = stale_days  #: element sets older than this are marked in the pass list
        self.failure: BaseException | None = None  #: the exception that stopped the console, if one did
        self._queue: collections.deque[Event] = collections.deque(maxlen=2000)
        self._lock = threading.Lock()
        self._port = ConsolePort(self._show_help, self._toggle_zone)  #: the help and zone entries' target
        self._unsubscribe: Callable[[], None] | None = None
        self._search: PassSearch | None = None
        self._search_key: tuple[Any, ...] | None = None
        self._shown_log = "incoming"

    # -- layout -------------------------------------------------------------------------------
    def compose(self) -> ComposeResult:
        yield Static(id="state")
        with Horizontal(id="logs"):
            with Vertical(id="outgoing-pane", classes="pane"):
                yield ReflowLog(id="outgoing", max_lines=500)
            with Vertical(id="incoming-pane", classes="pane"):
                yield ReflowLog(id="incoming", max_lines=500)
            with Vertical(id="side"):
                yield Static(id="passes")
                yield Static(id="sky")
        yield Input(placeholder=input_hint(Face.CONSOLE), id="poke")
        yield Footer()

    def on_mount(self) -> None:
        self.query_one("#state").border_title = "nfwserver"
        self.query_one("#outgoing-pane").border_title = "F1 outgoing"
        self.query_one("#incoming-pane").border_title = "F3 incoming"
        self.query_one("#side").border_title = "Passes"
        self.query_one("#side").border_subtitle = LEGEND
        self._unsubscribe = self.core.events.subscribe(self._enqueue)
        self.set_interval(0.1, partial(self._while_shown, self._drain))
        self.set_interval(0.25, partial(self._while_shown, self._refresh_state))
        self._layout()
        self.call_after_refresh(self._write_notes)
        self._refresh_state()
        self.query_one("#poke", Input).focus()

    def _write_notes(self) -> None:
        """First-run notes, written once the pane has its width, so they wrap to it."""
        incoming = self.query_one("#incoming", ReflowLog)
        for note in (self.transport_note, self.hint):
            if note:
                incoming.add(Text(f"note: {note}", style="yellow"))

    def on_resize(self) -> None:
        self._layout()
        self.call_after_refresh(partial(self._while_shown, self._refresh_state))  # fitted to the new width

    def _layout(self) -> None:
        narrow = self.size.width < NARROW_COLUMNS
        self.query_one("#outgoing-pane").set_class(narrow and self._shown_log != "outgoing", "hidden")
        self.query_one("#incoming-pane").set_class(narrow and self._shown_log != "incoming", "hidden")
        self.query_one("#sky").set_class(self.size.height < SHORT_LINES, "hidden")
        # F1 on a narrow terminal takes the width of the passes too: a Nova string and its time on one row
        self.query_one("#side").set_class(narrow and self._shown_log == "outgoing", "hidden")

    def on_unmount(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()

    def _handle_exception(self, error: Exception) -> None:
        """Remember what stopped the console; ``nfwserver run`` reports it and carries on headless."""
        self.failure = error
        super()._handle_exception(error)
        self._exit_renderables.clear()  # one sentence from the run command instead of a screenful

    # -- events -------------------------------------------------------------------------------
    def _enqueue(self, event: Event) -> None:  # any thread
        with self._lock:
            self._queue.append(event)

    def _drain(self) -> None:
        with self._lock:
            events = list(self._queue)
            self._queue.clear()
        outgoing = self.query_one("#outgoing", ReflowLog)
        incoming = self.query_one("#incoming", ReflowLog)
        for e in events:
            stamp = self.times.clock(e.time)
            if e.direction is Direction.OUT:
                who = f" -> {e.client}" if e.client else ""
                outgoing.add(Text(f"{stamp} {e.text}{who}"))
            else:
                mark = "" if e.accepted is None else (" ok" if e.accepted else " REFUSED")
                detail = f" ({e.detail})" if e.detail and not e.accepted else ""
                who = e.client or "server"
                style = "red" if e.accepted is False else ("dim" if e.direction is Direction.INFO else "")
                incoming.add(Text(f"{stamp} [{who}] {escape_for_log(e.text)}{mark}{detail}", style=style))

    @staticmethod
    def _while_shown(update: Callable[[], None]) -> None:
        """Run a timer's screen update; a tick that lands while the app closes finds its widgets gone
        (textual's NoMatches) and is skipped."""
        try:
            update()
        except NoMatches:
            pass

    def _note(self, text: str, style: str = "yellow") -> None:
        self.query_one("#incoming", ReflowLog).add(Text(f"{self.times.clock(self.core.clock.now())} {text}",
                                                        style=style))

    # -- the state pane ---------------------------------------------------------------------------
    def _refresh_state(self) -> None:
        snap = self.core.snapshot()
        now = self.core.clock.now()
        catnr = snap.catalog_number
        self._maybe_search(now, catnr)
        search = self._search if self._search is not None and self._search.selected == catnr else None
        sample = snap.last_sample
        above = sample.above_horizon if sample is not None and sample.catalog_number == catnr else None
        width = self.query_one("#state").content_region.width  #: 0 before the first layout: no limit yet
        lines: list[Text | None] = [guarded("Satellite", lambda: satellite_line(snap, self.core, self.clients(),
                                                                                width))]
        values, why = realtime(self.core, catnr, now, self.schedules.get(catnr) if catnr is not None else None)
        lines.extend(realtime_lines(values, why, self.core, catnr, above, width))
        lines.append(Text(next_pass_text(search, self.times, now)))
        lines.append(elements_line(self.core, catnr, now, self.stale_days))
        radio = guarded("Radio", lambda: radio_line(self.radio, snap.state.doppler_on))
        lines.extend(antenna_lines(snap, radio or Text(), width))
        if self.rotor is not None:
            lines.append(guarded("Rotor", partial(rotor_line, self.rotor)))
        lines.append(guarded("Outputs", lambda: outputs_line(self.tcp, self.easycomm)))
        lines.append(status_line(snap, self.times, now))
        shown = [fit(line, width) for line in lines if line is not None]  # none wraps
        self.query_one("#state", Static).update(Text("\n").join(shown))
        self.query_one("#side").border_title = f"Passes ({self.times.zone(now)})"
        self.query_one("#passes", Static).update(pass_table(self._search, self.core.state.catalog, self.times, now,
                                                                 self.stale_days))
        current = (values.azimuth_deg, values.elevation_deg) if values is not None else None
        track = search.track if search is not None else []
        self.query_one("#sky", Static).update(Text(render_sky(track, current)))

    # -- pass searches on a worker thread -----------------------------------------------------------
    def _maybe_search(self, now: datetime, catnr: int | None) -> None:
        state = self.core.state
        if state.observer is None:
            return
        key = (int(now.timestamp() // 60), catnr, id(state.observer), len(state.catalog))
        if key == self._search_key:
            return
        self._search_key = key
        args = (state.catalog, state.observer, state.horizon, state.ut1_utc_s, self.favourites, catnr, now)
        self.run_worker(partial(self._search_thread, *args), thread=True, group="passes", exclusive=True,
                        exit_on_error=False)

    def _search_thread(self, *args: Any) -> None:  # worker thread
        try:
            result = search_passes(*args)
        except Exception:
            log.exception("console: pass search failed")
            return
        try:
            self.call_from_thread(self._searched, result)
        except RuntimeError:  # the app is closing
            pass

    def _searched(self, result: PassSearch) -> None:
        if self._search is None or result.now >= self._search.now or result.selected != self._search.selected:
            self._search = result
            self._refresh_state()

    # -- commands -----------------------------------------------------------------------------------
    def on_input_submitted(self, message: Input.Submitted) -> None:
        text = message.value.strip()
        message.input.value = ""
        if text:  # the core parses it as the console's, runs it through the command table and records it
            self._answered(self.core.command(text, source="console", face=Face.CONSOLE, session=self._port,
                                             display=self._port))

    def _key(self, entry: Command, value: object) -> None:
        """A key's command: its table entry and argument, run as the typed command would be, with no text."""
        self._answered(self.core.execute(Request.of(entry, value, Face.CONSOLE), source="console",
                                         session=self._port, display=self._port))

    def _answered(self, result: CommandResult) -> None:
        """The incoming pane shows the core's record of the command (refused with the reason); a warning of an
        accepted command is noted too."""
        if result.warning and result.note:
            where = f" (configuration: {self.config_file})" if self.config_file else ""
            self._note(f"warning: {result.note}{where}")
        self._drain()
        self._refresh_state()

    def _show_help(self, lines: Sequence[str]) -> None:
        """HELP's answer in a screen of its own, the terminal's whole width (the log panes are too narrow)."""
        if not isinstance(self.screen, HelpScreen):
            self.push_screen(HelpScreen(lines), self._help_closed)

    def _help_closed(self, _: None) -> None:
        self.query_one("#poke", Input).focus()

    def action_pick_satellite(self) -> None:
        if isinstance(self.screen, (SatellitePicker, HelpScreen)):
            return
        picker = SatellitePicker(self.core.state.catalog, self.core.state.catalog_number, self.favourites)
        self.push_screen(picker, self._picked)

    def _picked(self, catalog_number: int | None) -> None:
        if catalog_number is not None:
            self._key(SATELLITE_CHOICE, catalog_number)
        self.query_one("#poke", Input).focus()

    def _show_log(self, which: str) -> None:
        """Show (on a narrow terminal) the ``which`` log; Page Up/Down scroll it.  The command line keeps
        the focus, so typing goes on where it was."""
        self._shown_log = which
        self._layout()
        if not isinstance(self.screen, SatellitePicker):
            self.query_one("#poke", Input).focus()

    def action_scroll_log(self, pages: int) -> None:
        log_pane = self.query_one(f"#{self._shown_log}", RichLog)
        if pages < 0:
            log_pane.scroll_page_up(animate=False)
        else:
            log_pane.scroll_page_down(animate=False)

    def action_show_outgoing(self) -> None:
        self._show_log("outgoing")

    def action_show_incoming(self) -> None:
        self._show_log("incoming")

    def action_toggle_zone(self) -> None:
        self._key(ZONE_TOGGLE, None)

    def _toggle_zone(self) -> None:
        """The display's side of the zone entry: times in UTC or in the local zone."""
        self.times.toggle()
        self._note(f"times now in {self.times.zone(self.core.clock.now())}", "dim")
        self._refresh_state()

    def action_toggle_doppler(self) -> None:
        self._key(DOPPLER_SWITCH, not self.core.state.doppler_on)

    def action_toggle_feed(self) -> None:
        self._key(FEED_SWITCH, not self.core.snapshot().state.feed_on)

    def action_cycle_flip(self) -> None:
        """The next flip mode (auto, on, off), through the flip entry as if typed on the input line."""
        order = list(FLIP_MODES)
        current = self.rotor.flip_mode if self.rotor is not None else order[-1]
        self._key(FLIP_MODE, order[(order.index(current) + 1) % len(order)])
