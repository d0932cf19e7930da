"""How the command line reports: the one runtime error, the one diagnostic line, the one configuration load.

Every command raises :class:`CliError` for a runtime problem (``main`` prints it as ``nfwserver: <sentence>``
and exits 1), writes its other diagnostics with :func:`say`, and loads the configuration with
:func:`load_config_or_fail`.  This module imports nothing of the command line, so any command module may
import it at its top.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from nfwserver.config.schema import Config

__all__ = ["CliError", "config_refused", "load_config_or_fail", "say"]


class CliError(Exception):
    """A runtime problem to report in one sentence (exit code 1)."""


def say(text: str) -> None:
    """One diagnostic line on stderr, ``nfwserver: <text>``, in a single write (threads may be logging)."""
    sys.stderr.write(f"nfwserver: {text}\n")
    sys.stderr.flush()


def load_config_or_fail(path: str | None) -> Config:
    """The configuration at ``path`` (None: the default file, or the built-in defaults without one); a file the
    loader refuses is a :class:`CliError` naming why."""
    from nfwserver.config.loader import ConfigError, load_config  # loaded by the commands that need it only

    try:
        return load_config(path)
    except ConfigError as exc:
        raise CliError(f"configuration refused: {exc}") from None


def config_refused(path: str | None) -> CliError | None:
    """Why the configuration at ``path`` (None: the default file) is refused, or None when it loads: for the
    commands that reach a running station, which runs on its last good configuration whatever the file says."""
    try:
        load_config_or_fail(path)
    except CliError as exc:
        return exc
    return None


def say_last_good(problem: CliError) -> None:
    """The one warning line of a command that reached the running station although its file is refused."""
    say(f"warning: {problem}; the running station runs on its last good configuration")
