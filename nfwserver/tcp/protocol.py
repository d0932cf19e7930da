"""Nova's TCP command protocol, as text in and text out (no sockets: the server and tests use it).

Nova for Windows' TCP server (Setup/TCP) greets each client with ``Hello, this is Nova for
Windows.`` and answers ``SUMMARY`` with the same string its DDE item carries.  We keep that and add
a few commands; every reply line ends with CR LF (added by the server).

The commands and their replies are the command table's (docs/COMMANDS.md, generated from it).  Replies:
``OK`` when a command was accepted and took effect, ``OK warning: ...`` when it took effect with a warning,
else ``ERROR <reason>`` -- also for an accepted command that had no effect (``TRACK ON`` without a station or
satellite, which OrbitDRV ignores: a script that asked for tracking needs to know it is not happening; DDE
clients still get an acknowledgement).  ``STATUS`` is one line of ``key=value`` pairs
(:mod:`nfwserver.tcp.status_line`), with the fields of the ``extra`` callable (rotor and radio) at the end.

Keywords are accepted in any case with blanks around them.  A blank line outside ``WATCH`` (empty, or only
blanks, tabs, VT, FF or the 0x1C-0x1F separators) gets no reply.  Every line is handed to the station core
(:meth:`StationCore.command`), which parses it through the command table, runs it and records it in the
event stream with the peer as ``client``; this module only turns the outcome into reply lines.
"""

from __future__ import annotations

import enum
import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from nfwserver.commands.help_text import help_lines
from nfwserver.commands.table import Face
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
    """The session commands' target for one line: each action leaves its reply here (the core records them)."""

    def __init__(self, protocol: NovaTcpProtocol) -> None:
        self.protocol = protocol
        self.reply: Reply | None = None

    def summary(self) -> None:
        self.reply = Reply((self.protocol.core.current_text(),))

    def status(self) -> None:
        self.reply = Reply((self.protocol.status_line(),))

    def watch(self) -> None:
        self.reply = Reply(("OK",), Action.WATCH)

    def help(self) -> None:
        self.reply = Reply(help_lines(Face.TCP) + ("OK",))

    def quit(self) -> None:
        self.reply = Reply(("OK",), Action.QUIT)


class NovaTcpProtocol:
    """Answers one line at a time for the station ``core``; ``extra`` adds STATUS fields."""

    def __init__(self, core: StationCore, extra: StatusFields | None = None) -> None:
        self.core = core
        self.extra = extra
        self._extra_failures = RateLimitedLog(log, core.clock, 60.0)  #: a broken STATUS field: logged whole

    def handle(self, line: str, peer: str, rate_key: str | None = None) -> Reply | None:
        """The reply to ``line`` (without its terminator) from ``peer``; None for a blank line.

        The core parses the line once, runs it through the command table and records it; ``rate_key`` groups
        the refusal log lines of one client across its connections (its address)."""
        if not line.strip():  # blank, including lines of only VT, FF or the 0x1C-0x1F separators
            return None
        session = _Session(self)
        result = self.core.command(line, source=peer, face=Face.TCP, rate_key=rate_key, session=session)
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
