"""Nova's TCP command protocol, as text in and text out (no sockets: the server and tests use it).

Nova for Windows' TCP server (Setup/TCP) greets each client with ``Hello, this is Nova for
Windows.`` and answers ``SUMMARY`` with the same string its DDE item carries.  We keep that and add
a few commands; every reply line ends with CR LF (added by the server).

=================  ==========================================================================
line               reply
=================  ==========================================================================
``SUMMARY``        the current Nova string (:meth:`StationCore.current_text`); an empty line
                   before ``TUNE ON``, after ``TUNE OFF`` and while nothing can be computed
Nova's commands    ``TUNE ON|OFF``, ``TRACK ON|OFF``, ``SAT=n``, ``ANTAZ=deg``, ``ANTEL=deg``
                   through :meth:`StationCore.command`: ``OK`` when the command was accepted and
                   took effect, else ``ERROR <reason>``.  Decision: an accepted command that had
                   no effect (``TRACK ON`` without a station or satellite, which OrbitDRV ignores)
                   also answers ``ERROR <why it was ignored>``, because a script that asked for
                   tracking needs to know it is not happening.  DDE clients still get an
                   acknowledgement for it; only this protocol reports it.
``STATUS``         one line of ``key=value`` pairs separated by single blanks (values never
                   contain blanks): satellite, name, satellite_from (who chose it: config,
                   saved-state, or the client that sent SAT=), tune, track, radio_tuning, status (the
                   status word, hex), interface (version), az/el/rr/ah of the last tick when
                   there is a position, then the fields of the ``extra`` callable (rotor and
                   radio state, given by the station).
``WATCH``          ``OK``, then every string the station publishes, one per line, until the client
                   sends any line (an empty one too); a non-empty line is then handled as usual.
``QUIT``           ``OK``, then the server closes the connection.
``FLIP AUTO|ON|OFF`` FlipAnts' inverted tracking forced on (function 7F), off (7E) or chosen per
                   pass; ``ERROR`` when the station has no rotor.
``PARK``           ``TRACK OFF`` and the rotor to its park position; ``ERROR`` without a rotor.
=================  ==========================================================================

Keywords are accepted in any case with blanks around them.  A blank line outside ``WATCH`` (empty, or only
blanks, tabs, VT, FF or the 0x1C-0x1F separators) gets no reply.  Every command is recorded in the event
stream with the peer as ``client``.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from nfwserver.commands.help_text import help_lines
from nfwserver.commands.parsing import clean_command_text, parse_line
from nfwserver.commands.rotor_commands import RotorControl, run_rotor_command
from nfwserver.commands.table import CommandError, Face, Target
from nfwserver.core.events import Direction
from nfwserver.core.nova_protocol import format_azimuth, format_elevation, format_range_rate
from nfwserver.core.station_core import StationCore
from nfwserver.tcp.greeting import GREETING as GREETING  # the server sends it

StatusFields = Callable[[], Mapping[str, object]]


class Action(enum.Enum):
    REPLY = "reply"  #: send the lines, carry on
    WATCH = "watch"  #: send the lines, then stream published strings
    QUIT = "quit"  #: send the lines, then close


@dataclass(frozen=True)
class Reply:
    lines: tuple[str, ...]
    action: Action = Action.REPLY


def _value(value: object) -> str:
    """A STATUS value without blanks or control characters."""
    if isinstance(value, bool):
        return "on" if value else "off"
    if value is None:
        return "-"
    text = "".join(ch if ch.isprintable() and not ch.isspace() else "_" for ch in str(value))
    return text or "-"


def _one_line(text: str) -> str:
    """``text`` as one printable line (a reason may quote what the client sent)."""
    return " ".join("".join(ch if ch.isprintable() else " " for ch in text).split())


class NovaTcpProtocol:
    """Answers one line at a time for the station ``core``; ``extra`` adds STATUS fields."""

    def __init__(self, core: StationCore, extra: StatusFields | None = None,
                 rotor: RotorControl | None = None) -> None:
        self.core = core
        self.extra = extra
        self.rotor = rotor  #: the rotor's command port (None without a rotor)

    def _record(self, peer: str, text: str, detail: str = "") -> None:
        self.core.events.add(self.core.clock.now(), Direction.IN, "request", text, client=peer, accepted=True,
                             detail=detail)

    def handle(self, line: str, peer: str, rate_key: str | None = None) -> Reply | None:
        """The reply to ``line`` (without its terminator) from ``peer``; None for a blank line.

        ``rate_key`` groups the refusal log lines of one client across its connections (its address)."""
        if not line.strip():  # blank, including lines of only VT, FF or the 0x1C-0x1F separators
            return None
        try:
            parsed = parse_line(line, Face.TCP)
        except CommandError as exc:
            if exc.command is not None and exc.command.target is Target.ROTOR and self.rotor is None:
                self._record(peer, clean_command_text(line))
                return Reply(("ERROR no rotor is configured",))
            if exc.command is not None and exc.command.target is not Target.STATION:
                self._record(peer, clean_command_text(line), str(exc))
                return Reply((f"ERROR {_one_line(str(exc))}",))
            return self._station(line, peer, rate_key)  # the core records and rate-limits the refusal
        entry = parsed.command
        if entry.target is Target.STATION:
            return self._station(line, peer, rate_key)
        if entry.target is Target.ROTOR:
            self._record(peer, clean_command_text(line))
            why = run_rotor_command(parsed, self.rotor, self.core, peer)
            return Reply(("OK",) if why is None else (f"ERROR {why}",))
        return self._session(entry.word, peer)

    def _station(self, line: str, peer: str, rate_key: str | None) -> Reply:
        result = self.core.command(line, source=peer, face=Face.TCP, rate_key=rate_key)
        if result.ok:
            return Reply(("OK",))
        if result.accepted and result.warning:
            return Reply((f"OK warning: {_one_line(result.note or '')}",))
        return Reply((f"ERROR {_one_line(result.note or 'refused')}",))

    def _session(self, word: str, peer: str) -> Reply:
        if word == "SUMMARY":
            text = self.core.current_text()
            self._record(peer, "SUMMARY", text)
            return Reply((text,))
        self._record(peer, word)
        if word == "STATUS":
            return Reply((self.status_line(),))
        if word == "WATCH":
            return Reply(("OK",), Action.WATCH)
        if word == "QUIT":
            return Reply(("OK",), Action.QUIT)
        if word == "HELP":
            return Reply(help_lines(Face.TCP) + ("OK",))
        raise AssertionError(f"the TCP face has no handler for {word}")  # a table entry without one

    @staticmethod
    def too_long(limit: int) -> Reply:
        return Reply((f"ERROR line longer than {limit} bytes refused",))

    def status_line(self) -> str:
        snap = self.core.snapshot()
        state = snap.state
        fields: dict[str, object] = {
            "satellite": state.catalog_number, "name": snap.dde_name, "satellite_from": self.core.selected_by,
            "tune": state.dde_output,
            "track": state.tracking, "radio_tuning": state.radio_tuning, "status": f"0x{snap.status:04X}",
            "interface": snap.interface_version,
        }
        sample = snap.last_sample
        if sample is not None and sample.look_angles is not None and sample.catalog_number == state.catalog_number:
            la = sample.look_angles
            fields.update(az=format_azimuth(la.azimuth_deg), el=format_elevation(la.elevation_deg),
                          rr=format_range_rate(la.range_rate_km_s), ah="Y" if sample.above_horizon else "N")
        faults = self.core.health.faults()
        fields["faults"] = ",".join(faults) or "none"
        fields.update({f"{name}_fault": text for name, text in faults.items()})
        if self.extra is not None:
            try:
                fields.update(self.extra())
            except Exception as exc:  # a broken extra field must not cost the client its answer
                fields["extra_error"] = type(exc).__name__
        return " ".join(f"{_value(key)}={_value(value)}" for key, value in fields.items())
