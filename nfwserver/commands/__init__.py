"""The station's commands: one table (:mod:`.table`), one parser (:mod:`.parsing`), help generated from them."""

from nfwserver.commands.parsing import Parsed, Request, parse_line, parse_request
from nfwserver.commands.table import COMMANDS, Command, CommandError, Face, Target

__all__ = ["COMMANDS", "Command", "CommandError", "Face", "Parsed", "Request", "Target", "parse_line", "parse_request"]
