"""``nfwserver poke TEXT`` and ``nfwserver status``: control a running station over its TCP port.

Host and port are where this user's running station says it listens (its channel,
:mod:`nfwserver.cli.station_channel`), so these commands reach it whatever state the configuration file is in
(a file it refuses is named in one warning line); with no station described, or with ``--config``, they come
from the configuration's ``[tcp]`` section; ``--host`` and ``--port`` override.  So a second terminal or a cron
job can switch a headless station:
``nfwserver poke "TRACK ON"`` (``nfwserver watch``, :mod:`nfwserver.cli.watch_command`, shows it live).
The reply goes to stdout; ``ERROR ...`` replies and an unreachable station are one sentence on stderr with exit code 1.
"""

from __future__ import annotations

import argparse

from nfwserver.cli.arguments import number_in
from nfwserver.cli.errors import CliError, config_refused, load_config_or_fail, say, say_last_good


def add_station_options(p: argparse.ArgumentParser) -> None:
    """``--config``, ``--host``, ``--port`` and ``--timeout``: where the station is (``[tcp]``) and how long to wait."""
    p.add_argument("--config", metavar="FILE", help="configuration file giving [tcp] host and port")
    p.add_argument("--host", help="station address (default: [tcp] host, loopback for a wildcard)")
    p.add_argument("--port", type=number_in(1, 65535, integer=True), help="station TCP port (default: [tcp] port)")
    p.add_argument("--timeout", type=number_in(0, 600, low_open=True, unit="s"), default=5.0, metavar="SECONDS",
                   help="give up after this long (default 5)")


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    from nfwserver.commands.help_text import poke_epilog

    p = subparsers.add_parser(
        "poke", help="send a command to the running station (TCP)",
        description="Send one command to the running station over its TCP port and print the reply.",
        epilog=poke_epilog(), formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("text", help='the command, e.g. "TRACK ON"')
    add_station_options(p)
    p.set_defaults(func=poke)
    s = subparsers.add_parser("status", help="one line of the running station's state (TCP)",
                              description="Print the running station's STATUS line (key=value pairs).")
    add_station_options(s)
    s.set_defaults(func=status)


def station_address(args: argparse.Namespace) -> tuple[str, int]:
    """Host and port of the station: ``--host``/``--port``, else the running station's own description
    (unless ``--config`` names a file that loads), else the configuration's ``[tcp]``."""
    from nfwserver.cli.station_channel import StationChannel
    from nfwserver.tcp.client import connect_host

    if args.host and args.port:  # both given: neither the file nor the channel is asked
        return args.host, int(args.port)
    problem = config_refused(args.config)
    info = StationChannel().serving() if problem is not None or not args.config else None
    if info is not None and info.tcp is not None:
        if problem is not None:
            say_last_good(problem)
        host, port = info.tcp
    elif problem is not None:
        raise problem  # no station to fall back on: the file's problem is the answer
    else:
        config = load_config_or_fail(args.config)
        host, port = connect_host(config.tcp.host), config.tcp.port
    return args.host or host, int(args.port or port)


def _ask(args: argparse.Namespace, line: str, until: str | None = None) -> str:
    from nfwserver.tcp.client import StationUnreachable, ask

    host, port = station_address(args)
    try:
        return ask(host, port, line, args.timeout, until)
    except StationUnreachable as exc:
        raise CliError(str(exc)) from None


def poke(args: argparse.Namespace) -> int:
    import sys

    from nfwserver.commands.parsing import parse_request
    from nfwserver.commands.table import Face

    text = args.text.strip()
    if not text or not text.isascii() or not text.isprintable() or len(text) > 256:
        print("nfwserver poke: the command must be one line of printable ASCII (at most 256 characters)",
              file=sys.stderr)
        return 2
    entry = next(iter(parse_request(text, Face.TCP).commands), None)  # as the station will read it
    if entry is not None and entry.command.streams:
        print(f"nfwserver poke: {entry.command.usage} streams until stopped: `nfwserver watch` shows the station "
              "live (`nfwserver watch --json` for scripts)", file=sys.stderr)
        return 2
    reply = _ask(args, text, until="OK" if entry is not None and entry.command.reply_until_ok else None)
    if reply.startswith("ERROR"):
        raise CliError(f"the station refused {text!r}: {reply[5:].strip()}")
    print(reply)
    return 0


def status(args: argparse.Namespace) -> int:
    """The STATUS line on stdout; a stale element set (``elements_stale=yes``) is also said on stderr."""

    from nfwserver.tcp.status_line import parse_status

    line = _ask(args, "STATUS")
    print(line)
    fields = parse_status(line)
    if fields.get("elements_stale") == "yes":
        name = fields.get("name", "the selected satellite")
        say(f"the elements of {name} are {fields.get('elements_age_d', '?')} days old, older than "
              "[elements] stale_days: positions drift; `nfwserver elements update` fetches current ones")
    return 0
