"""Commands from the page: who may send one, and sending it through the station core's command entry.

A control request is a JSON object ``{"command": "TRACK ON", "token": "..."}`` posted to
``/api/command``.  It is refused (HTTP 403, one log line per address a minute, and an event in the
station's stream) when ``[web] control`` is off, when the token is missing or wrong (compared in
constant time), or when it is not one of the station's or the rotor's commands (``TUNE``, ``TRACK``,
``SAT``, ``ANTAZ``/``ANTEL``, ``FLIP``, ``PARK``: the entries of :data:`nfwserver.commands.table.COMMANDS`
that act on the station or the rotor).  An accepted station command goes to
:meth:`~nfwserver.core.station_core.StationCore.command` as a TCP line would, a rotor command to
:func:`~nfwserver.commands.rotor_commands.run_rotor_command` as TCP and the console run it, with the
browser's address as the source; the reply is their answer.
"""

from __future__ import annotations

import hmac
import logging
import re
from dataclasses import dataclass

from nfwserver.commands.parsing import parse_line
from nfwserver.commands.rotor_commands import RotorControl, run_rotor_command
from nfwserver.commands.table import Command, CommandError, Face, Target, commands_for, escape_for_log
from nfwserver.config.schema import WebConfig
from nfwserver.core.events import Direction
from nfwserver.core.station_core import StationCore
from nfwserver.ratelimited_log import RateLimitedLog

log = logging.getLogger(__name__)

#: Longest command text taken from the page (the table refuses longer ones anyway).
MAX_COMMAND_CHARS = 256


@dataclass(frozen=True)
class ControlReply:
    """What ``/api/command`` answers: HTTP status, accepted, and the core's note or the refusal."""

    status: int
    ok: bool
    message: str

    def as_json(self) -> dict[str, object]:
        return {"ok": self.ok, "message": self.message}


def help_entries() -> list[dict[str, str]]:
    """The commands the page may send, from the command table (usage and summary)."""
    return [{"usage": c.usage, "summary": c.summary} for c in _page_commands()]


def _page_commands() -> list[Command]:
    """The commands the page may send: the station's and the rotor's (not the TCP session's)."""
    return [c for c in commands_for(Face.TCP) if c.target in (Target.STATION, Target.ROTOR)]


def _entry(text: str) -> Command | None:
    """The table entry ``text``'s keyword names, if any."""
    match = re.match(r"\s*([A-Za-z]+)", text)
    word = match.group(1).upper() if match else ""
    return next((c for c in commands_for(Face.TCP) if c.word == word), None)


class Control:
    """Checks and runs control requests; called on the HTTP connection threads."""

    def __init__(self, core: StationCore, config: WebConfig, rotor: RotorControl | None = None) -> None:
        self.core = core
        self.config = config
        self.rotor = rotor  #: the rotor's command port (FLIP, PARK); None without a rotor
        self._refusals = RateLimitedLog(log, core.clock, 60.0)

    @property
    def enabled(self) -> bool:
        return bool(self.config.control and self.config.token)

    def _refuse(self, peer: str, status: int, reason: str, text: str = "") -> ControlReply:
        self._refusals.warning(f"{peer}:{reason}", "web control from %s refused: %s", peer, reason)
        self.core.events.add(self.core.clock.now(), Direction.IN, "poke", escape_for_log(text), client=peer,
                             accepted=False, detail=f"web control refused: {reason}")
        return ControlReply(status, False, reason)

    def run(self, request: object, peer: str) -> ControlReply:
        """Check and run one decoded JSON request from ``peer`` (``"web 192.0.2.1"``)."""
        if not self.enabled:
            return self._refuse(peer, 403, "control is off ([web] control)")
        if not isinstance(request, dict):
            return self._refuse(peer, 400, "the request must be a JSON object with command and token")
        token, text = request.get("token"), request.get("command")
        if not isinstance(token, str) or not hmac.compare_digest(token.encode("utf-8", "replace"),
                                                                 str(self.config.token).encode("utf-8")):
            return self._refuse(peer, 403, "missing or wrong token", text if isinstance(text, str) else "")
        if not isinstance(text, str) or not text.strip() or len(text) > MAX_COMMAND_CHARS \
                or "\n" in text or "\r" in text:
            return self._refuse(peer, 400, "command must be one line of at most 256 characters",
                                text if isinstance(text, str) else "")
        entry = _entry(text)
        if entry is None or entry.target not in (Target.STATION, Target.ROTOR):
            usages = ", ".join(c.short for c in _page_commands())
            return self._refuse(peer, 400, f"not a station command ({usages})", text)
        if entry.target is Target.ROTOR:
            return self._rotor(text, peer)
        result = self.core.command(text, source=peer, face=Face.TCP)
        return ControlReply(200 if result.accepted else 409, result.accepted, result.note or "OK")

    def _rotor(self, text: str, peer: str) -> ControlReply:
        """``FLIP``/``PARK``: parsed by the table and run as every face runs them."""
        try:
            parsed = parse_line(text, Face.TCP)
        except CommandError as exc:
            return self._refuse(peer, 409, str(exc), text)
        why = run_rotor_command(parsed, self.rotor, self.core, peer)
        self.core.events.add(self.core.clock.now(), Direction.IN, "poke", escape_for_log(text), client=peer,
                             accepted=why is None, detail=why or "")
        return ControlReply(200, True, "OK") if why is None else ControlReply(409, False, why)
