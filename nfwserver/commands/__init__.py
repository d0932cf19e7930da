"""The station's commands: one table (:mod:`.table`), one parser (:mod:`.parsing`), help generated from them."""

from nfwserver.commands.parsing import Parsed, parse_line, parse_poke
from nfwserver.commands.table import COMMANDS, Command, CommandError, Face, Poke, PokeKind, Target

__all__ = ["COMMANDS", "Command", "CommandError", "Face", "Parsed", "Poke", "PokeKind", "Target", "parse_line",
           "parse_poke"]
