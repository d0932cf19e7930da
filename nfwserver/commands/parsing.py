"""Parsing command text through the table (:mod:`nfwserver.commands.table`), for every face.

:func:`parse_request` reads what a face received: one command, or from a DDE poke or execute Nova's
station commands, several, one per line: every line must parse before any is taken, so a half-understood
poke changes nothing.  :meth:`Request.of` is a command a console key gives as its entry and argument,
with no text to parse.  Surrounding NULs, CR/LF and blanks are stripped, keywords are matched in any case.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from nfwserver.commands.table import (
    MAX_COMMAND_LENGTH,
    Command,
    CommandError,
    Face,
    Target,
    commands_for,
)

__all__ = ["Parsed", "Request", "clean_command_text", "parse_line", "parse_request"]


@dataclass(frozen=True)
class Parsed:
    """One command as parsed: its table entry and its checked argument (None when it takes none)."""

    command: Command
    value: object


@dataclass(frozen=True)
class Request:
    """What a face received, parsed once: the commands in it, or why it is not a command."""

    text: str  #: as received
    face: Face
    commands: tuple[Parsed, ...]  #: empty when refused
    error: CommandError | None = None

    @classmethod
    def of(cls, entry: Command, value: object, face: Face) -> Request:
        """The command ``entry`` with the argument ``value`` (of the type its converter gives), as a key of
        ``face`` sends it: no text is parsed; the record shows it as a client would write it."""
        return cls(entry.spell(value), face, (Parsed(entry, value),))

    @property
    def target(self) -> Target:
        """What the text acts on: its entry's target, the station's when no entry is known (a station
        command's refusal is the station's to count and explain)."""
        entry = self.commands[0].command if self.commands else (self.error.command if self.error else None)
        return entry.target if entry is not None else Target.STATION


def clean_command_text(text: str) -> str:
    """Strip the NULs, CR/LF and blanks that clients leave around a command."""
    return text.strip("\x00\r\n\t ")


def _unknown(face: Face) -> str:
    station = ", ".join(c.short for c in commands_for(face, Target.STATION))
    return f"not a Nova command ({station})"


def parse_line(text: str, face: Face, target: Target | None = None) -> Parsed:
    """One command from ``face`` (only commands acting on ``target`` when given); raises :class:`CommandError`."""
    text = clean_command_text(text)
    if not text:
        raise CommandError("empty poke")
    if len(text) > MAX_COMMAND_LENGTH:
        raise CommandError(f"poke of {len(text)} characters is too long")
    known = commands_for(face, target)
    for entry in known:
        match = entry.match(text)
        if match:
            try:
                return Parsed(entry, entry.convert(match, face))
            except CommandError as exc:
                raise CommandError(str(exc), exc.bad_argument, entry) from None
    word = re.match(r"\w+", text, re.ASCII)
    for entry in known:
        if word and word.group(0).upper() == entry.word:
            raise CommandError(f"{entry.word} needs {entry.needs}", bad_argument=True, command=entry)
    raise CommandError(_unknown(face))


def _station_lines(text: str) -> list[str]:
    if len(text) > 4 * MAX_COMMAND_LENGTH:
        raise CommandError(f"poke of {len(text)} characters is too long")
    lines = [p for p in re.split(r"[\r\n\x00]+", text) if clean_command_text(p)]
    if not lines:
        raise CommandError("empty poke")
    return lines


def parse_request(text: str, face: Face) -> Request:
    """``text`` as ``face`` sends it, parsed once; never raises.

    A DDE poke or execute holds Nova's station commands, one per line (CR, LF or NUL between them), all
    parsed before any is taken; the other faces send one command, of any target the face may use (several
    lines from them are read as a DDE poke is)."""
    try:
        lines = _station_lines(text)
        if face is Face.DDE or len(lines) > 1:
            parsed = tuple(parse_line(line, face, Target.STATION) for line in lines)
        else:
            parsed = (parse_line(text, face),)
    except CommandError as exc:
        return Request(text, face, (), exc)
    return Request(text, face, parsed)
