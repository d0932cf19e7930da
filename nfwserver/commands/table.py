"""The one table of the station's commands: every face parses, dispatches and documents through it.

In the spirit of Hamlib's ``rotctl_parse.c``: each :class:`Command` is one entry holding its grammar
(a whole-line regular expression, keywords in any case, blanks allowed around ``=``), the faces that
may send it (:class:`Face`), what it acts on (:class:`Target`: the station core, the TCP session, the
rotor, the console's display), how its argument is checked and converted, its reply, and its action
(:mod:`nfwserver.commands.actions`, run by the station core whichever face sent the command).  The
parser (:mod:`nfwserver.commands.parsing`), ``HELP`` on TCP, the console's help line,
``nfwserver poke --help`` and ``docs/COMMANDS.md`` (:mod:`nfwserver.commands.help_text`) all read
this table; a new command is one entry here plus its action.

Numbers are ASCII digits only (``SAT=²`` is refused, never half-read).
"""

from __future__ import annotations

import enum
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field

from nfwserver.commands import actions
from nfwserver.commands.actions import Action

__all__ = ["COMMANDS", "Command", "CommandError", "Face", "Poke", "PokeKind", "Target", "escape_for_log"]

#: Longest command text looked at; longer input is refused without being parsed.
MAX_COMMAND_LENGTH = 256


class Face(enum.Flag):
    """Where a command comes from."""

    DDE = enum.auto()  #: a poke or execute on Nova's DDE topic (several commands, one per line)
    TCP = enum.auto()  #: a line on Nova's TCP port (``nfwserver poke`` sends one)
    CONSOLE = enum.auto()  #: the console's input line
    WEB = enum.auto()  #: a command posted by the web dashboard (``POST /api/command``)
    ALL = DDE | TCP | CONSOLE | WEB


class Target(enum.Enum):
    """What a command acts on."""

    STATION = "station"  #: the station core (Nova's commands): validated whole, then applied in order
    SESSION = "session"  #: the TCP connection that sent it
    ROTOR = "rotor"  #: the rotor coupling
    DISPLAY = "display"  #: the console's display


class PokeKind(enum.Enum):
    """Nova's station commands."""

    TUNE = "TUNE"
    TRACK = "TRACK"
    SAT = "SAT"
    ANTAZ = "ANTAZ"
    ANTEL = "ANTEL"


@dataclass(frozen=True)
class Poke:
    """One parsed station command.  ``value``: bool (TUNE/TRACK), int (SAT by catalog number), str (SAT by
    name, TCP and console only, resolved by the station) or float (ANTAZ/ANTEL, degrees)."""

    kind: PokeKind
    value: bool | int | float | str

    def __str__(self) -> str:
        if self.kind in (PokeKind.TUNE, PokeKind.TRACK):
            return f"{self.kind.value} {'ON' if self.value else 'OFF'}"
        return f"{self.kind.value}={self.value}"


class CommandError(ValueError):
    """A command that is not part of the grammar; the message says why in one sentence.

    ``bad_argument`` is True for a known command with a bad argument (OrbitDRV's "bad subfunction"),
    False for something that is not a command at all ("bad function"); ``command`` is that known command.
    """

    def __init__(self, message: str, bad_argument: bool = False, command: Command | None = None) -> None:
        super().__init__(message)
        self.bad_argument = bad_argument
        self.command = command


def escape_for_log(text: str, limit: int = 120) -> str:
    """A one-line, printable rendering of untrusted text (so CR/LF cannot forge log lines)."""
    out = text[:limit].encode("unicode_escape", errors="backslashreplace").decode("ascii")
    return out + ("..." if len(text) > limit else "")


@dataclass(frozen=True)
class Command:
    """One command of the table."""

    word: str  #: the keyword, upper case
    grammar: str  #: regular expression of the whole line (matched case-insensitively, ASCII classes)
    usage: str  #: how it is written, for help texts
    short: str  #: how the refusal of an unknown command lists it
    needs: str  #: what the keyword needs, for the refusal of a bad argument ("SAT needs ...")
    summary: str  #: what it does, one sentence
    reply: str  #: what the sender gets back
    faces: Face
    target: Target
    #: the checked argument from the match (may raise :class:`CommandError`); None for no argument
    convert: Callable[[re.Match[str], Face], object] = lambda match, face: None
    #: what it does (:mod:`nfwserver.commands.actions`), run by the station core for every face
    action: Action = field(kw_only=True)

    def match(self, text: str) -> re.Match[str] | None:
        return re.fullmatch(self.grammar, text, re.IGNORECASE | re.ASCII)


# -- argument converters ------------------------------------------------------------------------------
_NUMBER = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)", re.ASCII)


def _on(match: re.Match[str], face: Face) -> bool:
    return match.group(1).upper() == "ON"


def _satellite(match: re.Match[str], face: Face) -> int | str:
    value = match.group(1).strip()
    if any(ch.isspace() for ch in value) and (face is Face.DDE or value[:1].isdigit()):
        raise CommandError("SAT needs =<catalog number>", bad_argument=True)
    if value.isascii() and value.isdigit() and 1 <= len(value) <= 6:
        return int(value)
    if face is not Face.DDE and value.isascii() and value.isprintable() and any(ch.isalpha() for ch in value) \
            and not value[:1].isdigit():
        return value  # a name (ASCII, with a letter): the station resolves it when it is unique
    raise CommandError(f"SAT needs a catalog number, got '{escape_for_log(value, 20)}'", bad_argument=True)


