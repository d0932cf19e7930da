"""What each command does: the action column of the command table (Hamlib's ``ACTION(...)`` in ``rotctl_parse.c``).

Every entry of :data:`nfwserver.commands.table.COMMANDS` names one of the actions below.  An action takes the
:class:`Targets` a command can act on (the station core, the rotor, the sender's session, the console's
display), the entry's checked argument and the sender, and returns an :class:`Outcome`.  The targets are
typed by what the actions call on them (protocols), so this package imports none of them.

An entry may also name a check step (Hamlib checks and converts an argument before its ``ACTION``): it
runs on the station before any command of a poke takes effect, turns the parsed argument into the one the
action takes (``SAT=`` by name into a catalog number) and raises :class:`Refused` when the station cannot do
it now.  The station core runs the checks and the actions and records every command
(:meth:`nfwserver.core.station_core.StationCore.execute`); a face only hands over the text it received
(or, for a key, the entry and its argument) and renders the outcome.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

__all__ = ["DONE", "DOPPLER_WITHOUT_RADIO", "NO_ROTOR", "TRACK_WITHOUT_ROTOR", "Action", "Check", "DisplayPort",
           "Outcome", "Refused", "RotorControl", "SessionPort", "StationPort", "Targets", "AutotrackSwitch"]

#: Why a rotor command is refused on a station with no rotor (every face says it in these words).
NO_ROTOR = "no rotor is configured"

#: The warning that comes with an accepted ``TRACK ON`` on a station that drives no rotor itself.
TRACK_WITHOUT_ROTOR = ("TRACK ON with no rotor configured: nothing turns here ([rotor] backend); "
                       "DDE clients that drive their own rotor still follow the feed")

#: The warning that comes with an accepted ``DOPPLER ON`` on a station that drives no radio.
DOPPLER_WITHOUT_RADIO = ("DOPPLER ON with no radio configured: nothing is tuned (set [radio] backend = \"rigctld\" "
                         "with the host and port of a running rigctld, and give the satellite a channel in "
                         "[satellites] channels)")


class Refused(Exception):
    """A check step's refusal: the command cannot be done now; the message says why in one sentence."""


@dataclass(frozen=True)
class Outcome:
    """What one command did."""

    refused: str | None = None  #: not done, and why (a rotor command with no rotor)
    note: str | None = None  #: done but without effect, and why (``TRACK ON`` with no satellite)
    warning: str | None = None  #: done, with something the sender should know


DONE = Outcome()


class AutotrackSwitch(Protocol):
    """The station's autotrack as the commands switch it (:class:`nfwserver.autotrack.AutotrackRuntime`)."""

    @property
    def on(self) -> bool: ...

    def switch_on(self) -> bool: ...

    def switch_off(self, reason: str) -> bool: ...

    def list_warning(self) -> str | None:
        """What ``AUTO ON`` says about the list of satellites (nothing to work, names left out), or None."""


class StationPort(Protocol):
    """What Nova's station commands need of the station core."""

    #: whether the station drives a rotor itself (None: not known, then no warning)
    rotor_configured: bool | None
    #: whether the station drives a radio itself (None: not known, then no warning)
    radio_configured: bool | None

    def satellites(self, value: int | str) -> list[tuple[int, str]]:
        """Catalog number and DDE name of each satellite ``value`` names (a catalog number, or a name)."""

    def why_not_computable(self, catalog_number: int) -> str | None: ...

    #: the station's autotrack (None: this station has none)
    autotrack: AutotrackSwitch | None

    def set_autotrack(self, on: bool, source: str) -> None: ...

    def choose_satellite(self, catalog_number: int, source: str) -> str | None:
        """``SAT=``: select it; a sentence when that switched autotrack off, else None."""

    def set_doppler(self, on: bool, source: str = ...) -> None: ...

    def set_feed(self, on: bool, source: str = ...) -> None: ...

    def set_track(self, on: bool, source: str = ...) -> str | None: ...

    def report_antenna_position(self, azimuth_deg: float | None, elevation_deg: float | None,
                                source: str = ...) -> None: ...


class RotorControl(Protocol):
    """What the rotor commands need of the rotor coupling (any thread may call these)."""

    def set_flip_mode(self, mode: str) -> None: ...

    def request_park(self) -> None: ...


