"""The Textual console of ``nfwserver run``.

Shows what Nova's diagnostic screens showed and more: the live session state (satellite, look
angles, range rate, AH, Doppler at the satellite's beacon frequency when known, tune/track, status
word, antenna position, clients, next pass), the outgoing strings (F1) and the incoming strings
with the conversation that sent them (F3).  The input line at the bottom takes the same commands
a client pokes (``TUNE ON``, ``SAT=27607`` ...).

Events arrive on the server's threads; they are queued and drained on the UI thread by a timer,
so a flood of strings at 50 Hz never blocks the publisher.
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Callable
from datetime import datetime, timedelta

from rich.text import Text
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.widgets import Footer, Header, Input, OptionList, RichLog, Static
from textual.widgets.option_list import Option

from nfwserver.console.skyplot import render_sky
from nfwserver.core.events import Direction, Event
from nfwserver.core.nova_protocol import escape_for_log
from nfwserver.core.station_core import StationCore
from nfwserver.core.status import describe
from nfwserver.radio.coupling import RadioCoupling
from nfwserver.rotor.coupling import RotorCoupling
from nfwserver.tracking.doppler import doppler_shift_hz
from nfwserver.tracking.look_angles import LookAngleCalculator
from nfwserver.tracking.passes import Pass, find_passes


def _clock(when: datetime | None) -> str:
    return when.strftime("%H:%M:%S") if when else "--:--:--"


class NfwConsole(App):
    """The console; give it the running server."""

    TITLE = "nfwserver"
    CSS = """
    #state { height: auto; border: round $accent; padding: 0 1; }
    #logs { height: 1fr; }
    .pane { width: 1fr; border: round $primary; }
    #side { width: 40; border: round $primary; }
    #picker { height: 12; display: none; border: round $warning; }
    #picker.shown { display: block; }
    #poke { dock: bottom; }
    """
    BINDINGS = [
        Binding("f1", "focus_outgoing", "Outgoing (F1)"),
        Binding("f3", "focus_incoming", "Incoming (F3)"),
        Binding("f2", "pick_satellite", "Satellites (F2)"),
        Binding("ctrl+t", "toggle_tune", "Tune on/off"),
        Binding("ctrl+d", "toggle_doppler", "Doppler tuning"),
        Binding("ctrl+q", "quit", "Quit"),
    ]

    def __init__(self, core: StationCore, transport_note: str = "", hint: str = "",
                 radio: RadioCoupling | None = None, rotor: RotorCoupling | None = None,
                 favourites: tuple[int, ...] = (), clients: Callable[[], tuple[int, int]] | None = None) -> None:
        super().__init__()
        self.clients = clients or (lambda: (0, 0))
        self.favourites = favourites
        self._passes_key: int | None = None
        self.core = core
        self.radio = radio
        self.rotor = rotor
        self.transport_note = transport_note
        self.hint = hint
        self._queue: collections.deque[Event] = collections.deque(maxlen=2000)
        self._lock = threading.Lock()
        self._unsubscribe = None
        self._next_pass: Pass | None = None
        self._pass_key: tuple[int | None, int] | None = None

    def compose(self) -> ComposeResult:
        yield Header(show_clock=False)
        yield Static(id="state")
        with Horizontal(id="logs"):
            with Vertical(classes="pane"):
                yield Static("[b]F1 outgoing[/b]")
                yield RichLog(id="outgoing", max_lines=500, wrap=False, markup=False)
            with Vertical(classes="pane"):
                yield Static("[b]F3 incoming[/b]")
                yield RichLog(id="incoming", max_lines=500, wrap=True, markup=False)
            with Vertical(id="side"):
                yield Static("[b]Upcoming passes[/b]")
                yield Static(id="passes")
                yield Static("[b]Sky (selected satellite)[/b]")
                yield Static(id="sky")
        yield OptionList(id="picker")
        yield Input(placeholder="poke: TUNE ON | TUNE OFF | TRACK ON | SAT=25544 | ANTAZ=123 ...", id="poke")
        yield Footer()

    def on_mount(self) -> None:
        self._unsubscribe = self.core.events.subscribe(self._enqueue)
        incoming = self.query_one("#incoming", RichLog)
        for note in (self.transport_note, self.hint):
            if note:
                incoming.write(Text(f"note: {note}", style="yellow"))
        self.set_interval(0.1, self._drain)
        self.set_interval(0.25, self._refresh_state)
        self._refresh_state()
        picker = self.query_one("#picker", OptionList)
        for sat in self.core.state.catalog:
            label = f"{sat.dde_name:12} {sat.catalog_number:>6}  {sat.name}"
            picker.add_option(Option(label, id=str(sat.catalog_number)))
        self.query_one("#poke", Input).focus()

    def on_unmount(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()

    def _enqueue(self, event: Event) -> None:  # any thread
        with self._lock:
            self._queue.append(event)

    def _drain(self) -> None:
        with self._lock:
            events = list(self._queue)
            self._queue.clear()
        outgoing = self.query_one("#outgoing", RichLog)
        incoming = self.query_one("#incoming", RichLog)
        for e in events:
            stamp = _clock(e.time)
            if e.direction is Direction.OUT:
                who = f" -> {e.client}" if e.client else ""
                outgoing.write(f"{stamp} {e.text}{who}")
            else:
                mark = "" if e.accepted is None else (" ok" if e.accepted else " REFUSED")
                detail = f" ({e.detail})" if e.detail and not e.accepted else ""
                who = e.client or "server"
                style = "red" if e.accepted is False else ("dim" if e.direction is Direction.INFO else "")
                incoming.write(Text(f"{stamp} [{who}] {escape_for_log(e.text)}{mark}{detail}", style=style))

    def _upcoming_pass(self, now: datetime) -> Pass | None:
        snap = self.core.snapshot()
        key = (snap.catalog_number, int(now.timestamp() // 60))
        if key != self._pass_key:
            self._pass_key = key
            self._next_pass = None
            sat = self.core.state.catalog.get(snap.catalog_number) if snap.catalog_number else None
            if sat is not None and self.core.state.observer is not None:
                passes = find_passes([sat], self.core.state.observer, now, now + timedelta(hours=24),
                                     horizon=self.core.state.horizon, ut1_utc=self.core.state.ut1_utc_s)
                self._next_pass = next((p for p in passes if p.los is None or p.los > now), None)
        return self._next_pass

    def _refresh_state(self) -> None:
        snap = self.core.snapshot()
        sample = snap.last_sample
        now = self.core.clock.now()
        lines = []
        sat = f"{snap.dde_name} ({snap.catalog_number})" if snap.catalog_number else "none selected"
        conversations, loops = self.clients()
        lines.append(f"Satellite {sat}   TUNE {'ON' if snap.state.dde_output else 'OFF'}   "
                     f"TRACK {'ON' if snap.state.tracking else 'OFF'}   rate {snap.state.rate_hz:g} Hz   "
                     f"clients {conversations} ({loops} advise)")
        if sample is not None and sample.look_angles is not None:
            la = sample.look_angles
            lines.append(f"AZ {la.azimuth_deg:6.1f}  EL {la.elevation_deg:5.1f}  RR {la.range_rate_km_s:+.4f} km/s  "
                         f"range {la.range_km:8.1f} km  AH {'Y' if sample.above_horizon else 'N'}  "
                         f"Doppler@145.8MHz {doppler_shift_hz(145.8e6, la.range_rate_km_s):+.0f} Hz")
        else:
            lines.append("no position (no satellite, no observer, or SGP4 error)")
        ant = snap.state.antenna
        ant_text = (f"{ant.azimuth_deg if ant.azimuth_deg is not None else '-'} / "
                    f"{ant.elevation_deg if ant.elevation_deg is not None else '-'} ({ant.source or 'unknown'})")
        nxt = self._upcoming_pass(now)
        if nxt is not None:
            pass_text = (f"AOS {_clock(nxt.aos)}  TCA {_clock(nxt.tca)} max {nxt.max_elevation_deg:.0f}deg  "
                         f"LOS {_clock(nxt.los)}")
        else:
            pass_text = "no pass in the next 24 h"
        lines.append(f"Antenna {ant_text}   next pass: {pass_text}")
        if self.rotor is not None:
            driver = self.rotor.driver
            _, _, tgt_el, tgt_az = driver.positions()
            pos = driver.rotor_position()
            bits = driver.status().bits
            target = f"{tgt_az:.1f}/{tgt_el:.1f}" if tgt_az is not None else "-"
            actual = f"{pos[0]:.1f}/{pos[1]:.1f}" if pos is not None else "unreachable"
            lines.append(f"Rotor: target {target}  actual {actual}  flip {'ON' if self.rotor.flip_state else 'off'}"
                         f"  KCT status 0x{int(bits):02X}")
        if self.radio is not None:
            r = self.radio.last_result
            state = "ON" if snap.state.radio_tuning else "OFF"
            if not self.radio.tuner.available:
                radio_text = f"Radio: Doppler tuning {state}, radio unreachable ({self.radio.tuner.last_error})"
            elif r is not None:
                tx = f" TX {r.tx_hz / 1e6:.6f} MHz" if r.tx_hz else ""
                radio_text = f"Radio: Doppler tuning {state}, RX {r.rx_hz / 1e6:.6f} MHz{tx}"
            else:
                radio_text = f"Radio: Doppler tuning {state}"
            lines.append(radio_text)
        self._refresh_side(now)
        current = None
        if sample is not None and sample.look_angles is not None:
            current = (sample.look_angles.azimuth_deg, sample.look_angles.elevation_deg)
        self.query_one("#sky", Static).update(render_sky(getattr(self, "_track", []), current))
        status = ", ".join(describe(snap.status)) or "ok"
        lines.append(f"Status 0x{snap.status:04X}: {status}   {_clock(now)} UTC")
        self.query_one("#state", Static).update("\n".join(lines))

    def on_input_submitted(self, message: Input.Submitted) -> None:
        text = message.value.strip()
        message.input.value = ""
        if text:
            self.core.command(text, source="console")
            self._drain()
            self._refresh_state()

    def action_pick_satellite(self) -> None:
        picker = self.query_one("#picker", OptionList)
        picker.toggle_class("shown")
        if picker.has_class("shown"):
            picker.focus()
        else:
            self.query_one("#poke", Input).focus()

    def on_option_list_option_selected(self, message: OptionList.OptionSelected) -> None:
        if message.option.id:
            self.core.command(f"SAT={message.option.id}", source="console")
        message.option_list.remove_class("shown")
        self.query_one("#poke", Input).focus()
        self._passes_key = None
        self._drain()
        self._refresh_state()

    def _refresh_side(self, now: datetime) -> None:
        """Upcoming passes of the favourites and the sky plot, recomputed once a minute."""
        snap = self.core.snapshot()
        key = int(now.timestamp() // 60) * 1_000_000 + (snap.catalog_number or 0)
        if key == self._passes_key or self.core.state.observer is None:
            return
        self._passes_key = key
        selected = [snap.catalog_number] if snap.catalog_number else []
        wanted = list(dict.fromkeys([*self.favourites, *selected]))
        sats = [s for s in (self.core.state.catalog.get(n) for n in wanted) if s is not None]
        lines = []
        if sats:
            passes = find_passes(sats, self.core.state.observer, now, now + timedelta(hours=12),
                                 horizon=self.core.state.horizon, ut1_utc=self.core.state.ut1_utc_s)
            for p in [p for p in passes if p.los is None or p.los > now][:8]:
                name = self.core.state.catalog.get(p.catalog_number).dde_name
                lines.append(f"{name:12} {_clock(p.aos)} {p.max_elevation_deg:3.0f}deg {_clock(p.los)}")
        self.query_one("#passes", Static).update("\n".join(lines) or "none in the next 12 h")
        sat = self.core.state.catalog.get(snap.catalog_number) if snap.catalog_number else None
        track: list[tuple[float, float]] = []
        nxt = self._upcoming_pass(now)
        if sat is not None and nxt is not None and nxt.aos is not None and nxt.los is not None:
            calc = LookAngleCalculator(self.core.state.observer, self.core.state.ut1_utc_s)
            t = nxt.aos
            while t <= nxt.los:
                la = calc.compute(sat.satrec, t)
                track.append((la.azimuth_deg, la.elevation_deg))
                t += timedelta(seconds=20)
        self._track = track

    def action_focus_outgoing(self) -> None:
        self.query_one("#outgoing", RichLog).focus()

    def action_focus_incoming(self) -> None:
        self.query_one("#incoming", RichLog).focus()

    def action_toggle_doppler(self) -> None:
        if self.radio is not None:
            self.core.set_radio_tuning(not self.core.state.radio_tuning, source="console")

    def action_toggle_tune(self) -> None:
        self.core.command("TUNE OFF" if self.core.snapshot().state.dde_output else "TUNE ON", source="console")
