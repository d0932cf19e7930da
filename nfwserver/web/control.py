"""Commands from the page: who may send one, and sending it through the station core's command entry.

A control request is a JSON object ``{"command": "TRACK ON", "token": "..."}`` posted to
``/api/command``.  It is refused (HTTP 403, one log line per address a minute, and an event in the
station's stream) when ``[web] control`` is off or its token is weak (checked before the body is read),
when the token is missing or wrong (:func:`~nfwserver.config.tokens.token_matches`, constant time), or
when the line is not one of the commands the table lets the web face send (:attr:`Face.WEB`: ``TUNE``,
``TRACK``, ``SAT``, ``ANTAZ``/``ANTEL``, ``DOPPLER``, ``AUTO``, ``FLIP``, ``PARK``).  The line is parsed by the
command table (:func:`~nfwserver.commands.parsing.parse_request`, once, which also bounds its length) and run through
the table's actions by :meth:`~nfwserver.core.station_core.StationCore.execute`, as every face's commands
are, with the browser's address as the source; the reply is the station's answer (a rotor command acts on
the station's rotor, or is refused without one).  The control switch and the token are read
from :attr:`Control.config` at every request, so a changed ``[web]`` section applies at once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from nfwserver.commands.parsing import parse_request
from nfwserver.commands.table import Face, commands_for, escape_for_log
from nfwserver.config.schema import WebConfig
from nfwserver.config.tokens import token_matches, weak_token_reason
from nfwserver.core.events import Direction
from nfwserver.core.station_core import StationCore


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
    return [{"usage": c.usage, "summary": c.summary} for c in commands_for(Face.WEB)]


def _open(config: WebConfig) -> bool:
    """Whether ``config`` lets the page send commands: control on, with a token that is not weak."""
    return _closed_reason(config) is None


def _closed_reason(config: WebConfig) -> str | None:
    """Why ``config`` lets the page send no command, or None.  A weak token in the file turns control off
    as it is loaded (:mod:`nfwserver.config.loader`): the refusal names the token, not the switch."""
    weak = weak_token_reason(config.token) if config.token else None
    if weak is not None:
        return f"control is off: [web] token {weak}"
    if not config.control or not config.token:
        return "control is off ([web] control)"
    return None


class Control:
    """Checks and runs control requests; called on the HTTP connection threads."""

    def __init__(self, core: StationCore, config: WebConfig, note: Callable[[str, str], bool]) -> None:
        self.core = core  #: runs every command; FLIP and PARK act on its rotor (:attr:`StationCore.rotor`)
        self.config = config  #: replaced whole when the configuration changes (read once per request)
        #: ``note(address, line)`` logs a refusal unless that address had one logged in the last minute
        #: (:meth:`WebServer._note_refusal`); True when it wrote the line
        self._note = note

    @property
    def enabled(self) -> bool:
        return _open(self.config)

    def refuse(self, peer: str, status: int, reason: str, text: str = "") -> ControlReply:
        """Refuse a request from ``peer``: one log line and one event per burst of refusals from its address,
        whatever the reason."""
        host = peer.removeprefix("web ")
        if self._note(host, f"web control from {host} refused: {reason}"):
            self.core.events.add(self.core.clock.now(), Direction.IN, "poke", escape_for_log(text), client=peer,
                                 accepted=False, detail=f"web control refused: {reason}")
        return ControlReply(status, False, reason)

    def closed(self, peer: str) -> ControlReply | None:
        """The refusal when control is off (checked before a request's body is read), else None."""
        why = _closed_reason(self.config)
        return None if why is None else self.refuse(peer, 403, why)

    def run(self, request: object, peer: str) -> ControlReply:
        """Check and run one decoded JSON request from ``peer`` (``"web 192.0.2.1"``)."""
        config = self.config  # one reading for the whole request
        why = _closed_reason(config)
        if why is not None or config.token is None:
            return self.refuse(peer, 403, why or "control is off ([web] control)")
        if not isinstance(request, dict):
            return self.refuse(peer, 400, "the request must be a JSON object with command and token")
        token, text = request.get("token"), request.get("command")
        shown = text if isinstance(text, str) else ""
        if not isinstance(token, str) or not token_matches(token, config.token):
            return self.refuse(peer, 403, "missing or wrong token", shown)
        if not isinstance(text, str) or "\n" in text or "\r" in text:
            return self.refuse(peer, 400, "command must be one line", shown)
        parsed = parse_request(text, Face.WEB)
        error = parsed.error
        if error is not None and error.command is None and not error.bad_argument:
            usages = ", ".join(c.short for c in commands_for(Face.WEB))
            return self.refuse(peer, 400, f"not a station command ({usages}): {error}", text)
        result = self.core.execute(parsed, source=peer)  # run and recorded there, as every face's commands are
        return ControlReply(200 if result.accepted else 409, result.accepted, result.note or "OK")
