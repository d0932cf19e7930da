"""``nfwserver config``: where the configuration lives, a commented starting file, and what it means."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any

from nfwserver.cli.arguments import number_in
from nfwserver.cli.errors import CliError, load_config_or_fail


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser("config", help="configuration file: path, init, show, set, edit",
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
    init.add_argument("--web", action="store_true", help="serve the web dashboard ([web] enabled = true, on "
                      "127.0.0.1)")
    init.add_argument("--keep", action="store_true", help="leave an existing file as it is and succeed (for "
                      "installers); without it an existing file is an error")
    init.add_argument("--web-control", action="store_true",
                      help="let the web page send commands, with a freshly generated token (printed)")
    init.set_defaults(func=run_init)
    show = sub.add_parser("show", help="validate the file and print what the server will use")
    show.add_argument("--config", metavar="FILE")
    show.set_defaults(func=run_show)
    edit = sub.add_parser("set", help="change one setting, keeping the file's comments",
                          description="Set SECTION.KEY to VALUE in the configuration file (created from the "
                          "template when missing).  The whole file is validated before it is written; a "
                          "refused value changes nothing.  VALUE is read as TOML when it is a TOML value "
                          "(true, 12.5, [25544, 7530]), else as text (JO01ab).  A running station follows the "
                          "file it loaded and applies the change by itself; the command says when a change "
                          "needs a restart.")
    edit.add_argument("key", metavar="SECTION.KEY", help="e.g. observer.location, tcp.enabled, rotor.backend")
    edit.add_argument("value", metavar="VALUE", help='e.g. JO01ab, true, "[25544, 7530]"')
    edit.add_argument("--config", metavar="FILE", help="the file to change (default: the usual location)")
    edit.set_defaults(func=run_set)
    opened = sub.add_parser("edit", help="open the configuration file in your editor (created when missing)",
                            description="Open the configuration file in your editor: $VISUAL or $EDITOR, else "
                            "the system's editor for the file (Notepad on Windows).  A missing file is "
                            "first written from the template, as `config init` does.")
    opened.add_argument("--config", metavar="FILE", help="the file to open (default: the usual location)")
    opened.set_defaults(func=run_edit)


def run_path(args: argparse.Namespace) -> int:
    from nfwserver.config import default_config_path

    print(default_config_path())
    return 0


def run_init(args: argparse.Namespace) -> int:
    from nfwserver.config import default_config_path
    from nfwserver.config.render import template
    from nfwserver.config.tokens import TEMPLATE_TOKEN, new_token
    from nfwserver.file_lock import locked
    from nfwserver.storage import atomic_write_text

    path = _written_through(Path(args.config) if args.config else default_config_path())
    if path.exists() and not args.force:
        if args.keep:
            print(f"{path} (kept as it was)")
            return 0
        raise CliError(f"{path} already exists (use --force to overwrite)")
    if path.exists() and not path.is_file():
        raise CliError(f"{path} is not a regular file; not replacing it")
    if (args.lat is None) != (args.lon is None):
        raise CliError("give both --lat and --lon (or --locator)")
    if args.locator and args.lat is not None:
        raise CliError("give --locator or --lat/--lon, not both")
    token = new_token()  # the template's example token is refused: offer a fresh one instead
    text = template().replace(f'# token = "{TEMPLATE_TOKEN}"', f'# token = "{token}"')
    if args.web_control:
        text = _edited(_edited(text, "web", "token", token, path), "web", "control", True, path)
    derived = ""
    if args.locator or args.lat is not None:
        location = args.locator or f"{args.lat:g},{args.lon:g},{args.alt:g}"
        text = _edited(text, "observer", "location", location, path)
        derived = _position(text, path, location)
    if args.web:
        text = _edited(text, "web", "enabled", True, path)
    try:
        with locked(path):
            atomic_write_text(path, text, _private_mode(text, path))
    except OSError as exc:
        raise CliError(f"cannot write {path}: {exc.strerror or exc} "
                       "(choose another place with --config FILE)") from None
    print(path)
    if derived:
        print(derived)
    if args.web_control:
        print(f"web control is on; the page's token is {token}")
    return 0


def run_edit(args: argparse.Namespace) -> int:
    from nfwserver.cli.config_editor import open_in_editor

    return open_in_editor(Path(args.config) if args.config else None)


def _position(text: str, path: Path, location: str) -> str:
    """The station position ``location`` stands for, as the configuration reads it (a locator is the centre
    of its square), for the operator to check."""
    from nfwserver.config.loader import parse_config

    o = parse_config(text, str(path), path.parent).observer
    ns, ew = ("N" if o.latitude_deg >= 0 else "S"), ("E" if o.longitude_deg >= 0 else "W")
    return (f"observer: {abs(o.latitude_deg):.4f} {ns}, {abs(o.longitude_deg):.4f} {ew}, {o.altitude_m:g} m "
            f"(from {location})")


def run_show(args: argparse.Namespace) -> int:
    """Every key with its effective value; "default" stores resolved to the paths actually used."""
    from dataclasses import replace

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
    if config.web.token:  # a secret: `config show` output ends up in bug reports and screen shares
        config = replace(config, web=replace(config.web, token="********"))
        notes["web.token"] = "hidden (the file holds it)"
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


def _private_mode(text: str, path: Path) -> int | None:
    """0600 for a configuration that holds the web token (a secret: only its owner may read it), else None
    (the file keeps its mode)."""
    from nfwserver.config import ConfigError
    from nfwserver.config.loader import parse_config

    try:
        return 0o600 if parse_config(text, str(path), path.parent).web.token else None
    except ConfigError:
        return None


def _written_through(path: Path) -> Path:
    """The file a write of ``path`` must replace: a symbolic link's target (written through the link, which
    stays), else ``path`` itself."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


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
    from nfwserver.config.table import setting
    from nfwserver.file_lock import locked
    from nfwserver.storage import atomic_write_text

    try:
        section, key = split_key(args.key)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    path = _written_through(Path(args.config) if args.config else default_config_path())
    try:
        with locked(path):  # read, edit and write under the lock: a parallel `config set` loses nothing
            try:
                text = read_config_text(path) if path.exists() else template()
            except ConfigError as exc:
                raise CliError(str(exc)) from None
            new = _edited(text, section, key, parse_value(args.value, setting(section, key).kind), path)
            atomic_write_text(path, new, _private_mode(new, path))
    except OSError as exc:
        raise CliError(f"cannot write {path}: {exc.strerror or exc}") from None
    note = _change_note(text, new, path)
    print(f"{path}: [{section}] {key} set" + (f"; {note}" if note else ""))
    return 0


def _change_note(old_text: str, new_text: str, path: Path) -> str:
    """How a running station takes the change (:func:`nfwserver.app.change_note.change_note`)."""
    from nfwserver.app.change_note import change_note
    from nfwserver.config import ConfigError
    from nfwserver.config.loader import parse_config

    new = parse_config(new_text, str(path), path.parent)
    try:
        old = parse_config(old_text, str(path), path.parent)
    except ConfigError:
        return "a running station applies it within seconds, or names what needs a restart in its log"
    return change_note(old, new)
