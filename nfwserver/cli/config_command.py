"""``nfwserver config``: where the configuration lives, a commented starting file, and what it means."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
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
    from nfwserver.config.loader import TEMPLATE
    from nfwserver.storage import atomic_write_text

    path = Path(args.config) if args.config else default_config_path()
    if path.exists() and not args.force:
        raise CliError(f"{path} already exists (use --force to overwrite)")
    atomic_write_text(path, TEMPLATE)
    print(path)
    return 0


def run_show(args: argparse.Namespace) -> int:
    from nfwserver.cli import CliError
    from nfwserver.config import ConfigError, load_config

    try:
        config = load_config(args.config)
    except ConfigError as exc:
        raise CliError(f"configuration refused: {exc}") from None
    out = sys.stdout
    out.write(f"source: {config.source}\n")
    out.write(f"observer: {config.observer}{'' if config.observer_configured else ' (default)'}\n")
    out.write(f"horizon: {config.horizon.points or 'flat 0 deg'}\n")
    out.write(f"elements: bundled={config.elements.use_bundled} files={list(config.elements.files)} "
              f"urls={list(config.elements.urls)} refresh_hours={config.elements.refresh_hours:g}\n")
    s = config.server
    out.write(f"server: rate {s.rate_hz:g} Hz, services {list(s.services)}, topic {s.topic}, items {list(s.items)}, "
              f"satellite {s.satellite}, UT1-UTC {s.ut1_utc_s:g} s\n")
    out.write(f"DDE names: {config.dde_names or 'derived'}; favourites: {list(config.favourites)}\n")
    return 0
