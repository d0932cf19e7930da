"""``nfwserver stop`` and ``nfwserver dashboard``: the user's running station, reached through its local channel.

``stop`` asks the station to stop cleanly (state saved, DDE conversations ended, listeners closed), never
by killing it, and waits until its process has ended (on Windows its program files are in use until then; an
installer replacing them relies on it).  A station that is still starting is found too: its lock is the first
thing ``run`` takes, and ``stop`` waits (up to ``--timeout``) for it to describe itself.

- Linux: ``SIGTERM`` (what systemd sends) to the process the description names, once that process is
  verified to be the station (its start time and, from ``/proc/locks``, the lock it holds:
  :meth:`~nfwserver.cli.station_channel.StationChannel.verified`).  Nothing is written, so a full disk does
  not matter.  A signal cannot be taken back: when the station has not stopped within ``--timeout`` the
  sentence says what will happen (a suspended station stops as soon as it is continued; a busy one when it
  has finished what it is doing).
- Windows: the verified station's named stop event is set (:mod:`nfwserver.cli.stop_event`; verified by its
  start time, ``GetProcessTimes``): nothing is written, so a full disk does not matter.  Only when that event
  cannot be opened (or the description is not verified) is ``stop`` written to the station's control file
  (``control`` in the state directory, never a path the description names); the process waited for is the
  described one only when verified, otherwise the lock alone.  When the station has not stopped within
  ``--timeout``, the request is withdrawn (the event taken back by a zero-timeout wait, or the file removed)
  unless the station has already taken it, and the sentence says which.

Exit status: 0 once stopped; 1 with one sentence when none is running (or it cannot be asked, or its
description names a process that is not the station); :data:`STILL_RUNNING` (3) with one sentence when it has
not stopped within ``--timeout``.  The waits are on the operating system (another process's lock and exit), in
real time.

``dashboard`` opens the running station's web page in the default browser (``--print``: only print its
address), waiting for a station that is still starting.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from nfwserver.cli.arguments import number_in
from nfwserver.cli.errors import CliError, config_refused, say, say_last_good
from nfwserver.cli.station_channel import StationChannel, StationInfo
from nfwserver.cli.station_process import process_ended, process_start
from nfwserver.cli.stop_event import SentRequest, ask_to_stop
from nfwserver.storage import atomic_write_text

#: Default seconds ``stop`` waits for the station to be gone.
STOP_TIMEOUT_S = 60.0
#: Seconds between looks at the lock while waiting.
POLL_S = 0.1
#: ``stop``'s exit status when the station was asked but has not stopped in time.
STILL_RUNNING = 3
#: Seconds ``dashboard`` waits for a station that is starting.
START_WAIT_S = 60.0


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    stop = subparsers.add_parser(
        "stop", help="stop the running station cleanly and wait until it has stopped",
        description="Ask this user's running station (`nfwserver run`, in a terminal, headless or started at "
        "logon) to stop cleanly, as Ctrl+C does, and wait until it has stopped. Exit 0 once stopped, 1 when "
        f"none is running, {STILL_RUNNING} when it has not stopped within --timeout.")
    stop.add_argument("--timeout", type=number_in(0.1, 3600.0, unit="s"), default=STOP_TIMEOUT_S, metavar="SECONDS",
                      help=f"how long to wait for the station to stop (default {STOP_TIMEOUT_S:g})")
    stop.set_defaults(func=run_stop)
    dash = subparsers.add_parser(
        "dashboard", help="open the running station's web dashboard in the browser",
        description="Open the web page of this user's running station in the default browser.")
    dash.add_argument("--print", dest="print_only", action="store_true", help="only print the address")
    dash.add_argument("--wait", type=number_in(0.0, 3600.0, unit="s"), default=START_WAIT_S, metavar="SECONDS",
                      help=f"how long to wait for a station that is still starting (default {START_WAIT_S:g})")
    dash.set_defaults(func=run_dashboard)


def _described(channel: StationChannel, timeout_s: float, started: bool = False) -> StationInfo | None:
    """The running station's description, waiting up to ``timeout_s`` for a station that is starting to
    write it (first once it listens for requests, then, ``started``, once it is up) and for it to be
    verified (:meth:`StationChannel.verified`: one left by a killed station is replaced at once); what was
    found by then (verified or not: the caller checks), or None if nothing, or no station runs any more."""
    deadline = time.monotonic() + timeout_s
    while True:
        info = channel.info()
        if info is not None and (info.started or not started) and channel.verified(info):
            return info
        if not channel.running() or time.monotonic() >= deadline:
            return info if info is not None and (info.started or not started) else None
        time.sleep(POLL_S)


def _not_the_station(channel: StationChannel, info: StationInfo) -> CliError:
    return CliError(f"the station's description {channel.info_path} names process {info.pid}, which is not the "
                    f"process holding {channel.lock_path}: nothing was done; stop the station from its own console "
                    "or with Ctrl+C")


def _ask_to_stop(channel: StationChannel, info: StationInfo, verified: bool) -> SentRequest | None:
    """Send the stop request to the verified station: a signal (POSIX); on Windows its stop event
    (:mod:`nfwserver.cli.stop_event`, the request returned), or its own control file when the event cannot be
    opened (None returned)."""
    if sys.platform != "win32":
        import signal

        os.kill(info.pid, signal.SIGTERM)
        return None
    if verified and info.start is not None:
        sent = ask_to_stop(info.pid, info.start)
        if sent is not None:
            return sent
    try:
        atomic_write_text(channel.default_control, "stop\n")
    except OSError as exc:
        raise CliError(f"cannot ask the station (process {info.pid}) to stop: {channel.default_control}: "
                       f"{exc.strerror or exc}") from None
    return None


def _gave_up(channel: StationChannel, info: StationInfo, timeout_s: float, sent: SentRequest | None) -> str:
    """What happens to the request of a ``stop`` that waited ``timeout_s`` in vain, in one sentence; the request
    (the event's ``sent``, else the control file) is withdrawn unless the station has taken it."""
    from nfwserver.cli.station_process import suspended

    head = f"the station (process {info.pid}) was asked to stop but is still running after {timeout_s:g} s"
    if sys.platform != "win32":
        if suspended(info.pid):
            return (f"{head}: it is suspended (SIGSTOP or Ctrl+Z) and has the stop signal, so it will stop "
                    f"cleanly as soon as it is continued (`kill -CONT {info.pid}`)")
        return f"{head}: it has the stop signal and will stop once it finishes what it is doing (its log says what)"
    if sent is not None and not sent.withdraw():
        return f"{head}: it has taken the request and is stopping (its log says what it is waiting for)"
    if sent is not None:
        return f"{head}; the request is withdrawn: it will go on running (its log says what it is waiting for)"
    try:
        channel.default_control.unlink()
    except FileNotFoundError:
        return f"{head}: it has taken the request and is stopping (its log says what it is waiting for)"
    except OSError as exc:
        return (f"{head}; the request could not be withdrawn ({exc.strerror or exc}), so it will stop when it "
                f"next looks at {channel.default_control}")
    return f"{head}; the request is withdrawn: it will go on running (its log says what it is waiting for)"


def run_stop(args: argparse.Namespace) -> int:
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
    verified = channel.verified(info)
    if not verified and sys.platform != "win32":  # Windows writes only the station's own control file: no harm
        raise _not_the_station(channel, info)
    sent = _ask_to_stop(channel, info, verified)
    deadline = time.monotonic() + args.timeout
    # the lock is freed just before the process ends: wait for its end too (the same start time: not a new one)
    while channel.running() or (verified and process_start(info.pid) == info.start and not process_ended(info.pid)):
        if time.monotonic() >= deadline:
            say(_gave_up(channel, info, args.timeout, sent))
            return STILL_RUNNING
        time.sleep(POLL_S)
    print(f"stopped the station (process {info.pid})" if verified else "stopped the station")
    return 0


def run_dashboard(args: argparse.Namespace) -> int:
    channel = StationChannel()
    if not channel.running():
        raise CliError("no station is running for this user: start one (`nfwserver run`, or the Start menu's "
                       "\"nfwserver station\"), then open its dashboard")
    info = _described(channel, args.wait, started=True)
    if info is None and channel.running():
        raise CliError(f"the station has not finished starting after {args.wait:g} s; try again in a moment")
    if info is not None and not channel.verified(info):
        raise _not_the_station(channel, info)
    problem = config_refused(None)
    if problem is not None:
        say_last_good(problem)
    if info is None or not info.web_url:
        raise CliError("the running station serves no web dashboard: `nfwserver config set web.enabled true` "
                       "turns it on (the station applies it at its next start)")
    print(info.web_url)
    if not args.print_only:
        import webbrowser

        if not webbrowser.open(info.web_url):
            raise CliError(f"no browser could be started; open {info.web_url} yourself")
    return 0
