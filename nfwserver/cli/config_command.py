"""``nfwserver config``: where the configuration lives, a commented starting file, and what it means."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from nfwserver.cli.arguments import number_in
from nfwserver.cli.errors import CliError, load_config_or_fail


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser("config", help="configuration file: path, init, show",
                              description="Manage the configuration file.")
    sub = p.add_subparsers(dest="config_action", metavar="ACTION", required=True)
    sub.add_parser("path", help="print where the configuration file is looked for").set_defaults(func=run_path)
    init = sub.add_parser("init", help="write a commented starting file")
    init.add_argument("--config", metavar="FILE", help="where to write (default: the usual location)")
    init.add_argument("--force", action="store_true", help="overwrite an existing file")
    init.add_argument("--locator", metavar="LOCATOR", help="your station's Maidenhead locator, e.g. JO01ab")
    init.add_argument("--lat", type=number_in(-90, 90, unit="deg"), metavar="DEG",
                      help="your station's latitude, degrees north (with --lon)")
    init.add_argument("--lon", type=number_in(-180, 180, unit="deg"), metavar="DEG",
                      help="your station's longitude, degrees east (with --lat)")
    init.add_argument("--alt", type=number_in(-500, 9000, unit="m"), metavar="M", default=0.0,
                      help="height above the WGS84 ellipsoid, metres (with --lat/--lon; default 0)")
    init.set_defaults(func=run_init)
    show = sub.add_parser("show", help="validate the file and print what the server will use")
    show.add_argument("--config", metavar="FILE")
    show.set_defaults(func=run_show)
    edit = sub.add_parser("set", help="change one setting, keeping the file's comments",
                          description="Set SECTION.KEY to VALUE in the configuration file (created from the "
                          "template when missing).  The whole file is validated before it is written; a "
                          "refused value changes nothing.  VALUE is read as TOML when it is a TOML value "
                          "(true, 12.5, [25544, 7530]), else as text (JO01ab).  A running station applies "
                          "the change by itself.")
    edit.add_argument("key", metavar="SECTION.KEY", help="e.g. observer.location, tcp.enabled, rotor.backend")
    edit.add_argument("value", metavar="VALUE", help='e.g. JO01ab, true, "[25544, 7530]"')
    edit.add_argument("--config", metavar="FILE", help="the file to change (default: the usual location)")
    edit.set_defaults(func=run_set)


def run_path(args: argparse.Namespace) -> int:
    from nfwserver.config import default_config_path

    print(default_config_path())
    return 0


def run_init(args: argparse.Namespace) -> int:
    from nfwserver.config import default_config_path
    from nfwserver.config.render import template
    from nfwserver.storage import atomic_write_text

    path = Path(args.config) if args.config else default_config_path()
    if path.exists() and not args.force:
        raise CliError(f"{path} already exists (use --force to overwrite)")
    if (args.lat is None) != (args.lon is None):
        raise CliError("give both --lat and --lon (or --locator)")
    if args.locator and args.lat is not None:
        raise CliError("give --locator or --lat/--lon, not both")
    text = template()
    if args.locator or args.lat is not None:
        location = args.locator or f"{args.lat:g},{args.lon:g},{args.alt:g}"
        text = _edited(text, "observer", "location", location, path)
    try:
        atomic_write_text(path, text)
    except OSError as exc:
        raise CliError(f"cannot write {path}: {exc.strerror or exc} "
                       "(choose another place with --config FILE)") from None
    print(path)
    return 0


def run_show(args: argparse.Namespace) -> int:
    """Every key with its effective value; "default" stores resolved to the paths actually used."""
    from nfwserver.app.element_store import default_store_path
    from nfwserver.app.session_state import default_state_path
    from nfwserver.config.render import show

    config = load_config_or_fail(args.config)
    notes = {}
    if config.elements.store == "default":
        notes["elements.store"] = f"default: {default_store_path()}"
    elif config.elements.store is None:
        notes["elements.store"] = "no stored catalog"
    if config.state_file == "default":
        notes["server.state_file"] = f"default: {default_state_path()}"
    elif config.state_file is None:
        notes["server.state_file"] = "not kept"
    written = _written(config.path)
    if "location" in written.get("observer", {}):
        notes.update({f"observer.{key}": "from location" for key in ("latitude_deg", "longitude_deg", "altitude_m")})
    sys.stdout.write(show(config, notes, written))
    return 0


def _written(path: str | None) -> dict[str, Any]:
    """The file's own TOML document (values as the user wrote them), or {} for the built-in defaults."""
    if path is None:
        return {}
    from nfwserver.config.loader import read_config_text, toml_document

    return toml_document(read_config_text(Path(path)))


def _edited(text: str, section: str, key: str, value: Any, path: Path) -> str:
    from nfwserver.config import ConfigError
    from nfwserver.config.edit import set_key

    try:
        return set_key(text, section, key, value, str(path), path.parent)
    except ConfigError as exc:
        raise CliError(f"{section}.{key} = {value!r} refused: {'; '.join(exc.problems)}") from None


def run_set(args: argparse.Namespace) -> int:
    """``config set SECTION.KEY VALUE``: edit, validate the whole file, write atomically."""
    from nfwserver.config import ConfigError, default_config_path
    from nfwserver.config.edit import parse_value, split_key
    from nfwserver.config.loader import read_config_text
    from nfwserver.config.render import template
    from nfwserver.storage import atomic_write_text

    try:
        section, key = split_key(args.key)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    path = Path(args.config) if args.config else default_config_path()
    try:
        text = read_config_text(path) if path.exists() else template()
    except ConfigError as exc:
        raise CliError(str(exc)) from None
    new = _edited(text, section, key, parse_value(args.value), path)
    try:
        atomic_write_text(path, new)
    except OSError as exc:
        raise CliError(f"cannot write {path}: {exc.strerror or exc}") from None
    print(f"{path}: [{section}] {key} set")
    return 0
