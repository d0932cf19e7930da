"""``nfwserver config``: where the configuration lives, a commented starting file, and what it means."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser("config", help="configuration file: path, init, show",
                              description="Manage the configuration file.")
    sub = p.add_subparsers(dest="config_action", metavar="ACTION", required=True)
    sub.add_parser("path", help="print where the configuration file is looked for").set_defaults(func=run_path)
    init = sub.add_parser("init", help="write a commented starting file")
    init.add_argument("--config", metavar="FILE", help="where to write (default: the usual location)")
    init.add_argument("--force", action="store_true", help="overwrite an existing file")
    init.set_defaults(func=run_init)
    show = sub.add_parser("show", help="validate the file and print what the server will use")
    show.add_argument("--config", metavar="FILE")
    show.set_defaults(func=run_show)


def run_path(args: argparse.Namespace) -> int:
    from nfwserver.config import default_config_path

    print(default_config_path())
    return 0


def run_init(args: argparse.Namespace) -> int:
    from nfwserver.cli import CliError
    from nfwserver.config import default_config_path
    from nfwserver.config.render import template
    from nfwserver.storage import atomic_write_text

    path = Path(args.config) if args.config else default_config_path()
    if path.exists() and not args.force:
        raise CliError(f"{path} already exists (use --force to overwrite)")
    try:
        atomic_write_text(path, template())
    except OSError as exc:
        raise CliError(f"cannot write {path}: {exc.strerror or exc} "
                       "(choose another place with --config FILE)") from None
    print(path)
    return 0


def run_show(args: argparse.Namespace) -> int:
    """Every key with its effective value; "default" stores resolved to the paths actually used."""
    from nfwserver.app.element_store import default_store_path
    from nfwserver.app.session_state import default_state_path
    from nfwserver.cli import CliError
    from nfwserver.config import ConfigError, load_config
    from nfwserver.config.render import show

    try:
        config = load_config(args.config)
    except ConfigError as exc:
        raise CliError(f"configuration refused: {exc}") from None
    notes = {}
    if config.elements.store == "default":
        notes["elements.store"] = f"default: {default_store_path()}"
    elif config.elements.store is None:
        notes["elements.store"] = "no stored catalog"
    if config.state_file == "default":
        notes["server.state_file"] = f"default: {default_state_path()}"
    elif config.state_file is None:
        notes["server.state_file"] = "not kept"
    sys.stdout.write(show(config, notes))
    return 0
