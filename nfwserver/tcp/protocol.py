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
                   contain blanks; :mod:`nfwserver.tcp.status_line` writes and reads it):
                   satellite, name, satellite_from (who chose it: config,
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
import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from nfwserver.commands.help_text import help_lines
from nfwserver.commands.parsing import clean_command_text, parse_request
from nfwserver.commands.table import Face, Target
from nfwserver.core.events import Direction
from nfwserver.core.nova_protocol import format_azimuth, format_elevation, format_range_rate
from nfwserver.core.station_core import StationCore
from nfwserver.ratelimited_log import RateLimitedLog
from nfwserver.tcp.greeting import GREETING as GREETING  # the server sends it
from nfwserver.tcp.status_line import format_status

log = logging.getLogger(__name__)

StatusFields = Callable[[], Mapping[str, object]]


class Action(enum.Enum):
    REPLY = "reply"  #: send the lines, carry on
    WATCH = "watch"  #: send the lines, then stream published strings
    QUIT = "quit"  #: send the lines, then close


@dataclass(frozen=True)
class Reply:
    lines: tuple[str, ...]
    action: Action = Action.REPLY


def _one_line(text: str) -> str:
    """``text`` as one printable line (a reason may quote what the client sent)."""
    return " ".join("".join(ch if ch.isprintable() else " " for ch in text).split())


class _Session:
    """The session commands' target for one line from ``peer``: each action leaves its reply here."""

    def __init__(self, protocol: NovaTcpProtocol, peer: str) -> None:
        self.protocol = protocol
        self.peer = peer
        self.reply: Reply | None = None

    def summary(self) -> None:
        text = self.protocol.core.current_text()
        self.protocol.record(self.peer, "SUMMARY", text)
        self.reply = Reply((text,))

    def status(self) -> None:
        self.protocol.record(self.peer, "STATUS")
        self.reply = Reply((self.protocol.status_line(),))

    def watch(self) -> None:
        self.protocol.record(self.peer, "WATCH")
        self.reply = Reply(("OK",), Action.WATCH)

    def help(self) -> None:
        self.protocol.record(self.peer, "HELP")
        self.reply = Reply(help_lines(Face.TCP) + ("OK",))

    def quit(self) -> None:
        self.protocol.record(self.peer, "QUIT")
        self.reply = Reply(("OK",), Action.QUIT)


class NovaTcpProtocol:
    """Answers one line at a time for the station ``core``; ``extra`` adds STATUS fields."""

    def __init__(self, core: StationCore, extra: StatusFields | None = None) -> None:
        self.core = core
        self.extra = extra
        self._extra_failures = RateLimitedLog(log, core.clock, 60.0)  #: a broken STATUS field: logged whole

    def record(self, peer: str, text: str, detail: str = "") -> None:
        """An event for a line that is not a station command (the core records those)."""
        self.core.events.add(self.core.clock.now(), Direction.IN, "request", text, client=peer, accepted=True,
                             detail=detail)

    def handle(self, line: str, peer: str, rate_key: str | None = None) -> Reply | None:
        """The reply to ``line`` (without its terminator) from ``peer``; None for a blank line.

        The line is parsed once and run by the core through the command table; ``rate_key`` groups the
        refusal log lines of one client across its connections (its address)."""
        if not line.strip():  # blank, including lines of only VT, FF or the 0x1C-0x1F separators
            return None
        request = parse_request(line, Face.TCP)
        target = request.target
        if target is Target.ROTOR or (target is Target.SESSION and request.error is not None):
            no_rotor = target is Target.ROTOR and self.core.rotor is None
            detail = str(request.error) if request.error is not None and not no_rotor else ""
            self.record(peer, clean_command_text(line), detail)  # the session's actions record their own
        session = _Session(self, peer)
        result = self.core.execute(request, source=peer, rate_key=rate_key, session=session)
        if session.reply is not None:
            return session.reply
        if result.ok:
            return Reply(("OK",))
        if result.accepted and result.warning:
            return Reply((f"OK warning: {_one_line(result.note or '')}",))
        return Reply((f"ERROR {_one_line(result.note or 'refused')}",))

    @staticmethod
    def too_long(limit: int) -> Reply:
        return Reply((f"ERROR line longer than {limit} bytes refused",))

    def status_line(self) -> str:
        snap = self.core.snapshot()
        state = snap.state
        fields: dict[str, object] = {
            "satellite": state.catalog_number, "name": snap.dde_name, "satellite_from": state.selected_by,
            "tune": state.feed_on,
            "track": state.tracking, "radio_tuning": state.doppler_on, "status": f"0x{snap.status:04X}",
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
                self._extra_failures.log(logging.ERROR, "extra", "STATUS fields of the devices failed",
                                         exc_info=True)
        return format_status(fields)
