"""The ``nfwserver`` command: one sub-command per module of this package.

Each command module exposes ``register(subparsers)``, which adds its sub-parser and sets
``func`` (a callable taking the parsed namespace and returning the exit code) as a default.
Only the module of the command being run is imported (:data:`nfwserver.cli.arguments.COMMANDS`
lists every command with its help line for ``--help``), so start-up does not pay for numpy,
the DDE server or the console unless the command needs them.
Conventions (README, "Command line"): data on stdout, diagnostics on stderr; exit 0 on success, 2 for
usage errors, 1 for runtime errors, with one clear sentence and no traceback for bad input.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import logging
import sys
from collections.abc import Sequence

from nfwserver.blas_threads import single_threaded_blas
from nfwserver.cli.arguments import COMMANDS, command_word, join_negative_values
from nfwserver.cli.errors import CliError, say

#: Command modules, in the order their commands appear in ``--help``.
COMMAND_MODULES: tuple[str, ...] = tuple(dict.fromkeys(module for _, module, _ in COMMANDS))


__all__ = ["CliError", "TerminalFormatter", "build_parser", "entry", "main", "say"]


class TerminalFormatter(logging.Formatter):
    """Log records on the terminal as the command's other diagnostics: ``nfwserver: warning: <message>`` (the
    logger's name too with ``with_names``, for ``-vv``).  The handler writes each record whole, in one write, so
    records from the station's threads never run into each other or into :func:`say`'s lines."""

    def __init__(self, with_names: bool = False) -> None:
        super().__init__()
        self.with_names = with_names

    def format(self, record: logging.LogRecord) -> str:
        text = super().format(record)
        where = f" ({record.name})" if self.with_names else ""
        return f"nfwserver: {record.levelname.lower()}{where}: {text}"


class VersionAction(argparse.Action):
    """``--version``: prints ``nfwserver <version>`` and exits; the version is derived only then (in a checkout
    it asks git: :mod:`nfwserver.release`), not for every command."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS,
                         help="show the program's version and exit")

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: object,
                 option_string: str | None = None) -> None:
        from nfwserver.release import package_version

        print(f"nfwserver {package_version()}")
        parser.exit()


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The argument parser; with ``argv``, only the module of the command named in it is imported
    (the other commands get help-only stand-ins), without it every command module is."""
    parser = argparse.ArgumentParser(
        prog="nfwserver",
        description="Satellite-tracking server speaking Nova for Windows' DDE interface.",
    )
    parser.add_argument("--version", action=VersionAction)
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more diagnostics on stderr")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    wanted = command_word(argv) if argv is not None else None
    chosen = {module for name, module, _ in COMMANDS if argv is None or name == wanted}
    done: set[str] = set()
    for name, module, help_text in COMMANDS:
        if module in chosen:
            if module not in done:
                importlib.import_module(f"nfwserver.cli.{module}").register(subparsers)
                done.add(module)
        else:
            subparsers.add_parser(name, help=help_text, add_help=False)
    return parser


def entry() -> int:
    """The ``nfwserver`` process (the installed command, ``python -m nfwserver``): :func:`main`, whose objects
    are then left to the process's end.  The interpreter's shutdown searches every object it still tracks for
    reference cycles, module by module (45 ms of a 0.5 s ``passes`` over 2,000 satellites); frozen
    (:func:`gc.freeze`), they are freed without that search.  Only what would be freed as part of a cycle is
    left to the system, which reclaims the whole process anyway: the command has written and flushed its
    output, and ``atexit`` handlers (logging's flush) still run.  Not for callers that go on after
    :func:`main` (tests): their cycles would never be collected."""
    try:
        return main()
    finally:
        gc.freeze()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the process exit code."""
    if sys.stdout is not None and sys.stderr is not None:
        return _main(argv)
    from nfwserver.cli import windowless  # nfwserverw.exe: no console, so no standard streams

    tail = windowless.capture()
    try:
        code = _main(argv)
    except SystemExit as exc:  # argparse: usage errors (2), --help and --version (0)
        code = exc.code if isinstance(exc.code, int) else 2
    except Exception:  # a failure nobody would otherwise see: its traceback goes into the message box
        import traceback

        traceback.print_exc()
        code = 1
    windowless.report(tail, code)
    return code


def _main(argv: Sequence[str] | None = None) -> int:
    single_threaded_blas()  # before a command loads numpy
    args_list = join_negative_values(list(sys.argv[1:] if argv is None else argv))
    parser = build_parser(args_list)
    args = parser.parse_args(args_list)
    terminal = logging.StreamHandler(sys.stderr)
    terminal.setFormatter(TerminalFormatter(with_names=args.verbose >= 2))
    logging.basicConfig(level=logging.WARNING - 10 * min(args.verbose, 2), handlers=[terminal])
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(func(args) or 0)
    except CliError as exc:
        say(str(exc))
        return 1
    except OSError as exc:  # a file or device the command could not use: one line, the details with -v
        where = f": {exc.filename}" if exc.filename else ""
        say(f"{exc.strerror or exc}{where}")
        if args.verbose:
            logging.getLogger("nfwserver").debug("details", exc_info=True)
        return 1
    except KeyboardInterrupt:
        return 130
