"""``nfwserver simulate``: what will *my* client see?  The real server on the in-process DDE transport
under a virtual clock, with one client playing a real client's transaction pattern.

Default: a hot advise loop on NFW32|NFW_DATA!NFW_SERVER, every string printed as
``<ISO-8601 UTC with ms and Z><TAB><string>``, the time being the instant the values were computed
for.  With ``--client`` (:mod:`nfwserver.cli.simulated_clients`) each transaction is printed as
``<time><TAB><kind><TAB><text>``, kind ``data``, ``notify``, ``reply`` or ``poke`` (``(empty)`` for an
empty string).  ``--link`` watches any served item, the Orbitron, WXtrack and SatPC32 dialects
included.  Pokes are scheduled with ``--poke 120:SAT=25544`` (sent 120 s in); ``TUNE ON`` is poked
at the start unless the first TUNE command among the ``--poke`` options is ``TUNE ON`` or is sent at
0 s (so ``--poke 60:"TUNE OFF"`` shows the feed stopping, and ``--poke 30:"TUNE ON"`` what a client
gets before it).  Each ``--poke`` is sent as given, whatever it holds, and what the server did with
it is said on stderr (:mod:`nfwserver.cli.simulate_pokes`).  A poke takes the path of a DDE client's:
through Nova's DDE service on the in-process transport to the station core.  The dialects take no pokes
(their clients never send any), so on a dialect link the pokes go to Nova's item on a second conversation.
"""

from __future__ import annotations

import argparse
import logging
import sys

from nfwserver.app.autotrack_link import StationAutotrack
from nfwserver.cli.arguments import number_in, satellite_value, time_value
from nfwserver.cli.errors import CliError, say
from nfwserver.cli.simulate_pokes import MAX_DURATION_S, commands_of, observe_poke, poke_value
from nfwserver.cli.simulated_clients import CLIENTS, Link, SimulatedClient, parse_link
from nfwserver.cli.tracking_options import add_tracking_options, format_time, load_tracking_inputs
from nfwserver.clock import VirtualClock
from nfwserver.commands.parsing import Parsed
from nfwserver.commands.table import FEED_SWITCH, SATELLITE_CHOICE
from nfwserver.core.publisher import run_virtual
from nfwserver.core.state import MAX_RATE_HZ, MIN_RATE_HZ
from nfwserver.core.station_core import StationCore
from nfwserver.dde.nova_service import NovaDdeService
from nfwserver.dialects.dde_service import DialectServer
from nfwserver.dialects.orbitron import ORBITRON
from nfwserver.dialects.satpc32 import SATPC32
from nfwserver.dialects.wxtrack import WXTRACK
from nfwserver.fake_dde import DdeError, FakeDdeSystem

NOVA_LINK = Link("NFW32", "NFW_DATA", "NFW_SERVER")
DIALECTS = {d.service.upper(): d for d in (ORBITRON, WXTRACK, SATPC32)}


