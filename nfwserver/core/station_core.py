"""The station core: the live state, the tracker, the event stream and the command port, together.

:class:`StationCore` is what every output adapter is given.  Adapters read the state
(:attr:`StationCore.state`), subscribe to ticks (:meth:`StationCore.subscribe`) and talk back
through narrow ports: :meth:`execute` (every command, as a face parsed it:
:func:`nfwserver.commands.parsing.parse_request`; :meth:`command` parses text for a caller that has
only text), :meth:`select_satellite`, :meth:`report_antenna_position`, :meth:`set_doppler`.  No
adapter keeps its own copy of the station.

Every command is run through its entry's action in the command table (:mod:`nfwserver.commands`):
Nova's ``TUNE ON|OFF`` (the DDE output), ``TRACK ON|OFF`` (autotracking), ``SAT=<catalog number>``,
``ANTAZ=<deg>``, ``ANTEL=<deg>`` on the station; ``FLIP``/``PARK`` on the rotor; the TCP session's and
the console's own commands on the session or display the face passes.
``TRACK ON`` is an OrbitDRV enable call: "ignored if the station or satellite parameters have not
been set".  It is then acknowledged (a client without error handling must not die on it) but does
nothing, and the reason is logged, recorded in the event stream and returned in
:attr:`CommandResult.note`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from datetime import datetime

from nfwserver.channels.channel import Channel
from nfwserver.clock import Clock
from nfwserver.commands.actions import NO_ROTOR, DisplayPort, RotorControl, SessionPort, Targets
from nfwserver.commands.parsing import Parsed, Request, parse_request
from nfwserver.commands.table import Face, Target, escape_for_log
from nfwserver.core.events import Direction, EventLog
from nfwserver.core.sample import TickSample
from nfwserver.core.state import DEFAULT_RATE_HZ, StateSnapshot, StationState
from nfwserver.core.status import INTERFACE_VERSION, StatusBit
from nfwserver.core.tracker import TickListener, Tracker
from nfwserver.health.board import HealthBoard
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.tracking.catalog import Catalog, Satellite
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
        #: the rotor's command port for FLIP and PARK (set by the station; None: no rotor)
        self.rotor: RotorControl | None = None
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

    def _satellite_for(self, value: int | str) -> tuple[Satellite | None, str | None]:
        """The satellite ``SAT=value`` names (a catalog number, or a name matching one satellite only),
        or None and why not."""
        catalog = self.state.catalog
        if isinstance(value, int):
            sat = catalog.get(value)
            return (sat, None) if sat is not None else (None, f"satellite {value} is not in the catalog")
        found = catalog.named(value)
        if len(found) == 1:
            return found[0], None
        shown = escape_for_log(value, 40)
        if not found:
            return None, f"no satellite is named '{shown}'"
        numbers = ", ".join(str(s.catalog_number) for s in found[:5]) + (", ..." if len(found) > 5 else "")
        return None, f"{len(found)} satellites are named '{shown}' ({numbers}); use the catalog number"

    def check(self, commands: Iterable[Parsed]) -> tuple[list[Parsed], str | None]:
        """Validate station commands as a whole before any takes effect: each ``SAT=`` resolved to a catalog
        number of a satellite that can be computed now; returns the resolved commands, or the refusal reason."""
        resolved = []
        for parsed in commands:
            if parsed.command.word == "SAT":
                value = parsed.value
                sat, why = self._satellite_for(value if isinstance(value, (int, str)) else str(value))
                if sat is None:
                    return [], f"{why}; keeping the current one"
                problem = self.tracker.why_not_computable(sat)
                if problem is not None:
                    return [], (f"satellite {sat.catalog_number} {sat.dde_name} cannot be computed now ({problem}); "
                                "keeping the current one")
                parsed = Parsed(parsed.command, sat.catalog_number)
            resolved.append(parsed)
        return resolved, None

    def command(self, text: str, source: str = "console", conversation: int | None = None,
                face: Face = Face.DDE, rate_key: str | None = None) -> CommandResult:
        """Parse ``text`` as ``face`` sends it and run it (:meth:`execute`): for a caller that holds only text."""
        return self.execute(parse_request(text, face), source, conversation=conversation, rate_key=rate_key)

    def execute(self, request: Request, source: str = "console", conversation: int | None = None,
                rate_key: str | None = None, session: SessionPort | None = None,
                display: DisplayPort | None = None) -> CommandResult:
        """Run a parsed request from ``source`` through its entries' actions (the command table's).

        Station commands are atomic: all are checked (:meth:`check`) before the first takes effect, so a
        refused poke changes nothing; each is an event, sets the bad function/subfunction bits when refused,
        and a refusal is logged once a minute at most per ``rate_key`` (default: ``source``; a network face
        passes the peer's address, so reconnecting does not start the count afresh).  The other commands act
        on the rotor (:attr:`rotor`), the sender's ``session`` or the console's ``display``; their face
        records them."""
        targets = Targets(self, self.rotor, session, display)
        if request.target is not Target.STATION:
            return self._run_other(request, targets, source)
        reason = note = warning = None
        bits = 0
        if request.error is not None:
            reason = str(request.error)
            bits = StatusBit.BAD_SUBFUNCTION if request.error.bad_argument else StatusBit.BAD_FUNCTION
        else:
            resolved, reason = self.check(request.commands)
            if reason is not None:
                bits = StatusBit.BAD_SUBFUNCTION
            for parsed in resolved:
                outcome = parsed.command.action(targets, parsed.value, source)
                note = outcome.note or note
                warning = outcome.warning or warning
        self.tracker.note_command(int(bits))
        accepted = reason is None
        text = request.text
        self.events.add(self.clock.now(), Direction.IN, "poke", text, conversation=conversation, client=source,
                        accepted=accepted, detail=reason or note or warning or "")
        if not accepted:
            self._refusals.warning(f"refused:{rate_key or source}", "refused command %s from %s: %s",
                                   escape_for_log(text), escape_for_log(source), reason)
        if accepted and note is None and warning is not None:
            return CommandResult(True, warning, self.tracker.status_word(), warning=True)
        return CommandResult(accepted, reason or note, self.tracker.status_word())

    def _run_other(self, request: Request, targets: Targets, source: str) -> CommandResult:
        """A rotor, session or display command: refused without a rotor for a rotor command, or with the
        parser's reason; else its action's outcome."""
        error = request.error
        if error is not None:
            no_rotor = error.command is not None and error.command.target is Target.ROTOR and self.rotor is None
            return CommandResult(False, NO_ROTOR if no_rotor else str(error), self.tracker.status_word())
        parsed = request.commands[0]
        outcome = parsed.command.action(targets, parsed.value, source)
        if outcome.refused is not None:
            return CommandResult(False, outcome.refused, self.tracker.status_word())
        return CommandResult(True, outcome.note or outcome.warning, self.tracker.status_word(),
                             warning=outcome.note is None and outcome.warning is not None)
