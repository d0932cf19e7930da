"""The ``nfwserver`` command: one sub-command per module of this package.

Each command module exposes ``register(subparsers)``, which adds its sub-parser and sets
``func`` (a callable taking the parsed namespace and returning the exit code) as a default.
Conventions (DESIGN.md §9): data on stdout, diagnostics on stderr; exit 0 on success, 2 for
usage errors, 1 for runtime errors, with one clear sentence and no traceback for bad input.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence

from nfwserver import __version__

#: Command modules, in the order their commands appear in ``--help``.
COMMAND_MODULES: tuple[str, ...] = (
    "run_command",
    "simulate_command",
    "tracking_commands",
    "elements_command",
    "config_command",
    "control_command",
)


class CliError(Exception):
    """A runtime problem to report in one sentence (exit code 1)."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="nfwserver",
        description="Satellite-tracking server speaking Nova for Windows' DDE interface.",
    )
    parser.add_argument("--version", action="version", version=f"nfwserver {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more diagnostics on stderr")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(f"nfwserver.cli.{name}").register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the process exit code."""
    from nfwserver.cli.arguments import join_negative_values

    args_list = join_negative_values(list(sys.argv[1:] if argv is None else argv))
    parser = build_parser()
    args = parser.parse_args(args_list)
    logging.basicConfig(
        level=logging.WARNING - 10 * min(args.verbose, 2),
        format="%(levelname)s %(name)s: %(message)s",
        stream=sys.stderr,
    )
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(func(args) or 0)
    except CliError as exc:
        print(f"nfwserver: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
