"""``nfwserver run``: the station server, with the console on a terminal or headless as a service.

Headless, the log goes to a rotating file (its path is printed at start); the start logs the observer,
satellite and enabled outputs, and a one-line status follows every ten minutes of the station clock.
A console that fails never stops the station: the failure is logged, the user is told in one
sentence, and the station carries on headless until a signal (or ``--duration``).
"""

from __future__ import annotations

import argparse
import logging
import logging.handlers
import os
import sys
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from nfwserver.cli.control_file import ControlFile, control_path
from nfwserver.cli.errors import CliError, load_config_or_fail, say
from nfwserver.cli.signals import StationSignals, signal_actions
from nfwserver.cli.station_channel import StationChannel, StationInfo
from nfwserver.cli.station_runner import run_console, serve_headless, start_report
from nfwserver.cli.stop_event import StopEvent
from nfwserver.clock import Clock, SystemClock

if TYPE_CHECKING:
    from nfwserver.app.station import Station
    from nfwserver.cli.log_file import StationLogFile
    from nfwserver.config.schema import Config
    from nfwserver.console.app import NfwConsole
    from nfwserver.dde.transport import DdeServerTransport

log = logging.getLogger("nfwserver")


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = subparsers.add_parser(
        "run", help="run the server (console on a terminal, or --headless)",
        description="Run the Nova-compatible DDE server with the configuration file (see `nfwserver config path`), "
        "or with built-in defaults when there is none.  The station follows that file while it runs "
        "(`nfwserver config set` changes it; settings that need a restart are named).",
    )
    p.add_argument("--config", metavar="FILE", help="configuration file (default: the platform's config directory)")
    p.add_argument("--headless", action="store_true", help="no console: run as a service, log to a rotating file")
    p.add_argument("--log-file", metavar="FILE", help="log file for --headless (default: user log directory)")
    p.add_argument("--web", action="store_true", help="serve the web dashboard for this run ([web] enabled; "
                   "the URL is printed at start)")
    p.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this many seconds (for checks)")
    p.set_defaults(func=run)


def _log_to_file(path: Path, clock: Clock) -> StationLogFile:
    """Send the log to the rotating file ``path`` (see :mod:`nfwserver.cli.log_file`); the terminal keeps
    showing warnings and errors only."""
    from nfwserver.cli.log_file import StationLogFile

    handler = StationLogFile(path, clock)
    root = logging.getLogger()
    for existing in root.handlers:
        if isinstance(existing, logging.StreamHandler) and not isinstance(existing, logging.FileHandler):
            existing.setLevel(max(existing.level, logging.WARNING))
    root.addHandler(handler)
    root.setLevel(min(root.level, logging.INFO))
    return handler


def default_log_file() -> Path:
    from platformdirs import user_log_dir

    return Path(user_log_dir("nfwserver", appauthor=False)) / "nfwserver.log"


@dataclass
class RunPlan:
    """How one ``run`` goes: console or headless, where the log goes, for how long, on which clock."""

    console: bool
    log_file: Path
    duration_s: float | None = None
    clock: Clock | None = None
    transport: DdeServerTransport | None = None  #: a DDE server transport (default: the platform's)
    #: builds the console app from (station, config, hint) (default: NfwConsole)
    make_console: Callable[[Station, Config, str], NfwConsole] | None = None
    console_options: dict[str, Any] | None = None  #: passed to the app's run() (tests: headless=True)
    stop: threading.Event | None = None  #: set to stop (default: signals and NFW_CONTROL_FILE; cli/signals.py)


def run(args: argparse.Namespace) -> int:
    """The station's lock is the first thing taken (:func:`_open_channel`), before the configuration is read or
    anything heavy is loaded: a second ``run`` is refused at once, and a ``stop`` finds a station that is still
    starting."""
    if args.duration is not None and not args.duration > 0:
        raise CliError("--duration must be positive")
    plan = RunPlan(console=sys.stdout.isatty() and not args.headless,
                   log_file=Path(args.log_file) if args.log_file else default_log_file(), duration_s=args.duration)
    opened = _open_channel(plan, SystemClock())
    try:
        from nfwserver.config.files import default_config_path

        config = load_config_or_fail(args.config)
        if getattr(args, "web", False) and not config.web.enabled:
            config = with_web(config)
        # The station follows the file it loaded, with or without --config; with none yet, the file `config init`
        # or `config set` would create, so a station started on built-in defaults takes it when it appears.
        return serve(config, plan, watch=config.path or str(default_config_path()), opened=opened)
    finally:
        opened.close()


def with_web(config: Config) -> Config:
    """``config`` with the web dashboard on (``--web``), warned about as the file's ``[web] enabled`` would be."""
    from dataclasses import replace

    from nfwserver.config.loader import exposure

    config = replace(config, web=replace(config.web, enabled=True))
    why = exposure(config.web.host)
    if why:
        config = replace(config, warnings=(*config.warnings, f"[web] host = \"{config.web.host}\": {why}; only "
                                           f"[web] allow addresses are served ({', '.join(config.web.allow)})"))
    return config


