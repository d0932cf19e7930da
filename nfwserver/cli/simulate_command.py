"""``nfwserver simulate``: run the real server on the fake DDE transport under a virtual clock.

One client holds a hot advise loop on NFW32/NFW_DATA/NFW_SERVER and every string it receives is
printed as ``<ISO-8601 UTC with ms and Z><TAB><string>``, the time being the instant the values were
computed for.  Pokes can be scheduled: ``--poke 120:SAT=25544`` is sent by that client 120 s in.
"""

from __future__ import annotations

import argparse
import logging
import sys

from nfwserver.cli.tracking_options import add_tracking_options, format_time, load_tracking_inputs, parse_time
from nfwserver.clock import VirtualClock
from nfwserver.dde.clipboard import CF_TEXT
from nfwserver.dde.publisher import run_virtual
from nfwserver.dde.server import MAX_RATE_HZ, MIN_RATE_HZ, NovaServer
from nfwserver.fake_dde import DdeError, FakeDdeSystem, Received


def _poke_spec(text: str) -> tuple[float, str]:
    offset, sep, command = text.partition(":")
    if sep and offset.replace(".", "", 1).isdigit():
        return float(offset), command
    return 0.0, text


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "simulate",
        help="show what a DDE client receives, on virtual time",
        description="Run the server on the in-process DDE transport under a virtual clock, with one "
        "client holding a hot advise loop on NFW32/NFW_DATA/NFW_SERVER; print each string it "
        "receives as '<UTC time>\\t<string>'. TUNE ON is poked at the start.",
    )
    add_tracking_options(p, output_format=False)
    p.add_argument("--start", required=True, help="start time, ISO-8601 (UTC when no zone is given)")
    p.add_argument("--duration", type=float, default=600.0, metavar="SECONDS", help="virtual duration")
    p.add_argument("--rate", type=float, default=5.0, metavar="HZ", help="publish rate, 1-50 Hz (default 5)")
    p.add_argument("--sat", type=int, metavar="CATNR", help="initial AutoTracking satellite")
    p.add_argument("--poke", action="append", default=[], metavar="[SECONDS:]COMMAND",
                   help="poke sent by the client at that offset (default 0); repeatable")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from nfwserver.cli import CliError

    if not MIN_RATE_HZ <= args.rate <= MAX_RATE_HZ:
        raise CliError(f"--rate must be between {MIN_RATE_HZ:g} and {MAX_RATE_HZ:g} Hz")
    if not 0 < args.duration <= 30 * 86400:
        raise CliError("--duration must be between 0 and 30 days")
    try:
        start = parse_time(args.start)
    except ValueError as exc:
        raise CliError(f"--start: {exc}") from None
    inputs = load_tracking_inputs(args)
    clock = VirtualClock(start)
    server = NovaServer(inputs.catalog, inputs.observer, clock, horizon=inputs.horizon,
                        ut1_utc=inputs.ut1_utc, rate_hz=args.rate)
    if args.sat is None:
        print("nfwserver: no --sat given: no AutoTracking satellite, so nothing is published", file=sys.stderr)
    elif not server.select_satellite(args.sat, source="simulate"):
        print(f"nfwserver: satellite {args.sat} is not in the element files; nothing is published",
              file=sys.stderr)
    # Refusals are reported below with their time; keep the server's own warning out of the way.
    server_log = logging.getLogger("nfwserver.dde.server")
    previous_level = server_log.level
    server_log.setLevel(logging.ERROR)  # restored below: the command may run inside another program
    system = FakeDdeSystem(received_capacity=16)
    server.attach(system.server_transport())
    client = system.connect("NFW32", "NFW_DATA", client_name="simulate")
    lines: list[str] = []

    def collect(received: Received) -> None:
        if received.kind == "data" and received.data is not None:
            sample = server.snapshot().last_sample
            when = sample.time if sample is not None else clock.now()
            lines.append(f"{format_time(when)}\t{received.text}\n")

    client.on_receive = collect
    client.start_advise("NFW_SERVER", CF_TEXT, hot=True)
    pending = sorted((_poke_spec(p) for p in args.poke), key=lambda x: x[0])
    pending.insert(0, (0.0, "TUNE ON"))

    def before_tick(offset: float) -> None:
        if lines:  # write what the previous tick delivered
            sys.stdout.write("".join(lines))
            lines.clear()
        while pending and pending[0][0] <= offset + 1e-9:
            _, command = pending.pop(0)
            try:
                client.poke("NFW_SERVER", command)
            except DdeError:
                refusal = server.events.recent(1)
                reason = refusal[0].detail if refusal else "refused"
                print(f"nfwserver: poke {command!r} at {format_time(clock.now())} refused: {reason}",
                      file=sys.stderr)

    try:
        run_virtual(server, clock, args.duration, before_tick=before_tick)
        sys.stdout.write("".join(lines))
        sys.stdout.flush()
    except BrokenPipeError:  # the reader went away (e.g. piped into head)
        sys.stderr.close()
        return 0
    finally:
        server.detach()
        server_log.setLevel(previous_level)
    return 0
