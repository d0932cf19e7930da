"""``nfwserver watch``: a live view of a running (headless) station in a terminal, over its TCP port.

Host and port as for ``nfwserver status`` (the configuration's ``[tcp]``, ``--host``/``--port`` override).
Decision: one connection, which asks ``STATUS`` and ``SUMMARY`` every ``--interval`` seconds (default 1)
and holds a ``WATCH`` subscription between two questions (the stream is read and dropped; a blank line ends
it before the next question): one connection has one failure to handle, the STATUS line already carries the
published values (``az``/``el``/``rr``/``ah``) and SUMMARY gives the exact Nova string.  The subscription
keeps the connection a watcher, never closed by the station's idle timeout whatever the interval, and the
questions are commands, so the connection is never the quietest of its address: when a crowd from the same
address fills the per-address cap, the station closes one of the crowd for ``nfwserver status``, not the
view; and a connection from the station's own address is never closed for another address
(:mod:`nfwserver.tcp.admission`).

On a terminal the status block is redrawn in place (``rich.live``); otherwise one plain line per update;
``--json`` prints one JSON object per update (:meth:`WatchUpdate.to_json`).  When the station does not answer
the view says so ("not reachable yet" before the first answer, "lost" after) and tries again after 1, 2, 4,
then every 8 seconds; Ctrl+C or SIGTERM stops it (exit 0).  ``--count N`` stops after N answers (scripts, tests).
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import threading
from collections.abc import Callable
from typing import TextIO

from nfwserver.cli.arguments import number_in
from nfwserver.cli.control_command import add_station_options, station_address
from nfwserver.cli.watch_view import WatchUpdate, block_lines, parse_status, plain_line
from nfwserver.clock import Clock, SystemClock
from nfwserver.tcp.client import StationLink, StationUnreachable

#: Seconds between attempts while the station does not answer: 1, 2, 4, then 8.
RETRY_S = (1.0, 2.0, 4.0, 8.0)
DRAIN_S = 0.25  #: seconds between two reads of the WATCH stream while waiting (a few published strings)


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser(
        "watch", help="live view of the running station (TCP)",
        description="Show the running station's state, refreshed in place: satellite and who chose it, the Nova "
        "string, AZ/EL/RR/AH, TUNE/TRACK, the status word, faults, rotor, radio, EasyComm and the age of the "
        "elements. Reconnects when the station goes away; Ctrl+C stops.")
    add_station_options(p)
    p.add_argument("--interval", type=number_in(0.05, 3600, unit="s"), default=1.0, metavar="SECONDS",
                   help="seconds between updates (default 1)")
    p.add_argument("--json", action="store_true", help="one JSON object per update on stdout, for scripts")
    p.add_argument("--count", type=number_in(1, 10**9, integer=True), metavar="N",
                   help="stop after N updates from the station (default: run until Ctrl+C)")
    p.set_defaults(func=run)


class StationWatcher:
    """Polls the station at ``host``:``port`` and hands each :class:`WatchUpdate` to ``show``.

    Runs on the calling thread; ``stop`` (an Event) ends it between polls.  Waits go through ``clock``."""

    def __init__(self, host: str, port: int, show: Callable[[WatchUpdate], None], *, clock: Clock,
                 interval_s: float = 1.0, timeout_s: float = 5.0, stop: threading.Event | None = None) -> None:
        self.host, self.port, self.show, self.clock = host, port, show, clock
        self.where = f"{host} port {port}"
        self.interval_s, self.timeout_s = interval_s, timeout_s
        self.stop = stop or threading.Event()
        self.answers = 0  #: updates received from the station so far

    def run(self, count: int | None = None) -> None:
        """Until ``stop`` is set or ``count`` answers were shown."""
        failures = 0
        while not self.stop.is_set():
            try:
                link = StationLink(self.host, self.port, self.timeout_s)
                try:
                    while not self.stop.is_set():
                        status = link.ask("STATUS")
                        nova = link.ask("SUMMARY")
                        self.answers += 1
                        failures = 0
                        self.show(WatchUpdate(self.clock.now(), self.where, True, parse_status(status), nova))
                        if count is not None and self.answers >= count:
                            return
                        self._watch_for(link, self.interval_s)
                finally:
                    link.close()
            except StationUnreachable as exc:
                retry = RETRY_S[min(failures, len(RETRY_S) - 1)]
                failures += 1
                self.show(WatchUpdate(self.clock.now(), self.where, False, problem=str(exc), retry_s=retry,
                                      ever_connected=self.answers > 0))
                self.clock.wait(self.stop, retry)


    def _watch_for(self, link: StationLink, seconds: float) -> None:
        """Hold a ``WATCH`` for ``seconds`` of the clock (or until ``stop``), reading the stream as it comes so
        that the station never finds it stalled, then end it (a blank line; the station answers ``OK``)."""
        if link.ask("WATCH") != "OK":
            raise StationUnreachable(f"the station at {self.where} refused WATCH")
        deadline = self.clock.monotonic() + seconds
        while not self.stop.is_set() and (left := deadline - self.clock.monotonic()) > 0:
            link.drain()
            self.clock.wait(self.stop, min(DRAIN_S, left))
        link.send("")
        while link.reply() != "OK":  # strings published before the blank line arrived
            pass


def _json_printer(out: TextIO) -> Callable[[WatchUpdate], None]:
    def show(update: WatchUpdate) -> None:
        out.write(json.dumps(update.to_json()) + "\n")
        out.flush()

    return show


def _plain_printer(out: TextIO) -> Callable[[WatchUpdate], None]:
    def show(update: WatchUpdate) -> None:
        out.write(plain_line(update) + "\n")
        out.flush()

    return show


class _Terminated(Exception):
    """SIGTERM: leave the view as Ctrl+C does."""


def _terminated(signum: int, frame: object) -> None:
    raise _Terminated


def _stop_on_signals() -> Callable[[], None]:
    """Make Ctrl+C (SIGINT) and SIGTERM end the view cleanly, even when SIGINT was inherited as ignored (a
    process started from a script or a service); returns what puts the previous handlers back.  Only on the
    main thread, where Python runs signal handlers."""
    if threading.current_thread() is not threading.main_thread():
        return lambda: None
    saved = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _terminated)

    def restore() -> None:
        for sig, handler in saved.items():
            signal.signal(sig, handler)

    return restore


def run(args: argparse.Namespace) -> int:
    host, port = station_address(args)
    count = int(args.count) if args.count is not None else None
    stop = threading.Event()
    restore = _stop_on_signals()
    try:
        if args.json or not sys.stdout.isatty():
            show = _json_printer(sys.stdout) if args.json else _plain_printer(sys.stdout)
            StationWatcher(host, port, show, clock=SystemClock(), interval_s=args.interval, timeout_s=args.timeout,
                           stop=stop).run(count)
        else:
            _run_live(host, port, args, count, stop)
    except (KeyboardInterrupt, _Terminated):  # Ctrl+C: the normal way to leave a live view
        stop.set()
    except BrokenPipeError:  # the reader went away (e.g. piped into head)
        sys.stderr.close()
    finally:
        restore()
    return 0


def _run_live(host: str, port: int, args: argparse.Namespace, count: int | None, stop: threading.Event) -> None:
    from rich.live import Live
    from rich.panel import Panel
    from rich.text import Text

    def render(update: WatchUpdate) -> Panel:
        style = "" if update.connected else "bold red"
        return Panel(Text("\n".join(block_lines(update)), style=style), title="nfwserver watch", expand=False)

    with Live(Text(f"connecting to {host} port {port} ..."), auto_refresh=False, transient=False) as live:
        def show(update: WatchUpdate) -> None:
            live.update(render(update), refresh=True)

        StationWatcher(host, port, show, clock=SystemClock(), interval_s=args.interval, timeout_s=args.timeout,
                       stop=stop).run(count)
