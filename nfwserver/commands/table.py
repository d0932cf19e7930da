"""The one table of the station's commands: every face parses, dispatches and documents through it.

In the spirit of Hamlib's ``rotctl_parse.c``: each :class:`Command` is one entry holding its grammar
(a whole-line regular expression, keywords in any case, blanks allowed around ``=``), the faces that
may send it (:class:`Face`), what it acts on (:class:`Target`: the station core, the TCP session, the
rotor, the console's display), how its argument is converted, its check/resolve step on the station
(``SAT=`` by name: the one satellite of that name, computable now), its reply, and its action
(:mod:`nfwserver.commands.actions`).  The station core runs the check and the action and records the
command, whichever face sent it; a console key names its entry and argument directly.  The
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
from nfwserver.commands.actions import Action, Check, Refused, StationPort

__all__ = ["COMMANDS", "DOPPLER_SWITCH", "FEED_SWITCH", "FLIP_MODE", "SATELLITE_CHOICE", "ZONE_TOGGLE", "Command",
           "CommandError", "Face", "Target", "command", "commands_for", "escape_for_log"]

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
    #: the station's check of the converted argument, run before any command of a poke takes effect: returns
    #: the argument the action takes, raises :class:`~nfwserver.commands.actions.Refused`
    check: Check = field(default=lambda station, value: value, kw_only=True)
    #: the reply is a stream that lasts until the client sends a line (WATCH)
    streams: bool = field(default=False, kw_only=True)
    #: the reply is several lines, the last one ``OK`` (HELP on TCP)
    reply_until_ok: bool = field(default=False, kw_only=True)

    def match(self, text: str) -> re.Match[str] | None:
        return re.fullmatch(self.grammar, text, re.IGNORECASE | re.ASCII)

    def spell(self, value: object) -> str:
        """The command as a client would write it with the argument ``value`` (a key's record, and its text)."""
        if value is None:
            return self.word
        if isinstance(value, bool):
            return f"{self.word} {'ON' if value else 'OFF'}"
        if "=" in self.usage:
            return f"{self.word}={value:g}" if isinstance(value, float) else f"{self.word}={value}"
        return f"{self.word} {str(value).upper()}"


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


def _check_satellite(station: StationPort, value: object) -> int:
    """``SAT=``'s check: the catalog number of the satellite ``value`` names (a catalog number, or a name that
    matches one satellite only) when it can be computed now; else :class:`Refused`, saying why."""
    named = value if isinstance(value, (int, str)) else str(value)
    found = station.satellites(named)
    shown = escape_for_log(str(named), 40)
    if not found:
        raise Refused((f"satellite {named} is not in the catalog" if isinstance(named, int) else
                       f"no satellite is named '{shown}'") + "; keeping the current one")
    if len(found) > 1:
        numbers = ", ".join(str(number) for number, _ in found[:5]) + (", ..." if len(found) > 5 else "")
        raise Refused(f"{len(found)} satellites are named '{shown}' ({numbers}); use the catalog number; "
                      "keeping the current one")
    number, name = found[0]
    problem = station.why_not_computable(number)
    if problem is not None:
        raise Refused(f"satellite {number} {name} cannot be computed now ({problem}); keeping the current one")
    return number


def _check_autotrack(station: StationPort, value: object) -> object:
    """``AUTO``'s check: the station has an autotrack to switch."""
    if station.autotrack is None:
        raise Refused("this station has no autotrack (it runs with `nfwserver run` or `simulate --config`)")
    return value


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
            "rotor tracking on or off (ON needs a station and a satellite; without a rotor it warns)",
            _STATION_REPLY + " (OK warning: <why nothing turns> when the station has no rotor)",
            Face.ALL, Target.STATION, _on, action=actions.track),
    Command("SAT", r"SAT\s*=\s*(.*?)", "SAT=<catalog number>", "SAT=n", "=<catalog number>",
            "select the satellite by catalog number (TCP, console, web: or by a name only one has); refused when "
            "unknown or not computable now",
            _STATION_REPLY + " (OK warning: autotrack switched off, when it was on)", Face.ALL, Target.STATION,
            _satellite, action=actions.satellite, check=_check_satellite),
    Command("ANTAZ", r"ANTAZ\s*=\s*(\S*)", "ANTAZ=<degrees>", "ANTAZ=deg", "=<degrees>",
            "report the antenna azimuth (-360..720 degrees), as a client with its own rotor read-back does",
            _STATION_REPLY, Face.ALL, Target.STATION, _degrees("ANTAZ", -360.0, 720.0),
            action=actions.antenna_azimuth),
    Command("ANTEL", r"ANTEL\s*=\s*(\S*)", "ANTEL=<degrees>", "ANTEL=deg", "=<degrees>",
            "report the antenna elevation (-90..180 degrees)",
            _STATION_REPLY, Face.ALL, Target.STATION, _degrees("ANTEL", -90.0, 180.0),
            action=actions.antenna_elevation),
    Command("DOPPLER", r"DOPPLER\s+(ON|OFF)", "DOPPLER ON|OFF", "DOPPLER ON|OFF", "ON or OFF",
            "the radio's Doppler tuning on or off (OrbitDRV's tuning, not TUNE); without a radio it warns",
            _STATION_REPLY + " (OK warning: <why nothing is tuned> when the station has no radio)",
            Face.ALL, Target.STATION, _on, action=actions.doppler),
    Command("AUTO", r"AUTO\s+(ON|OFF)", "AUTO ON|OFF", "AUTO ON|OFF", "ON or OFF",
            "autotrack: follow the [autotrack] schedule; any accepted SAT= switches it off",
            _STATION_REPLY + " (OK warning: <why> when AUTO ON finds no satellite of its list, or leaves names out)",
            Face.ALL, Target.STATION, _on, action=actions.autotrack, check=_check_autotrack),
    Command("SUMMARY", r"SUMMARY", "SUMMARY", "SUMMARY", "nothing after it",
            "the Nova string being published (an empty line while the feed is off or nothing can be computed)",
            "one line", Face.TCP, Target.SESSION, action=actions.summary),
    Command("STATUS", r"STATUS", "STATUS", "STATUS", "nothing after it",
            "the station's state as key=value pairs: satellite, tune, track, status word, position, faults, "
            "devices", "one line", Face.TCP, Target.SESSION, action=actions.status),
    Command("WATCH", r"WATCH", "WATCH", "WATCH", "nothing after it",
            "stream every published Nova string until the client sends a line (that line ends the stream "
            "and is not executed)", "OK, then one line per published string; OK again for the line that ends it",
            Face.TCP, Target.SESSION, action=actions.watch, streams=True),
    Command("HELP", r"HELP", "HELP", "HELP", "nothing after it",
            "list the commands this face takes", "one line per command (TCP: then OK)", Face.TCP | Face.CONSOLE,
            Target.SESSION, action=actions.show_help, reply_until_ok=True),
    Command("QUIT", r"QUIT", "QUIT", "QUIT", "nothing after it", "close the connection", "OK, then the server closes",
            Face.TCP, Target.SESSION, action=actions.quit_session),
    Command("FLIP", r"FLIP(?:\s+(\S+))?", "FLIP AUTO|ON|OFF", "FLIP AUTO|ON|OFF", "AUTO, ON or OFF",
            "FlipAnts' inverted (flip) tracking: forced on, off, or chosen per pass (auto)",
            f"OK, or ERROR {actions.NO_ROTOR}", Face.TCP | Face.CONSOLE | Face.WEB, Target.ROTOR, _flip_mode,
            action=actions.flip),
    Command("PARK", r"PARK", "PARK", "PARK", "nothing after it",
            "stop tracking (TRACK OFF) and turn the rotor to [rotor] park_azimuth_deg/park_elevation_deg; "
            "TRACK ON resumes", f"OK, or ERROR {actions.NO_ROTOR}",
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


#: The entries a console key acts on directly (the key gives the entry and its argument; no text is parsed),
#: and those whose effect the ``simulate`` command looks ahead for.
FEED_SWITCH = command("TUNE")
SATELLITE_CHOICE = command("SAT")
DOPPLER_SWITCH = command("DOPPLER")
FLIP_MODE = command("FLIP")
ZONE_TOGGLE = command("Z")
