"""Help generated from the command table: ``HELP`` on TCP, the console's help line, ``nfwserver poke
--help`` and ``docs/COMMANDS.md`` (``python -m nfwserver.commands > docs/COMMANDS.md``).

Nothing here knows a command by name: a new entry in :data:`nfwserver.commands.table.COMMANDS` shows
up everywhere at once, and ``tests/commands`` fails while the committed document is stale.
"""

from __future__ import annotations

import textwrap

from nfwserver.commands.table import Face, Target, command, commands_for

__all__ = ["help_lines", "input_hint", "markdown", "poke_epilog"]

_FACE_NAMES = ((Face.DDE, "DDE"), (Face.TCP, "TCP"), (Face.CONSOLE, "console"), (Face.WEB, "web"))
_TARGET_NAMES = {Target.STATION: "station", Target.SESSION: "connection", Target.ROTOR: "rotor",
                 Target.DISPLAY: "display"}


def help_lines(face: Face) -> tuple[str, ...]:
    """One line per command ``face`` takes: its usage, padded, then what it does (TCP ``HELP``)."""
    entries = commands_for(face)
    width = max(len(c.usage) for c in entries)
    return tuple(f"{c.usage:<{width}}  {c.summary}" for c in entries)


def input_hint(face: Face) -> str:
    """The hint of an input line of ``face``: a few of its commands' usages, and how to list them all."""
    entries = commands_for(face, Target.STATION)[:3]
    listed = " | ".join(c.short for c in entries)
    listing = command("HELP")
    return f"command: {listed} ..." + (f" ({listing.usage} lists them all)" if face & listing.faces else "")


def poke_epilog(width: int = 79) -> str:
    """``nfwserver poke --help``'s list of the commands the TCP port takes, wrapped to ``width`` columns."""
    entries = commands_for(Face.TCP)
    indent = max(len(c.usage) for c in entries) + 4
    out = ["commands the station takes (any case):"]
    for c in entries:
        out.append(textwrap.fill(c.summary, width, initial_indent=f"  {c.usage:<{indent - 2}}",
                                 subsequent_indent=" " * indent))
    return "\n".join(out)


def _faces(face: Face) -> str:
    return ", ".join(name for flag, name in _FACE_NAMES if face & flag)


def markdown() -> str:
    """``docs/COMMANDS.md``: every command, where it may come from, what it does, what it answers."""
    out = [
        "# Commands",
        "",
        "Generated from `nfwserver/commands/table.py` by `python -m nfwserver.commands > docs/COMMANDS.md`;",
        "a test fails when this file is stale.  Keywords are taken in any case, with blanks around `=`;",
        "numbers are ASCII digits only.  A DDE poke or execute may hold several station commands, one per",
        "line: all are checked before the first takes effect, so a refused poke changes nothing.",
        "",
        "| command | faces | acts on | what it does | reply |",
        "|---|---|---|---|---|",
    ]
    for entry in commands_for(Face.ALL):
        cells = (f"`{entry.usage}`", _faces(entry.faces), _TARGET_NAMES[entry.target], entry.summary, entry.reply)
        out.append("| " + " | ".join(cell.replace("|", "\\|") for cell in cells) + " |")
    out += ["", "Faces: **DDE** = a poke or execute on service `NFW32`/`NFW_SERVER`, topic `NFW_DATA`; "
            "**TCP** = a line on Nova's TCP port (`nfwserver poke` sends one); **console** = the console's "
            "input line; **web** = a command posted by the web dashboard (`[web] control`, docs/WEB.md).", ""]
    return "\n".join(out)
