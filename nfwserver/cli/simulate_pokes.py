"""``nfwserver simulate --poke``: a scheduled poke, sent as given, and what the server did with it.

A ``--poke [SECONDS:]TEXT`` stands for a poke the simulated DDE client sends: any text, sent as it is, so a
bad command, a poke of several lines or one with non-ASCII digits shows how the server answers it.  When
the poke is sent, the station core's answer (accepted, refused and why, accepted with a note or a warning)
and the change it made to the live state are reported as one line, e.g.
``t+60 s  poke 'TUNE OFF': accepted; feed off``; offsets are virtual seconds from ``--start``.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass

from nfwserver.commands.parsing import Parsed, parse_request
from nfwserver.commands.table import Face
from nfwserver.core.events import Direction, Event
from nfwserver.core.state import StateSnapshot
from nfwserver.core.station_core import StationCore

#: Longest simulated duration, in seconds (30 days); a poke's offset is at most this.
MAX_DURATION_S = 30 * 86400.0


def poke_value(text: str) -> tuple[float, str]:
    """``type=`` for ``--poke``: ``[SECONDS:]TEXT``.  Whatever follows the offset is sent as it is (a command
    the server refuses too, or several lines); only the offset is checked here.  Without a ':' the whole text
    is the poke, sent at 0 s."""
    offset, sep, command = text.partition(":")
    if not sep:
        return 0.0, text
    try:
        seconds = float(offset)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: the offset before ':' must be seconds, e.g. 120:SAT=25544 "
                                         "(0:TEXT sends a TEXT holding ':' at the start)") from None
    if not 0 <= seconds <= MAX_DURATION_S:
        raise argparse.ArgumentTypeError(f"{text!r}: the offset must be 0 to {MAX_DURATION_S:.0f} s")
    return seconds, command


def commands_of(command: str) -> tuple[Parsed, ...]:
    """The station commands a poke of ``command`` holds, as the DDE face parses it (none when it refuses it)."""
    return parse_request(command, Face.DDE).commands


@dataclass(frozen=True)
class PokeOutcome:
    """What one poke did: the core's answer and the change in the live state."""

    offset_s: float  #: virtual seconds since the start
    command: str
    accepted: bool | None  #: None when the core recorded no answer (the poke did not reach it)
    note: str  #: the refusal reason, why it had no effect, or the warning ("" when none)
    changes: tuple[str, ...]  #: what changed, e.g. ("feed off",)

    def line(self) -> str:
        """``t+60 s  poke 'TUNE OFF': accepted; feed off``."""
        if self.accepted is None:
            verdict = "no answer from the station"
        elif self.accepted:
            verdict = "accepted" + (f" ({self.note})" if self.note else "")
        else:
            verdict = f"refused: {self.note or 'no reason given'}"
        what = "; ".join(self.changes) if self.changes else ("no change" if self.accepted else "nothing changed")
        return f"t+{self.offset_s:g} s  poke {self.command!r}: {verdict}; {what}"


def _satellite(snap: StateSnapshot) -> str:
    if snap.catalog_number is None:
        return "none"
    name = snap.satellite.dde_name if snap.satellite is not None else "?"
    return f"{snap.catalog_number} {name}"


def state_changes(before: StateSnapshot, after: StateSnapshot) -> tuple[str, ...]:
    """The differences a command can make, in words (feed, tracking, satellite, antenna degrees)."""
    out: list[str] = []
    if before.feed_on != after.feed_on:
        out.append(f"feed {'on' if after.feed_on else 'off'}")
    if before.tracking != after.tracking:
        out.append(f"tracking {'on' if after.tracking else 'off'}")
    if before.catalog_number != after.catalog_number:
        out.append(f"satellite {_satellite(before)} -> {_satellite(after)}")
    if before.antenna.azimuth_deg != after.antenna.azimuth_deg and after.antenna.azimuth_deg is not None:
        out.append(f"antenna azimuth {after.antenna.azimuth_deg:g} deg")
    if before.antenna.elevation_deg != after.antenna.elevation_deg and after.antenna.elevation_deg is not None:
        out.append(f"antenna elevation {after.antenna.elevation_deg:g} deg")
    return tuple(out)


def observe_poke(core: StationCore, offset_s: float, command: str, send: Callable[[str], object]) -> PokeOutcome:
    """Call ``send(command)`` (which hands it to the core, through DDE or directly) and report what it did,
    from the core's own record of the poke (the event stream) and the state before and after."""
    seen: list[Event] = []

    def record(event: Event) -> None:
        if event.direction is Direction.IN and event.kind == "poke":
            seen.append(event)

    before = core.state.snapshot()
    unsubscribe = core.events.subscribe(record)
    try:
        send(command)
    finally:
        unsubscribe()
    after = core.state.snapshot()
    event = seen[-1] if seen else None
    return PokeOutcome(offset_s, command, event.accepted if event is not None else None,
                       event.detail if event is not None else "", state_changes(before, after))