def _notes(station: Station, config: Config) -> tuple[list[str], str]:
    """Start-up notes for the terminal, and the console's hint (no observer, stale elements)."""
    from nfwserver.config.loader import observer_hint

    source = config.path or config.source
    notes = [f"configuration: {source}", station.transport_note, f"{len(station.catalog)} satellites loaded",
             station.selection_note]
    if station.web is not None and station.web.address is not None:
        notes.append(f"web dashboard: {station.web.url}")
    hints = [] if config.observer_configured else [observer_hint(config)]
    ages = [s.age_days(station.clock.now()) for s in station.catalog]
    if ages and min(ages) > config.elements.stale_days:
        hints.append(f"the newest element set is {min(ages):.0f} days old: positions drift; "
                     "`nfwserver elements update` fetches current ones")
    return [n for n in notes if n] + hints, " ".join(hints + [station.selection_note])


def _make_console(station: Station, config: Config, hint: str) -> NfwConsole:
    from nfwserver.console.app import NfwConsole

    return NfwConsole(station.core, station.transport_note, hint, radio=station.radio, rotor=station.rotor,
                      favourites=config.favourites or (25544, 27607, 43017, 44909, 7530),
                      clients=station.nova.client_count, tcp=station.tcp, easycomm=station.easycomm,
                      config_file=config.path or "", schedules=config.schedules,
                      stale_days=config.elements.stale_days)


def _exit_app(app: NfwConsole) -> None:
    try:
        app.call_from_thread(app.exit)
    except RuntimeError:  # not running (any more)
        pass


class _Requests:
    """Stop and reload requests (signals, the control file) for one run: set ``stop``, leave the console,
    reload the station's configuration.  The console and the station are filled in as they come up."""

    def __init__(self, stop: threading.Event) -> None:
        self.stop = stop
        self.station: Station | None = None
        self.app: NfwConsole | None = None
        self._reload_pending = False  #: a reload asked for before the station was up
        self._lock = threading.Lock()

    def station_started(self, station: Station) -> None:
        """The station is up: reload requests reach it from now on, and one asked for while it started is
        carried out now (the file may have changed after it was read)."""
        with self._lock:
            self.station, pending, self._reload_pending = station, self._reload_pending, False
        if pending:
            station.reload_config()

    def on_stop(self) -> None:
        self.stop.set()
        if self.app is not None:
            _exit_app(self.app)

    def on_reload(self) -> None:
        with self._lock:
            station = self.station
            self._reload_pending = station is None
        if station is not None:
            station.reload_config()


def _claim_channel(plan: RunPlan) -> StationChannel | None:
    """This user's station channel, held for the run (:mod:`nfwserver.cli.station_channel`); None when the
    caller stops the run itself (``plan.stop``).  Refused while another station of this user runs."""
    if plan.stop is not None:
        return None
    channel = StationChannel()
    try:
        claimed = channel.claim()
    except OSError as exc:
        raise CliError(f"cannot use {channel.lock_path}: {exc.strerror or exc}") from None
    if not claimed:
        info = channel.info()
        who = f" (process {info.pid})" if info is not None and channel.verified(info) else ""
        raise CliError(f"a station is already running for this user{who}: `nfwserver stop` stops it")
    return channel


@dataclass
class _OpenChannel:
    """What a run takes before anything else and holds to its end: the user's station lock, the signal handlers
    and the control file's watcher (none of them when the caller stops the run itself, ``plan.stop``)."""

    requests: _Requests
    channel: StationChannel | None
    signals: StationSignals | None
    control: ControlFile | None
    stop_event: StopEvent | None = None  #: Windows: ``nfwserver stop``'s event (cli/stop_event.py)

    def describe(self, station: Station | None = None) -> None:
        """Say who runs (and, with ``station``, that it is up and where it listens) in the channel."""
        from nfwserver.cli.station_process import process_start

        if self.channel is None:
            return
        pid = os.getpid()
        if sys.platform == "win32" and self.stop_event is None and self.signals is not None:  # before it is described
            self.stop_event = StopEvent.create(pid, process_start(pid), self.signals.request)
        if station is None:
            self.channel.describe(StationInfo(pid, process_start(pid)))
        else:
            self.channel.describe(StationInfo(pid, process_start(pid), _browser_url(station), started=True,
                                              tcp=_tcp_address(station)))

    def close(self) -> None:
        """Stop watching, restore the signals, free the lock (once the station has stopped)."""
        control, self.control = self.control, None
        signals, self.signals = self.signals, None
        channel, self.channel = self.channel, None
        event, self.stop_event = self.stop_event, None
        if control is not None:
            control.stop()
        if event is not None:
            event.stop()
        if signals is not None:
            signals.close()
        if channel is not None:
            channel.release()


def _open_channel(plan: RunPlan, clock: Clock) -> _OpenChannel:
    """Claim the channel, then listen for requests (:func:`_listen`) and describe the station as starting."""
    requests = _Requests(plan.stop or threading.Event())
    channel = _claim_channel(plan)
    try:
        signals, control = _listen(plan, requests, clock, channel)
    except BaseException:
        if channel is not None:
            channel.release()
        raise
    opened = _OpenChannel(requests, channel, signals, control)
    opened.describe()
    return opened