def link_value(text: str) -> Link:
    try:
        return parse_link(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser(
        "simulate", help="show what a DDE client receives, on virtual time",
        description="Run the server on the in-process DDE transport under a virtual clock with one client "
        "playing a real client's transaction pattern, and print what it receives. Defaults: the configured "
        "observer, catalog and satellite, from now. TUNE ON is poked at the start unless the first TUNE "
        "command among the --poke options is TUNE ON or is sent at 0 s (so you can see what a client gets before "
        "TUNE ON). What each "
        "--poke did is printed on stderr.")
    add_tracking_options(p, output_format=False)
    p.add_argument("--start", type=time_value, default="now",
                   help="'now' (default), relative (+2h, -30m) or ISO-8601 (UTC when no zone is given)")
    p.add_argument("--duration", type=number_in(0, MAX_DURATION_S, low_open=True, unit="s"), default=600.0,
                   metavar="SECONDS", help="virtual duration (default 600)")
    p.add_argument("--rate", type=number_in(MIN_RATE_HZ, MAX_RATE_HZ, unit="Hz"), default=5.0, metavar="HZ",
                   help=f"publish rate, {MIN_RATE_HZ:g}-{MAX_RATE_HZ:g} Hz (default 5)")
    p.add_argument("--sat", type=satellite_value, metavar="CATNR|NAME",
                   help="initial AutoTracking satellite (default: [server] satellite)")
    p.add_argument("--poke", type=poke_value, action="append", default=[], metavar="[SECONDS:]TEXT",
                   help="poke sent by the client at that offset (default 0): any text, sent as it is (a command the "
                        "server refuses too); repeatable; what the server did with it is printed on stderr. A "
                        "first TUNE command that is TUNE ON, or is sent at 0 s, replaces the automatic TUNE ON at "
                        "the start")
    p.add_argument("--client", choices=CLIENTS, default="hot",
                   help="transaction pattern: hot (hot advise, default), warm (warm advise), wisp (poke, request "
                        "every --poll s, re-poke when AH: is missing), delphi (warm link + request per "
                        "notification), ndde (hot link + 1 s requests), matlab (poke, then requests)")
    p.add_argument("--poll", type=number_in(0, 3600, unit="s"), metavar="SECONDS",
                   help="request interval of wisp/matlab (default 3) and ndde (default 1); wisp with 0: warm "
                        "link + a request per notification")
    p.add_argument("--link", type=link_value, default=NOVA_LINK, metavar="SERVICE|TOPIC!ITEM",
                   help=f"item to watch (default {NOVA_LINK}); e.g. Orbitron|Tracking!TrackingDataEx, "
                        "WXtrack|Tracking!Tracking, SatPC32|SatPcDdeConv!SatPcDdeItem")
    p.set_defaults(func=run, usage_error=p.error)


def _pokes_decide_feed(previews: list[tuple[float, tuple[Parsed, ...]]]) -> bool:
    """True when the first feed switch among the pokes (sorted by offset) switches it on or is sent at the start:
    the user then decides when the feed starts, and no automatic one is poked for them.  ``previews`` are the
    pokes as the DDE face parses them (a poke it refuses switches nothing)."""
    switches = [(offset, parsed.value) for offset, commands in previews for parsed in commands
                if parsed.command is FEED_SWITCH]
    return bool(switches) and (switches[0][1] is True or switches[0][0] == 0)


def _first_sat(previews: list[tuple[float, tuple[Parsed, ...]]]) -> float | None:
    """The offset of the first poke that chooses a satellite, as the DDE face parses it."""
    return next((offset for offset, commands in previews
                 if any(parsed.command is SATELLITE_CHOICE for parsed in commands)), None)


def run(args: argparse.Namespace) -> int:

    pokes = sorted(args.poke, key=lambda p: p[0])
    late = [command for offset, command in pokes if offset > args.duration]
    if late:
        args.usage_error(f"--poke {late[0]!r} comes after the end of --duration {args.duration:g} s")
    if args.poll is not None and args.poll == 0 and args.client != "wisp":
        args.usage_error("--poll 0 (a request per notification) is WiSP's mode: use it with --client wisp")
    inputs = load_tracking_inputs(args)
    clock = VirtualClock(args.start)
    wanted = str(args.sat) if args.sat is not None else (str(inputs.satellite) if inputs.satellite else None)
    sat = inputs.catalog.find(wanted) if wanted is not None else None
    if wanted is not None and sat is None:
        if args.sat is not None:
            raise CliError(f"satellite {wanted} is not in the catalog")
        say(f"[server] satellite {wanted} is not in the catalog")
    # the station's start-up selection, as ``run`` makes it from [server] satellite
    server = StationCore(inputs.catalog, inputs.observer, clock, horizon=inputs.horizon, ut1_utc=inputs.ut1_utc,
                         rate_hz=args.rate, satellite=sat.catalog_number if sat is not None else None)
    previews = [(offset, commands_of(command)) for offset, command in pokes]  # read once, before any is sent
    autotrack = StationAutotrack(server, clock, inputs.config)  # [autotrack] of the configuration; AUTO ON|OFF
    if inputs.config().autotrack.enabled:
        say(autotrack.restore(None, None, None, "no state file") + ": it selects the satellites of its schedule")
    elif sat is None:
        sat_poke = _first_sat(previews)
        if sat_poke is None:
            say("no --sat given and no [server] satellite in the catalog: no AutoTracking satellite, so nothing is "
                "published")
        elif sat_poke > 0:
            say(f"no satellite until the SAT= poke at {sat_poke:g} s: nothing is published before it")
    auto_feed = not _pokes_decide_feed(previews)
    return _simulate(args, server, clock, pokes, auto_feed, autotrack)


def _simulate(args: argparse.Namespace, server: StationCore, clock: VirtualClock,
              pokes: list[tuple[float, str]], auto_feed: bool, autotrack: StationAutotrack) -> int:
    # Refusals are reported below with their time; keep the core's own warning out of the way
    # (restored on the way out: the logger is shared with anything else in this process).
    core_log = logging.getLogger("nfwserver.core.station_core")
    saved_level = core_log.level
    core_log.setLevel(logging.ERROR)
    system = FakeDdeSystem(received_capacity=16)
    link: Link = args.link
    dialect = DIALECTS.get(link.service.upper())
    nova = NovaDdeService(server)  # pokes go to Nova's item, as a client's do, whichever item is watched
    nova.attach(system.server_transport())
    services: list[NovaDdeService | DialectServer] = [nova]
    if dialect is not None:
        services.append(DialectServer(dialect, server))
        services[-1].attach(system.server_transport())
    lines: list[str] = []
    marked = args.client != "hot"

    def emit(kind: str, text: str) -> None:
        text = text.replace("\r", "\\r").replace("\n", "\\n")  # SatPC32 ends in CR LF: one line each
        sample = server.snapshot().last_sample
        when = sample.time if sample is not None and kind != "poke" else clock.now()
        if marked:
            lines.append(f"{format_time(when)}\t{kind}\t{text or '(empty)'}\n")
        elif kind == "data":
            lines.append(f"{format_time(when)}\t{text}\n")

    try:
        conversation = system.connect(link.service, link.topic, client_name="simulate")
        pokes_to = conversation if dialect is None else system.connect(NOVA_LINK.service, NOVA_LINK.topic,
                                                                       client_name="simulate")
    except DdeError:
        for service in services:
            service.detach()
        core_log.setLevel(saved_level)
        served = "NFW32|NFW_DATA or NFW_SERVER|NFW_DATA, " + ", ".join(f"{d.service}|{d.topic}"
                                                                        for d in DIALECTS.values())
        args.usage_error(f"--link {link}: nothing serves that service and topic here (served: {served})")
    client = SimulatedClient(args.client, conversation, link.item, emit, args.poll)
    pending = [(0.0, FEED_SWITCH.spell(True), False)] if auto_feed else []  # the automatic one is not reported
    pending += [(offset, command, True) for offset, command in pokes]
    started = False
    previous: list[float] = []  # the offset of the tick published last

    def send(command: str) -> None:
        if dialect is None:
            client.poke(command)
            return
        try:  # the dialects take no pokes (their clients never send any): a poke on Nova's item, as a client's
            pokes_to.poke(NOVA_LINK.item, command)
            verdict = ""
        except DdeError:
            verdict = ", refused"
        emit("poke", f"{command} (on {NOVA_LINK}{verdict})")

    def before_tick(offset: float) -> None:
        nonlocal started
        if previous:  # the client's requests due by the previous tick, once it was published
            client.after_tick(previous[0])
        previous[:] = [offset]
        if lines:  # write what the previous tick delivered
            sys.stdout.write("".join(lines))
            lines.clear()
        while pending and pending[0][0] <= offset + 1e-9:
            at, command, report = pending.pop(0)
            outcome = observe_poke(server, round(max(at, offset), 3), command, send)
            if report:  # what the poke did, among the diagnostics (stdout carries only what the client sees)
                print(outcome.line(), file=sys.stderr)
        autotrack.follow(clock.now())  # its satellite of this instant, before the tick computes it
        if not started:
            started = True
            try:
                client.start()
            except DdeError as exc:
                say(f"{link}: {exc}")

    try:
        run_virtual(server, clock, args.duration, before_tick=before_tick)
        if previous:
            client.after_tick(previous[0])
        sys.stdout.write("".join(lines))
        sys.stdout.flush()
    except BrokenPipeError:  # the reader went away (e.g. piped into head)
        sys.stderr.close()
        return 0
    finally:
        for service in services:
            service.detach()
        core_log.setLevel(saved_level)
    return 0
