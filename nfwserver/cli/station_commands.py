"""``nfwserver stop`` and ``nfwserver dashboard``: the user's running station, reached through its local channel.

``stop`` asks the station to stop cleanly (the request ``run`` takes from a signal: state saved, DDE
conversations ended, listeners closed), through its control file, never by killing it, and waits until it
has stopped: exit 0 once stopped, 1 with one sentence when none is running or it has not stopped in time.
It works the same on Linux and Windows, for a station in a terminal, headless, or started at logon
(:mod:`nfwserver.cli.station_channel`).

``dashboard`` opens the running station's web page in the default browser (``--print``: only print its
address).
"""

from __future__ import annotations

import argparse
import time

from nfwserver.cli.arguments import number_in
from nfwserver.cli.station_channel import StationChannel, StationInfo
from nfwserver.storage import atomic_write_text

#: Default seconds ``stop`` waits for the station to be gone.
STOP_TIMEOUT_S = 60.0
#: Seconds between looks at the lock while waiting.
POLL_S = 0.1


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    stop = subparsers.add_parser(
        "stop", help="stop the running station cleanly and wait until it has stopped",
        description="Ask this user's running station (`nfwserver run`, in a terminal, headless or started at "
        "logon) to stop cleanly, as Ctrl+C does, and wait until it has stopped. Exit 0 once stopped, 1 when "
        "none is running or it has not stopped within --timeout.")
    stop.add_argument("--timeout", type=number_in(0.1, 3600.0, unit="s"), default=STOP_TIMEOUT_S, metavar="SECONDS",
                      help=f"how long to wait for the station to stop (default {STOP_TIMEOUT_S:g})")
    stop.set_defaults(func=run_stop)
    dash = subparsers.add_parser(
        "dashboard", help="open the running station's web dashboard in the browser",
        description="Open the web page of this user's running station in the default browser.")
    dash.add_argument("--print", dest="print_only", action="store_true", help="only print the address")
    dash.set_defaults(func=run_dashboard)


def _described(channel: StationChannel, timeout_s: float) -> StationInfo | None:
    """The running station's description, waiting up to ``timeout_s`` for a station that is starting to
    write it (it is written once the station watches its control file); None if none runs any more."""
    deadline = time.monotonic() + timeout_s
    while True:
        info = channel.info()
        if info is not None or not channel.running():
            return info
        if time.monotonic() >= deadline:
            return None
        time.sleep(POLL_S)


def run_stop(args: argparse.Namespace) -> int:
    from nfwserver.cli import CliError

    channel = StationChannel()
    if not channel.running():
        raise CliError("no station is running for this user: nothing to stop")
    info = _described(channel, args.timeout)
    if info is None:
        if not channel.running():
            print("the station stopped by itself")
            return 0
        raise CliError(f"a station holds {channel.lock_path} but has not said how to reach it within "
                       f"{args.timeout:g} s; stop it from its own console or with Ctrl+C")
    try:
        atomic_write_text(info.control, "stop\n")
    except OSError as exc:
        raise CliError(f"cannot ask the station (process {info.pid}) to stop: {info.control}: "
                       f"{exc.strerror or exc}") from None
    deadline = time.monotonic() + args.timeout
    while channel.running():
        if time.monotonic() >= deadline:
            raise CliError(f"the station (process {info.pid}) was asked to stop but is still running after "
                           f"{args.timeout:g} s; its log says what it is waiting for")
        time.sleep(POLL_S)
    print(f"stopped the station (process {info.pid})")
    return 0


def run_dashboard(args: argparse.Namespace) -> int:
    from nfwserver.cli import CliError

    channel = StationChannel()
    if not channel.running():
        raise CliError("no station is running for this user: start one (`nfwserver run`, or the Start menu's "
                       "\"nfwserver station\"), then open its dashboard")
    info = _described(channel, 10.0)
    if info is None or not info.web_url:
        raise CliError("the running station serves no web dashboard: `nfwserver config set web.enabled true` "
                       "turns it on (the station applies it at its next start)")
    print(info.web_url)
    if not args.print_only:
        import webbrowser

        if not webbrowser.open(info.web_url):
            raise CliError(f"no browser could be started; open {info.web_url} yourself")
    return 0