def _tcp_address(station: Station) -> tuple[str, int] | None:
    """Where a client on this machine reaches the station's TCP port (a wildcard host is reached on loopback)."""
    from nfwserver.tcp.client import connect_host

    if station.tcp is None or station.tcp.address is None:
        return None
    host, port = station.tcp.address
    return connect_host(str(host)), int(port)


def _browser_url(station: Station) -> str | None:
    """The dashboard's address as a browser on this machine opens it (a wildcard host is reached on loopback)."""
    if station.web is None or station.web.address is None:
        return None
    url = station.web.url
    for wildcard, loopback in (("//0.0.0.0:", "//127.0.0.1:"), ("//[::]:", "//[::1]:")):
        url = url.replace(wildcard, loopback)
    return url


def _listen(plan: RunPlan, requests: _Requests, clock: Clock,
            channel: StationChannel | None) -> tuple[StationSignals | None, ControlFile | None]:
    """Signal handlers and the control file's watcher, unless the caller stops the run itself (``plan.stop``).
    The control file is NFW_CONTROL_FILE's or the channel's; the channel's is watched in any case."""
    if plan.stop is not None:
        return None, None
    signals = StationSignals(signal_actions(headless=not plan.console), requests.on_stop, requests.on_reload)
    signals.install()
    own = channel.default_control if channel is not None else None
    path = control_path() or own
    again = channel.describe_again if channel is not None else None
    control = ControlFile(path, clock, signals.request, each_look=again, also=own) if path is not None else None
    if control is not None:
        control.start()
    return signals, control


def serve(config: Config, plan: RunPlan, watch: str | None = None, opened: _OpenChannel | None = None) -> int:
    """Start the station from ``config``, run it as ``plan`` says, stop it; the exit code.

    Without ``plan.stop``, signals and the control file stop it or reload its configuration
    (:mod:`nfwserver.cli.signals`), from before the station starts until it has stopped; ``opened`` is the
    channel ``run`` claimed before reading the configuration (claimed here without it).  A stop asked for while
    the station starts is carried out once it has started."""
    from nfwserver.app.station import Station
    from nfwserver.cli.log_file import LOG_BACKOFF

    clock = plan.clock or SystemClock()
    own = opened is None
    channel = opened if opened is not None else _open_channel(plan, clock)
    requests = channel.requests
    file_handler = None
    try:
        if not plan.console:
            file_handler = _log_to_file(plan.log_file, clock)
            say(f"logging to {plan.log_file}")
        station = Station(config, clock, transport=plan.transport)
        if file_handler is not None:
            file_handler.attach(station.core.health.link("log-file", LOG_BACKOFF))
        try:
            station.start()
        except OSError as exc:
            station.stop()
            raise CliError(f"cannot start the station: {exc.strerror or exc}") from None
        requests.station_started(station)
        channel.describe(station)
        try:
            file_handler = _serve_started(station, config, plan, watch, requests, file_handler)
        finally:
            if channel.signals is not None:
                channel.signals.stopping()  # no reload from here on; a further stop request is only noted
            station.stop()
            log.info("stopped")
    finally:
        if file_handler is not None:
            logging.getLogger().removeHandler(file_handler)
            file_handler.close()
        if own:
            channel.close()
    return 0


def _serve_started(station: Station, config: Config, plan: RunPlan, watch: str | None, requests: _Requests,
                   file_handler: StationLogFile | None) -> StationLogFile | None:
    """Keep the started ``station`` serving until ``requests.stop`` or the duration; the log file in use."""
    from nfwserver.cli.log_file import LOG_BACKOFF

    clock = station.clock
    notes, hint = _notes(station, config)
    if watch:
        station.watch_config(watch)
    started = clock.monotonic()
    stop = requests.stop
    if plan.console and not stop.is_set():
        app = (plan.make_console or _make_console)(station, config, hint)
        requests.app = app
        timer = None
        if plan.duration_s:
            timer = threading.Timer(plan.duration_s, _exit_app, (app,))
            timer.daemon = True
            timer.start()
        failure = run_console(app, **(plan.console_options or {}))
        requests.app = None
        if timer is not None:
            timer.cancel()
        if failure is None:
            return file_handler
        file_handler = _log_to_file(plan.log_file, clock)
        file_handler.attach(station.core.health.link("log-file", LOG_BACKOFF))
        log.error("the console stopped: %s: %s", type(failure).__name__, failure, exc_info=failure)
        say(f"the console failed ({type(failure).__name__}: {failure}); the station keeps serving without it, "
            f"logging to {plan.log_file}; stop it with Ctrl+C.")
    elif not plan.console:
        for note in notes:
            say(note)
            log.info(note)
    for line in start_report(station):
        log.info(line)
    remaining = None
    if plan.duration_s is not None:
        remaining = max(0.0, plan.duration_s - (clock.monotonic() - started))
    serve_headless(station, stop, remaining)
    return file_handler
