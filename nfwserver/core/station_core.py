"""The station core: the live state, the tracker, the event stream and the command port, together.

:class:`StationCore` is what every output adapter is given.  Adapters read the state
(:attr:`StationCore.state`), subscribe to ticks (:meth:`StationCore.subscribe`) and talk back
through narrow ports: :meth:`command` (the text a face received, parsed once) or :meth:`execute` (a
parsed request, or a console key's entry and argument), :meth:`report_antenna_position` for the rotor's
read-back.  No adapter keeps its own copy of the station, and none records a command itself.

Every command is run through its entry's check and action in the command table
(:mod:`nfwserver.commands`) and recorded here as one event: Nova's ``TUNE ON|OFF`` (the DDE output),
``TRACK ON|OFF`` (autotracking), ``SAT=<catalog number>``, ``ANTAZ=<deg>``, ``ANTEL=<deg>`` and the radio's
``DOPPLER ON|OFF`` and ``AUTO ON|OFF`` on the station; ``FLIP``/``PARK`` on the rotor; the TCP session's and
the console's own commands on the session or display the face passes.
``TRACK ON`` is an OrbitDRV enable call: "ignored if the station or satellite parameters have not
been set".  It is then acknowledged (a client without error handling must not die on it) but does
nothing, and the reason is logged, recorded in the event stream and returned in
:attr:`CommandResult.note`.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from datetime import datetime

from nfwserver.channels.channel import Channel
from nfwserver.clock import Clock
from nfwserver.commands.actions import (
    NO_ROTOR,
    AutotrackSwitch,
    DisplayPort,
    Refused,
    RotorControl,
    SessionPort,
    Targets,
)
from nfwserver.commands.parsing import Parsed, Request, parse_request
from nfwserver.commands.table import Face, Target, escape_for_log
from nfwserver.core.events import Direction, EventLog
from nfwserver.core.sample import TickSample
from nfwserver.core.state import DEFAULT_RATE_HZ, StateSnapshot, StationState
from nfwserver.core.status import INTERFACE_VERSION, StatusBit
from nfwserver.core.tracker import TickListener, Tracker
from nfwserver.health.board import HealthBoard
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.tracking.catalog import Catalog
from nfwserver.tracking.horizon import HorizonTable
from nfwserver.tracking.observer import Observer

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class CommandResult:
    """The answer to one command string."""

    accepted: bool  #: understood and acknowledged (DDE_FACK); False: refused (DDE_FNOTPROCESSED)
    note: str | None  #: why it was refused, why an acknowledged command had no effect, or a warning
    status: int  #: the status word after the command (with 0x4000/0x8000 for a bad function/subfunction)
    #: the note is a warning on a command that took effect (``TRACK ON`` with no rotor configured)
    warning: bool = False

    @property
    def ok(self) -> bool:
        """Accepted and took effect, with nothing to add."""
        return self.accepted and self.note is None


@dataclass(frozen=True)
class CoreSnapshot:
    """What the console and status commands show, read consistently."""

    state: StateSnapshot
    last_sample: TickSample | None
    status: int
    interface_version: int = INTERFACE_VERSION

    @property
    def catalog_number(self) -> int | None:
        return self.state.catalog_number

    @property
    def dde_name(self) -> str | None:
        return self.state.satellite.dde_name if self.state.satellite is not None else None


class StationCore:
    """State + tracker + events + commands; see the module docstring."""

    def __init__(self, catalog: Catalog, observer: Observer | None, clock: Clock, *,
                 horizon: HorizonTable | None = None, ut1_utc: float = 0.0, rate_hz: float = DEFAULT_RATE_HZ,
                 channels: Mapping[int, Channel] | None = None, events: EventLog | None = None,
                 satellite: int | None = None) -> None:
        self.clock = clock
        self.events = events if events is not None else EventLog()
        self.state = StationState(catalog, observer, horizon=horizon, ut1_utc_s=ut1_utc, rate_hz=rate_hz,
                                  channels=channels)
        #: Every link's health (rotor, radio, element sources, state file, listeners, the tracker's own
        #: computation): what STATUS, the console and the web page show while a fault lasts.
        self.health = HealthBoard(clock)
        self.health.subscribe(self._health_changed)
        self.tracker = Tracker(self.state, clock, self.events, self.health.link("tracking", paced=False))
        #: Refused commands: one warning per client at once, then a counted summary at most once a minute
        #: (every refusal is still an event).
        self._refusals = RateLimitedLog(log, clock, 60.0)
        #: whether the station drives a rotor itself (set by the station; None: not known, no warning)
        self.rotor_configured: bool | None = None
        #: whether the station drives a radio itself (set by the station; None: not known, no warning)
        self.radio_configured: bool | None = None
        #: the station's autotrack, switched by AUTO ON/OFF and off by any accepted SAT= (set by the station)
        self.autotrack: AutotrackSwitch | None = None
        #: one choice of the satellite at a time: a client's SAT= (which switches autotrack off) or autotrack's
        self._choosing = threading.Lock()
        #: the rotor's command port for FLIP and PARK (set by the station; None: no rotor)
        self.rotor: RotorControl | None = None
        #: run before each request is checked: the station applies a configuration file changed a moment ago
        #: (``config set`` then a command: the command sees the change), see Station.catch_up_config
        self.before_command: Callable[[], None] = lambda: None
        if satellite is not None:
            self.state.set_selected_by("config")
        if satellite is not None and not self.select_satellite(satellite, source="startup"):
            log.warning("satellite %s is not in the catalog; no satellite selected", satellite)

    # -- reading -----------------------------------------------------------------------------
    @property
    def catalog(self) -> Catalog:
        return self.state.catalog

    def subscribe(self, listener: TickListener) -> Callable[[], None]:
        return self.tracker.subscribe(listener)

    def tick(self, when: datetime | None = None) -> TickSample:
        return self.tracker.tick(when)

    def current_text(self) -> str:
        return self.tracker.current_text()

    def snapshot(self) -> CoreSnapshot:
        return CoreSnapshot(self.state.snapshot(), self.tracker.last_sample, self.tracker.status_word())

    def _health_changed(self, link: object) -> None:
        name, fault = getattr(link, "name", "?"), getattr(link, "fault", None)
        text = f"{name}: recovered" if fault is None else f"{name}: {fault.reason}"
        self._note(text, "health", accepted=fault is None)

    # -- ports -------------------------------------------------------------------------------
    def _note(self, text: str, source: str, accepted: bool | None = None) -> None:
        self.events.add(self.clock.now(), Direction.INFO, "note", text, client=source, accepted=accepted)

    def set_feed(self, on: bool, source: str = "console") -> None:
        """Nova's TUNE ON/OFF: switch the feed (the Nova string published to every output) on or off."""
        if not on:
            self.tracker.feed_off()
        if self.state.set_feed(on):
            self.tracker.refresh_text()  # a request right after TUNE ON gets the string, not ""
            self._note(f"TUNE {'ON' if on else 'OFF'}", source)

    def set_track(self, on: bool, source: str = "console") -> str | None:
        """Nova's TRACK ON/OFF; returns why TRACK ON was ignored, or None."""
        if on:
            snap = self.state.snapshot()
            missing = [what for what, bad in (("station", snap.observer is None),
                                              ("satellite", snap.satellite is None)) if bad]
            if missing:
                reason = f"TRACK ON ignored: no {' and no '.join(missing)} elements set"
                log.warning("%s (from %s)", reason, escape_for_log(source))
                self._note(reason, source, accepted=False)
                return reason
        if self.state.set_tracking(on):
            self._note(f"TRACK {'ON' if on else 'OFF'}", source)
        return None

    def set_doppler(self, on: bool, source: str = "console") -> None:
        """Doppler on or off: frequency updates to the radio (OrbitDRV's Enable/Disable Tuning; not Nova's TUNE,
        which is :meth:`set_feed`)."""
        if self.state.set_doppler(on):
            self._note(f"radio Doppler tuning {'on' if on else 'off'}", source)

    def select_satellite(self, catalog_number: int, source: str = "console") -> bool:
        """Make ``catalog_number`` the AutoTracking satellite; False (and no change) when unknown."""
        sat = self.state.catalog.get(catalog_number)
        if sat is None:
            return False
        if self.state.select(catalog_number, by=source):
            self.tracker.selection_changed()
            self._note(f"satellite {catalog_number} {sat.dde_name} selected", source)
        return True

    def choose_satellite(self, catalog_number: int, source: str) -> str | None:
        """A client's or the operator's accepted ``SAT=``: select ``catalog_number`` and switch autotrack off (the
        person or program that chose wins); returns the sentence saying so when autotrack was on, else None."""
        reason = f"SAT={catalog_number} from {escape_for_log(source, 60)} chose the satellite; AUTO ON resumes it"
        with self._choosing:
            switched = self.autotrack is not None and self.autotrack.on and self.autotrack.switch_off(reason)
            self.select_satellite(catalog_number, source)
        if not switched:
            return None
        self._note(f"autotrack off: {reason}", source)
        return f"autotrack switched off: {reason}"

    def select_scheduled(self, catalog_number: int) -> str | None:
        """Autotrack's selection of its schedule's satellite: None when selected, else why not (autotrack was
        switched off meanwhile -- a SAT= on its way wins --, or the satellite cannot be computed now)."""
        with self._choosing:
            if self.autotrack is None or not self.autotrack.on:
                return "autotrack is off"
            why = self.why_not_computable(catalog_number)
            if why is None and not self.select_satellite(catalog_number, source="autotrack"):
                why = "not in the catalog"
            if why is None:
                self.state.set_selected_by("autotrack")  # also when it was selected already (by the configuration)
        return why

    def set_autotrack(self, on: bool, source: str) -> None:
        """AUTO ON/OFF (the station checked that it has an autotrack)."""
        if self.autotrack is None:
            return
        with self._choosing:
            changed = self.autotrack.switch_on() if on else self.autotrack.switch_off(
                f"AUTO OFF from {escape_for_log(source, 60)}")
        if changed:
            self._note(f"AUTO {'ON' if on else 'OFF'}", source)

    @property
    def selected_by(self) -> str:
        """Who chose the selected satellite: "config", "saved-state", or the source of the command (read with
        the selection itself from :meth:`StationState.snapshot` where both are shown)."""
        return self.state.snapshot().selected_by

    @selected_by.setter
    def selected_by(self, source: str) -> None:
        self.state.set_selected_by(source)

    def clear_satellite(self) -> None:
        if self.state.select(None):
            self.tracker.selection_changed()

    def report_antenna_position(self, azimuth_deg: float | None, elevation_deg: float | None,
                                source: str = "rotor") -> None:
        """Record where the antennas point (sky degrees; a rotor read-back, or ANTAZ/ANTEL)."""
        self.state.report_antenna(azimuth_deg, elevation_deg, source, self.clock.now())

    def satellites(self, value: int | str) -> list[tuple[int, str]]:
        """Catalog number and DDE name of each satellite ``SAT=value`` names (a catalog number, or a name)."""
        found = [self.state.catalog.get(value)] if isinstance(value, int) else self.state.catalog.named(value)
        return [(sat.catalog_number, sat.dde_name) for sat in found if sat is not None]

    def why_not_computable(self, catalog_number: int) -> str | None:
        """Why the satellite ``catalog_number`` cannot be computed now (``SAT=``'s check), or None if it can."""
        sat = self.state.catalog.get(catalog_number)
        return "not in the catalog" if sat is None else self.tracker.why_not_computable(sat)

    def command(self, text: str, source: str = "console", conversation: int | None = None,
                face: Face = Face.DDE, rate_key: str | None = None, session: SessionPort | None = None,
                display: DisplayPort | None = None) -> CommandResult:
        """Parse ``text`` as ``face`` sends it, once, and run it (:meth:`execute`)."""
        return self.execute(parse_request(text, face), source, conversation=conversation, rate_key=rate_key,
                            session=session, display=display)

    def execute(self, request: Request, source: str = "console", conversation: int | None = None,
                rate_key: str | None = None, session: SessionPort | None = None,
                display: DisplayPort | None = None) -> CommandResult:
        """Run a parsed request from ``source`` through its entries' checks and actions (the command table's),
        and record it, whatever face it came from.

        All commands of a request are checked (their entries' check steps) before the first takes effect, so a
        refused poke changes nothing.  Each request is one event (``poke`` for the station's and the rotor's commands,
        ``request`` for a session's or the display's); a refused one is logged once a minute at most per
        ``rate_key`` (default: ``source``; a network face passes the peer's address, so reconnecting does not
        start the count afresh).  Nova's station commands also set the status word's bad function/subfunction
        bits (cleared by the next accepted one).  Rotor commands act on :attr:`rotor` (refused without one),
        session commands on the sender's ``session``, display commands on the console's ``display``."""
        self.before_command()
        targets = Targets(self, self.rotor, session, display)
        target = request.target
        reason = note = warning = None
        bits = 0
        error = request.error
        if error is not None:
            no_rotor = error.command is not None and error.command.target is Target.ROTOR and self.rotor is None
            reason = NO_ROTOR if no_rotor else str(error)
            bits = StatusBit.BAD_SUBFUNCTION if error.bad_argument else StatusBit.BAD_FUNCTION
        else:
            try:  # every entry's check step (SAT= by name: to a catalog number) before any action
                resolved = [Parsed(p.command, p.command.check(self, p.value)) for p in request.commands]
            except Refused as refusal:
                reason, resolved, bits = str(refusal), [], StatusBit.BAD_SUBFUNCTION
            for parsed in resolved:
                outcome = parsed.command.action(targets, parsed.value, source)
                reason = outcome.refused or reason
                note = outcome.note or note
                warning = outcome.warning or warning
        if target is Target.STATION:
            self.tracker.note_command(int(bits))
        accepted = reason is None
        kind = "poke" if target in (Target.STATION, Target.ROTOR) else "request"
        self.events.add(self.clock.now(), Direction.IN, kind, request.text, conversation=conversation, client=source,
                        accepted=accepted, detail=reason or note or warning or "")
        if not accepted:
            self._refusals.warning(f"refused:{rate_key or source}", "refused command %s from %s: %s",
                                   escape_for_log(request.text), escape_for_log(source), reason)
        if accepted and note is None and warning is not None:
            return CommandResult(True, warning, self.tracker.status_word(), warning=True)
        return CommandResult(accepted, reason or note, self.tracker.status_word())
