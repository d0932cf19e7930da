"""``python -m nfwserver.commands``: print docs/COMMANDS.md, generated from the command table."""

from nfwserver.commands.help_text import markdown

print(markdown(), end="")