class SessionPort(Protocol):
    """The connection that sent a session command (Nova's TCP face; the console answers ``help`` only)."""

    def summary(self) -> None: ...

    def status(self) -> None: ...

    def watch(self) -> None: ...

    def help(self) -> None: ...

    def quit(self) -> None: ...


class DisplayPort(Protocol):
    """The console's display."""

    def toggle_zone(self) -> None: ...


@dataclass(frozen=True)
class Targets:
    """What a command may act on; a face that has no session or display passes None for it."""

    station: StationPort
    rotor: RotorControl | None = None
    session: SessionPort | None = None
    display: DisplayPort | None = None

    def the_session(self) -> SessionPort:
        if self.session is None:  # the table's faces keep session commands to faces that have one
            raise AssertionError("a session command from a face without a session")
        return self.session

    def the_display(self) -> DisplayPort:
        if self.display is None:
            raise AssertionError("a display command from a face without a display")
        return self.display


#: An entry's action: (targets, checked argument, sender) -> outcome.
Action = Callable[[Targets, object, str], Outcome]
#: An entry's check step: (station, parsed argument) -> the argument its action takes; raises :class:`Refused`.
Check = Callable[[StationPort, object], object]


def _degrees(value: object) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise AssertionError(f"a number of degrees was expected, got {value!r}")
    return float(value)


def feed(targets: Targets, value: object, source: str) -> Outcome:
    """TUNE ON/OFF: the feed (the published Nova string), not the radio's Doppler tuning."""
    targets.station.set_feed(value is True, source)
    return DONE


def track(targets: Targets, value: object, source: str) -> Outcome:
    on = value is True
    ignored = targets.station.set_track(on, source)
    if ignored is not None:
        return Outcome(note=ignored)
    if on and targets.station.rotor_configured is False:
        return Outcome(warning=TRACK_WITHOUT_ROTOR)
    return DONE


def satellite(targets: Targets, value: object, source: str) -> Outcome:
    """``SAT=``: ``value`` is the catalog number its check resolved (names are resolved there)."""
    if not isinstance(value, int) or isinstance(value, bool):
        raise AssertionError(f"SAT= reached its action unresolved: {value!r}")
    switched_off = targets.station.choose_satellite(value, source)
    return Outcome(warning=switched_off) if switched_off else DONE


def autotrack(targets: Targets, value: object, source: str) -> Outcome:
    """AUTO ON/OFF: the station selects the satellite of its schedule by itself, or leaves the choice to people."""
    targets.station.set_autotrack(value is True, source)
    switch = targets.station.autotrack
    warning = switch.list_warning() if value is True and switch is not None else None
    return Outcome(warning=warning) if warning else DONE


def doppler(targets: Targets, value: object, source: str) -> Outcome:
    """DOPPLER ON/OFF: frequency updates to the radio (OrbitDRV's Enable/Disable Tuning; not Nova's TUNE)."""
    on = value is True
    targets.station.set_doppler(on, source)
    if on and targets.station.radio_configured is False:
        return Outcome(warning=DOPPLER_WITHOUT_RADIO)
    return DONE


def antenna_azimuth(targets: Targets, value: object, source: str) -> Outcome:
    targets.station.report_antenna_position(_degrees(value), None, source)
    return DONE


def antenna_elevation(targets: Targets, value: object, source: str) -> Outcome:
    targets.station.report_antenna_position(None, _degrees(value), source)
    return DONE


def flip(targets: Targets, value: object, source: str) -> Outcome:
    if targets.rotor is None:
        return Outcome(refused=NO_ROTOR)
    targets.rotor.set_flip_mode(str(value))
    return DONE


def park(targets: Targets, value: object, source: str) -> Outcome:
    if targets.rotor is None:
        return Outcome(refused=NO_ROTOR)
    targets.station.set_track(False, source)
    targets.rotor.request_park()
    return DONE


def summary(targets: Targets, value: object, source: str) -> Outcome:
    targets.the_session().summary()
    return DONE


def status(targets: Targets, value: object, source: str) -> Outcome:
    targets.the_session().status()
    return DONE


def watch(targets: Targets, value: object, source: str) -> Outcome:
    targets.the_session().watch()
    return DONE


def show_help(targets: Targets, value: object, source: str) -> Outcome:
    targets.the_session().help()
    return DONE


def quit_session(targets: Targets, value: object, source: str) -> Outcome:
    targets.the_session().quit()
    return DONE


def toggle_zone(targets: Targets, value: object, source: str) -> Outcome:
    targets.the_display().toggle_zone()
    return DONE