def _degrees(word: str, low: float, high: float) -> Callable[[re.Match[str], Face], float]:
    def convert(match: re.Match[str], face: Face) -> float:
        value = match.group(1)
        if not _NUMBER.fullmatch(value):
            raise CommandError(f"{word} needs a number of degrees, got '{escape_for_log(value, 20)}'",
                               bad_argument=True)
        number = float(value)
        if not math.isfinite(number):
            raise CommandError(f"{word} value is not finite", bad_argument=True)
        if not low <= number <= high:
            raise CommandError(f"{word} {number} is outside {low:g}..{high:g} degrees", bad_argument=True)
        return number + 0.0

    return convert


def _flip_mode(match: re.Match[str], face: Face) -> str:
    mode = (match.group(1) or "").upper()
    if mode not in ("AUTO", "ON", "OFF"):
        raise CommandError("FLIP needs AUTO, ON or OFF", bad_argument=True)
    return mode.lower()


_STATION_REPLY = ("DDE: acknowledged, or refused (DDE_FNOTPROCESSED) with the reason in the log; TCP: OK, "
                  "or ERROR <reason>")

COMMANDS: tuple[Command, ...] = (
    Command("TUNE", r"TUNE\s+(ON|OFF)", "TUNE ON|OFF", "TUNE ON|OFF", "ON or OFF",
            "switch the Nova string feed on or off (DDE advise loops, requests, TCP WATCH and SUMMARY)",
            _STATION_REPLY, Face.ALL, Target.STATION, _on, action=actions.feed),
    Command("TRACK", r"TRACK\s+(ON|OFF)", "TRACK ON|OFF", "TRACK ON|OFF", "ON or OFF",
            "switch rotor tracking on or off (TRACK ON needs a station and a satellite; without a rotor it is "
            "accepted with a warning)",
            _STATION_REPLY + " (OK warning: <why nothing turns> when the station has no rotor)",
            Face.ALL, Target.STATION, _on, action=actions.track),
    Command("SAT", r"SAT\s*=\s*(.*?)", "SAT=<catalog number>", "SAT=n", "=<catalog number>",
            "select the satellite to track by catalog number; on TCP and the console also by a name that "
            "matches one satellite only; refused when unknown or not computable now",
            _STATION_REPLY, Face.ALL, Target.STATION, _satellite, action=actions.satellite),
    Command("ANTAZ", r"ANTAZ\s*=\s*(\S*)", "ANTAZ=<degrees>", "ANTAZ=deg", "=<degrees>",
            "report the antenna azimuth (-360..720 degrees), as a client with its own rotor read-back does",
            _STATION_REPLY, Face.ALL, Target.STATION, _degrees("ANTAZ", -360.0, 720.0),
            action=actions.antenna_azimuth),
    Command("ANTEL", r"ANTEL\s*=\s*(\S*)", "ANTEL=<degrees>", "ANTEL=deg", "=<degrees>",
            "report the antenna elevation (-90..180 degrees)",
            _STATION_REPLY, Face.ALL, Target.STATION, _degrees("ANTEL", -90.0, 180.0),
            action=actions.antenna_elevation),
    Command("SUMMARY", r"SUMMARY", "SUMMARY", "SUMMARY", "nothing after it",
            "the Nova string being published (an empty line while the feed is off or nothing can be computed)",
            "one line", Face.TCP, Target.SESSION, action=actions.summary),
    Command("STATUS", r"STATUS", "STATUS", "STATUS", "nothing after it",
            "the station's state as key=value pairs: satellite, tune, track, status word, position, faults, "
            "devices", "one line", Face.TCP, Target.SESSION, action=actions.status),
    Command("WATCH", r"WATCH", "WATCH", "WATCH", "nothing after it",
            "stream every published Nova string until the client sends a line (that line ends the stream "
            "and is not executed)", "OK, then one line per published string; OK again for the line that ends it",
            Face.TCP, Target.SESSION, action=actions.watch),
    Command("HELP", r"HELP", "HELP", "HELP", "nothing after it",
            "list the commands this face takes", "one line per command (TCP: then OK)", Face.TCP | Face.CONSOLE,
            Target.SESSION, action=actions.show_help),
    Command("QUIT", r"QUIT", "QUIT", "QUIT", "nothing after it", "close the connection", "OK, then the server closes",
            Face.TCP, Target.SESSION, action=actions.quit_session),
    Command("FLIP", r"FLIP(?:\s+(\S+))?", "FLIP AUTO|ON|OFF", "FLIP AUTO|ON|OFF", "AUTO, ON or OFF",
            "FlipAnts' inverted (flip) tracking: forced on, off, or chosen per pass (auto)",
            f"OK, or ERROR {actions.NO_ROTOR}", Face.TCP | Face.CONSOLE | Face.WEB, Target.ROTOR, _flip_mode,
            action=actions.flip),
    Command("PARK", r"PARK", "PARK", "PARK", "nothing after it",
            "stop tracking (as TRACK OFF) and send the rotor to its park position ([rotor] park_azimuth_deg and "
            "park_elevation_deg); TRACK ON resumes", f"OK, or ERROR {actions.NO_ROTOR}",
            Face.TCP | Face.CONSOLE | Face.WEB, Target.ROTOR, action=actions.park),
    Command("Z", r"Z", "Z", "Z", "nothing after it", "show times in UTC or in the local zone",
            "a note in the console", Face.CONSOLE, Target.DISPLAY, action=actions.toggle_zone),
)


def commands_for(face: Face, target: Target | None = None) -> tuple[Command, ...]:
    """The commands ``face`` may send (only those acting on ``target`` when given), in table order."""
    return tuple(c for c in COMMANDS if face & c.faces and (target is None or c.target is target))


def command(word: str) -> Command:
    """The entry of the keyword ``word``."""
    return next(c for c in COMMANDS if c.word == word.upper())
